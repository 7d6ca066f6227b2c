// The `cia402` command line: subcommands replay, decode, profiles and demo. main() only forwards to
// run(), so tests drive the whole tool with string streams.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace cia402::cli {

/// Runs the tool on `args` (without the program name). Returns the process exit status: 0 on
/// success, 2 on a usage error or refused input before any work, CLI11's code for parse errors.
int run(const std::vector<std::string>& args, std::istream& in, std::ostream& out,
        std::ostream& err);

}  // namespace cia402::cli
