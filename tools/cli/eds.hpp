// `cia402 eds`: the CiA 306 EDS of the virtual drive, printed from the same object dictionary the
// `cia402 bus` drives serve.
#pragma once

#include <iosfwd>
#include <string>

namespace CLI {
class App;
}

namespace cia402::cli {

struct eds_args {
  std::string profile = "cia402";
  std::string profile_file;
  int node = 1;
  bool node_given = false;  ///< --node was given: the file names its node
  std::string output;  ///< file, or standard output when empty
};

CLI::App* add_eds_subcommand(CLI::App& app, eds_args& args);
/// Exit status 0; 2 for an unknown profile or an output file that cannot be written.
int run_eds(const eds_args& args, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
