// What the drive does now in its operation mode, in words, inferred on the master's side from what
// any drive shows (status word, control word, 0x6061, 0x606C, 0x60FD and the set-points the page
// knows), so it reads the same for a drive in this process and one on a bus: the snapshot's
// `doing_now` and `homing.phase` (docs/instrument-page.md, "Modes and homing").
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "cia402/motion/homing.hpp"

namespace cia402::page::detail {

/// What the page read of a drive for the inference; nothing where it is not known.
struct mode_reading {
  bool enabled = false;               ///< OPERATION ENABLED
  std::uint16_t status_word = 0;      ///< 0x6041
  std::uint16_t control_word = 0;     ///< 0x6040 as sent
  std::optional<std::int64_t> mode;   ///< 0x6061
  std::optional<std::int64_t> velocity_rpm;    ///< 0x606C
  std::optional<std::int64_t> digital_inputs;  ///< 0x60FD
  std::optional<std::int64_t> target_position; ///< 0x607A
  std::optional<std::int64_t> target_velocity; ///< 0x60FF
  std::optional<std::int64_t> target_torque;   ///< 0x6071
  std::optional<std::int64_t> homing_method;   ///< 0x6098
  std::optional<std::int64_t> switch_speed_rpm;  ///< 0x6099 sub 1
  std::optional<std::int64_t> zero_speed_rpm;    ///< 0x6099 sub 2
};

/// The phase of a homing run (CiA 402-2 homing mode, status bits 13 / 12 / 10 and control bit 4):
/// error, attained (10 set) or still stopping (moving_to_zero), interrupted (10 with bit 4 up), not
/// started (bit 4 down); while it runs, the speed tells the search: near 0x6099 sub 1 the switch
/// search (the limit switch for methods 1, 2, 17, 18), near sub 2 the edge or index pulse, at rest
/// a reversal or the stop past home (stopping_past_home). Outside homing mode: not_started.
motion::homing_phase infer_homing_phase(const mode_reading& r) noexcept;

/// The phase in words with what it runs at: "searching home switch at 0x6099:1 = 1000 rpm".
std::string homing_phase_text(const mode_reading& r);

/// One line of what the drive does now in its mode: "moving to 20000 (set-point acknowledged)",
/// "target reached", "homing: searching home switch at 0x6099:1 = 1000 rpm", "following the
/// command value", or why it does nothing ("not enabled", "halted (control bit 8)").
std::string doing_now(const mode_reading& r);

}  // namespace cia402::page::detail
