// `cia402 path FROM TO`: the fewest-cycles command sequence between two states of a profile, as the
// master side plans it (cia402::plan_path), with the transition each cycle takes.
#pragma once

#include <iosfwd>
#include <vector>

#include "cia402/profile.hpp"
#include "cli/replay.hpp"

namespace cia402::cli {

/// Prints the path; returns 0 if the target is reachable, 1 if not, 2 on a bad argument.
int run_path(const profile& p, const std::vector<option_write>& writes, const std::string& from,
             const std::string& to, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
