// `cia402 replay`: one drive on an ideal plant unless told otherwise, driven by events read one a
// line, exactly as docs/semantics.md ("The replay interface") defines it.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"

namespace cia402::cli {

/// Steps a settle may take before replay gives up waiting for the state to stop changing. A sound
/// profile settles in a handful (T3 then T4, a ramp then its transition).
inline constexpr int max_settle_steps = 64;

/// One `--set INDEX=VALUE` (or `set INDEX VALUE`) write.
struct option_write {
  std::uint16_t index = 0;
  std::int32_t value = 0;
};

/// Parses "0x605A=6"; on failure returns false and says why in `error`.
bool parse_option_write(std::string_view text, option_write& out, std::string& error);

/// The replay's drive, its plant inputs and its fault causes. Each call that takes an event returns
/// the one JSON line replay prints for it.
class replay_session {
 public:
  explicit replay_session(const profile& p);

  /// Writes an option code before (or between) events; the SDO abort code says if it was refused.
  sdo_abort write(const option_write& w);
  /// Settles the freshly made drive from START: the `"transitions":[0,1]` line.
  std::string power_up();
  /// Handles one input line; returns "" for a blank or comment line, else one JSON line.
  std::string feed(std::string_view line, int line_number);

  const axis& drive_axis() const noexcept { return axis_; }
  const drive_inputs& inputs() const noexcept { return inputs_; }

 private:
  std::string settle();
  std::string error(std::string_view reason, int line_number) const;
  std::string handle(const std::vector<std::string_view>& words, int line_number);

  const profile* profile_;
  axis axis_;
  drive_inputs inputs_;
  drive_outputs last_;    ///< the outputs of the latest step
  bool stepped_ = false;  ///< a step has been taken (power-up)
  /// Fault causes present, oldest first: (error code, error class). The newest is the one the
  /// drive sees as inputs.fault_code.
  std::vector<std::pair<std::uint16_t, std::uint8_t>> faults_;
};

/// Runs a whole replay: writes, power-up line, then one line per event. Returns the exit status:
/// 0 at end of input, 2 when a write is refused before power-up (nothing is printed then).
int run_replay(const profile& p, const std::vector<option_write>& writes, std::istream& in,
               std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
