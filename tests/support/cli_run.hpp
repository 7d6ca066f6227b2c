// The tool's run() called as a test calls it: the arguments, what is on standard input, and the exit
// status with everything written to standard output and standard error; and the check of a refusal
// (its status and what it said). Shared by the CLI tests in tests/canopen and tests/page.
#pragma once

#include <gtest/gtest.h>

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

// The run ended with exit status `status` and said `text` on standard error (a refusal, a failure).
inline ::testing::AssertionResult exited_saying(const result& r, int status, const std::string& text) {
  if (r.status == status && r.err.find(text) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "exit status " << r.status << " (expected " << status
                                       << "), standard error:\n" << r.err << "(expected it to say \"" << text << "\")";
}

}  // namespace cia402::cli
