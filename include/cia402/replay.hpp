// The replay interface (docs/semantics.md, "The replay interface"): one drive on an ideal plant
// unless told otherwise, driven by events one a line (`cw 0x0F`, `fault 0x2310`, `sto on`, ...),
// answering each with one JSON line once the drive is at rest. `cia402 replay` and the Python
// package (`cia402.Replay`, `Drive.replay`) both run this one implementation. C++20, may allocate.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402 {

/// Steps a settle may take before it gives up waiting for the state to stop changing. A sound
/// profile settles in a handful (T3 then T4, a ramp then its transition).
inline constexpr int max_settle_steps = 64;

/// What a settle saw: the outputs of its last step, every transition taken on the way, in order,
/// and whether the drive came to rest within max_settle_steps.
struct settle_result {
  drive_outputs last;
  std::vector<std::uint8_t> transitions;
  bool settled = false;
};

/// Steps the axis with unchanged inputs until a step takes no transition and changes neither the
/// axis nor the outputs (every further step would then be the same), at most max_settle_steps.
/// `previous` is the outputs of the step before, or nullptr when the axis has not stepped yet (a
/// drive at START is never at rest).
settle_result settle(const profile& p, axis& a, const drive_inputs& in,
                     const drive_outputs* previous);

/// The replay's drive, its plant inputs and its fault causes. Each call that takes an event returns
/// the one JSON line replay prints for it.
class replay_session {
 public:
  /// The profile must outlive the session.
  explicit replay_session(const profile& p);

  /// Writes an option code (0x605A..0x605E, 0x6007) before or between events; the SDO abort code
  /// says if it was refused (then nothing changed).
  sdo_abort write(std::uint16_t index, std::int32_t value);
  /// Settles the freshly made drive from START: the `"transitions":[0,1]` line.
  std::string power_up();
  /// Handles one input line; returns "" for a blank or comment line, else one JSON line: the
  /// drive's outputs, or `{"error":"...","line":N}` for a line it refuses (which changes nothing).
  std::string feed(std::string_view line, int line_number);

  const axis& drive_axis() const noexcept { return axis_; }
  const drive_inputs& inputs() const noexcept { return inputs_; }

 private:
  std::string settle_line();
  std::string error(std::string_view reason, int line_number) const;
  std::string handle(const std::vector<std::string_view>& words, int line_number);
  std::string handle_fault(const std::vector<std::string_view>& words, int line_number);
  std::string handle_set(const std::vector<std::string_view>& words, int line_number);

  const profile* profile_;
  axis axis_;
  drive_inputs inputs_;
  drive_outputs last_;    ///< the outputs of the latest step
  bool stepped_ = false;  ///< a step has been taken (power-up)
  /// Fault causes present, oldest first: (error code, error class). The newest is the one the
  /// drive sees as inputs.fault_code.
  std::vector<std::pair<std::uint16_t, std::uint8_t>> faults_;
};

}  // namespace cia402
