// The tool's run() called as a test calls it: the arguments, what is on standard input, and the exit
// status with everything written to standard output and standard error. Shared by the CLI tests in
// tests/canopen and tests/page.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "cli/app.hpp"

namespace cia402::cli {

struct result {
  int status;
  std::string out;
  std::string err;
};

inline result run_tool(std::vector<std::string> args, const std::string& input = "") {
  std::istringstream in(input);
  std::ostringstream out, err;
  const int status = run(args, in, out, err);
  return {status, out.str(), err.str()};
}

}  // namespace cia402::cli
