// A profile compiled to a lookup table: the drive-side step at the speed of a table, with every
// feature of the full step kept. The table is derived once, by running detail::full_step on every
// (state, decoded command, bit-7 edge, torque) the ordinary cycle can meet; the rows stay the one
// source of truth. What no table holds (a fault, STO, no DC link, no remote control, a lost link, a
// local request, overspeed, a stop that is running) goes to detail::full_step, so the compiled step
// is exactly the full step: the model check (tests/core/model_check.hpp) proves it on every
// reachable pair of every built-in profile.
//
// Where the table lives: in RAM, built by the constructor (288 entries, 2,304 bytes a profile). A
// built-in profile is a constant in flash; its table would cost the same bytes of flash on a
// microcontroller, where flash is the scarcer of the two, and a profile loaded from a file can only
// be compiled at run time anyway. Build it once at start-up, outside the control loop: the
// constructor runs the full step up to 55,000 times (192 probes for each of 288 entries).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "cia402/drive.hpp"

namespace cia402 {

class compiled_profile {
 public:
  /// Entries: (state << 5) | (command << 2) | (bit-7 edge << 1) | torque was on.
  static constexpr std::size_t entry_count = state_count << 5;

  explicit compiled_profile(const profile& p) noexcept;

  const profile& source() const noexcept { return *profile_; }
  /// Entries the table answers itself (the rest fall back to the full step).
  std::size_t covered() const noexcept;

  // An entry is the first 8 bytes of the drive_outputs of an ordinary cycle with this key (state,
  // status word bits the table knows, transition, torque, brake), and in the padding byte after
  // `current`, which outputs do not use, what the step must do besides.
  static constexpr unsigned fallback = 1u << 0;      ///< detail::full_step decides
  static constexpr unsigned commit = 1u << 1;        ///< a row fires and completes at once
  static constexpr unsigned resets_error = 1u << 2;  ///< it is a fault reset (T15, seed 001 T16)
  static constexpr unsigned clears = 1u << 3;        ///< it clears the set-points
  static constexpr unsigned run = 1u << 4;           ///< the state runs: halt and target reached

 private:
  friend drive_outputs step(const compiled_profile& c, axis& a, const drive_inputs& in) noexcept;

  const profile* profile_;
  std::array<std::uint64_t, entry_count> table_{};
  std::uint64_t speed_span_ = 0;  ///< 2 * limit - 2: |speed| < limit is (speed + limit - 1) <= this
  bool has_speed_limit_ = false;
  bool has_halt_ = false;         ///< 0x605D exists: control-word bit 8 halts
};

namespace detail {

/// The first 8 bytes of drive_inputs as an ordinary cycle has them: no fault code, DC link, no STO,
/// remote, link up, no local request. One compare tells an ordinary cycle from one the table does
/// not hold.
inline std::uint64_t ordinary_head() noexcept {
  static_assert(offsetof(drive_inputs, local_disable) + sizeof(bool) <= 8,
                "the unusual inputs must fill the first 8 bytes of drive_inputs");
  constexpr drive_inputs defaults{};
  std::uint64_t head = 0;
  std::memcpy(&head, &defaults, 8);
  return head;
}

}  // namespace detail

/// Where the bytes of drive_outputs sit in the two 8-byte words a step builds them in.
namespace outputs_layout {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
constexpr unsigned shift(std::size_t offset, std::size_t size) noexcept {
  return static_cast<unsigned>(64 - 8 * ((offset % 8) + size));
}
#else
constexpr unsigned shift(std::size_t offset, std::size_t) noexcept {
  return static_cast<unsigned>(8 * (offset % 8));
}
#endif
static_assert(sizeof(drive_outputs) <= 16, "drive_outputs must fit two 8-byte words");
static_assert(offsetof(drive_outputs, brake_released) < 8 && offsetof(drive_outputs, clear_setpoints) >= 8,
              "the lower word holds state, status word, transition, ramp, torque and brake");
constexpr unsigned current = shift(offsetof(drive_outputs, current), 1);
constexpr unsigned actions = shift(offsetof(drive_outputs, current) + 1, 1);  // the padding byte
constexpr unsigned status_word = shift(offsetof(drive_outputs, status_word), 2);
constexpr unsigned transition = shift(offsetof(drive_outputs, transition), 1);
constexpr unsigned ramp = shift(offsetof(drive_outputs, ramp), 1);
static_assert(offsetof(drive_outputs, status_word) == 2, "a padding byte follows `current`");
}  // namespace outputs_layout

/// Runs one cycle: one table load for an ordinary cycle, detail::full_step for the rest. The same
/// outputs and axis as cia402::step(profile, ...), byte for byte.
inline drive_outputs step(const compiled_profile& c, axis& a, const drive_inputs& in) noexcept {
  namespace at = outputs_layout;
  const profile& p = *c.profile_;
  std::uint64_t head;
  std::memcpy(&head, &in, 8);
  // |speed| < limit as one unsigned compare, in 64 bits so no limit or speed can overflow it.
  const bool slow = c.has_speed_limit_ &&
                    static_cast<std::uint64_t>(std::int64_t{in.actual_speed_rpm} + p.speed_limit_rpm - 1) >
                        c.speed_span_;
  if ((head != detail::ordinary_head()) | (a.pending_row != no_pending_row) | slow) {
    return detail::full_step(p, a, in);
  }
  const unsigned cw = in.control_word;
  const unsigned flags = a.flags;
  const unsigned bit7 = (cw >> 7) & 1u;
  const unsigned key = (static_cast<unsigned>(a.current) << 5) |
                       (static_cast<unsigned>(p.command_of_bits[cw & 0x1Fu]) << 2) |
                       ((bit7 & ~flags) << 1) | ((flags >> 1) & 1u);
  std::uint64_t lo = c.table_[key];
  const unsigned actions = static_cast<unsigned>(lo >> at::actions) & 0xFFu;
  if (actions & compiled_profile::fallback) return detail::full_step(p, a, in);

  unsigned keep = ~static_cast<unsigned>(axis_flag::fault_reset_bit | axis_flag::torque_on);
  bool clear_setpoints = false;
  if (actions & compiled_profile::commit) {
    a.current = static_cast<state>((lo >> at::current) & 0xFFu);
    a.last_transition = static_cast<std::uint8_t>((lo >> at::transition) & 0xFFu);
    a.stop_code = 0;
    keep &= ~static_cast<unsigned>(axis_flag::entered_by_fault);
    if (actions & compiled_profile::resets_error) {
      keep &= ~static_cast<unsigned>(axis_flag::coast_reaction);
      a.error_code = 0;
    }
    clear_setpoints = (actions & compiled_profile::clears) != 0;
  }
  // Torque is on exactly where the entry's brake is released (a resting state, S12).
  const unsigned torque = static_cast<unsigned>(lo >> at::shift(offsetof(drive_outputs, torque), 1)) & 1u;
  a.flags = static_cast<std::uint8_t>((flags & keep) | bit7 | (torque << 1));
  unsigned status = static_cast<unsigned>(lo >> at::status_word) & 0xFFFFu;
  status |= (static_cast<unsigned>(in.warning) << 7) | (static_cast<unsigned>(in.internal_limit) << 11) |
            (in.mode_status_bits & status_bit::mode_specific);
  // Field by field, not one copy of the entry: the caller reads the outputs back in registers, and
  // a load that spans several narrower stores waits for all of them (store forwarding).
  drive_outputs out;
  out.ramp = stop_ramp::none;
  if (actions & compiled_profile::run) {
    const bool halt = ((cw >> 8) & 1u) & c.has_halt_;
    // 0x605D: 1 slow-down, 2 quick-stop, 3 current limit, 4 voltage limit (stop_ramp's values, S8).
    if (halt) out.ramp = static_cast<stop_ramp>(a.options[static_cast<int>(option::halt)]);
    status |= static_cast<unsigned>(halt ? in.standstill : in.target_reached) << 10;
  }
  out.current = static_cast<state>((lo >> at::current) & 0xFFu);
  out.status_word = static_cast<std::uint16_t>(status);
  out.transition = static_cast<std::uint8_t>((lo >> at::transition) & 0xFFu);
  out.torque = torque != 0;
  out.brake_released = torque != 0;
  out.clear_setpoints = clear_setpoints;
  const std::uint16_t code = a.error_code;
  out.error_code = code;
  out.error_register = code ? error_register_of(code) : std::uint8_t{0};
  return out;
}

}  // namespace cia402
