// `cia402 simulate FILE`: run a scenario (examples/scenarios/README.md) on a virtual drive, print its
// log, write traces and a plot, and exit non-zero if an expectation fails.
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>

namespace CLI {
class App;
}

namespace cia402::cli {

struct simulate_args {
  std::string file;
  std::string trace;  ///< out.csv, out.jsonl or out.vcd (by extension)
  std::string plot;   ///< out.svg
  std::size_t every = 1;  ///< keep every n-th row of a CSV/JSONL trace (changes always kept)
  bool quiet = false;
  bool vcd_standard = false;  ///< VCD without GTKWave's string variables
};

/// Registers the subcommand on `app`, filling `args` when it is parsed.
CLI::App* add_simulate_subcommand(CLI::App& app, simulate_args& args);

/// Runs it. Exit status: 0 every expectation held; 1 one failed; 2 the scenario file or an output
/// file was refused (nothing is run then).
int run_simulate(const simulate_args& args, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
