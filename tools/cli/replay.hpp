// `cia402 replay`: the replay interface of docs/semantics.md (cia402/replay.hpp) on standard input
// and output.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "cia402/profile.hpp"
#include "cia402/replay.hpp"

namespace cia402::cli {

using cia402::max_settle_steps;
using cia402::replay_session;

/// One `--set INDEX=VALUE` write.
struct option_write {
  std::uint16_t index = 0;
  std::int32_t value = 0;
};

/// Parses "0x605A=6"; on failure returns false and says why in `error`.
bool parse_option_write(std::string_view text, option_write& out, std::string& error);

/// Runs a whole replay: writes, power-up line, then one line per event. Returns the exit status:
/// 0 at end of input, 2 when a write is refused before power-up (nothing is printed then).
int run_replay(const profile& p, const std::vector<option_write>& writes, std::istream& in,
               std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
