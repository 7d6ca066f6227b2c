#include "mode_view.hpp"

#include "cia402/objects.hpp"
#include "cia402/words.hpp"

namespace cia402::page::detail {
namespace {

std::int64_t magnitude(std::int64_t v) noexcept { return v < 0 ? -v : v; }

bool limit_switch_method(std::int64_t m) noexcept { return m == 1 || m == 2 || m == 17 || m == 18; }

std::string value_or_unknown(const std::optional<std::int64_t>& v) {
  return v ? std::to_string(*v) : std::string("?");
}

}  // namespace

motion::homing_phase infer_homing_phase(const mode_reading& r) noexcept {
  using motion::homing_phase;
  if (r.mode != mode::homing) return homing_phase::not_started;
  const std::uint16_t sw = r.status_word;
  const bool start = (r.control_word & control_bit::homing_operation_start) != 0;
  if ((sw & status_bit::homing_error) != 0) return homing_phase::error;
  if ((sw & status_bit::homing_attained) != 0) {
    return (sw & status_bit::target_reached) != 0 ? homing_phase::attained : homing_phase::moving_to_zero;
  }
  if ((sw & status_bit::target_reached) != 0) return start ? homing_phase::interrupted : homing_phase::not_started;
  if (!start || !r.enabled) return homing_phase::not_started;
  // In progress (13 / 12 / 10 all 0): the speed says which search runs.
  if (!r.velocity_rpm || *r.velocity_rpm == 0) return homing_phase::stopping_past_home;
  const std::int64_t v = magnitude(*r.velocity_rpm);
  const std::int64_t fast = r.switch_speed_rpm.value_or(0);
  const std::int64_t slow = r.zero_speed_rpm.value_or(0);
  const std::int64_t method = r.homing_method.value_or(0);
  // Closer to sub 1 than to sub 2 (a ramp between them counts to the nearer).
  const bool at_switch_speed = magnitude(v - fast) < magnitude(v - slow) || v > fast;
  if (method == 33 || method == 34) return homing_phase::searching_index_pulse;
  if (at_switch_speed) {
    return limit_switch_method(method) ? homing_phase::searching_limit_switch : homing_phase::searching_home_switch;
  }
  return homing_phase::searching_index_pulse;
}

std::string homing_phase_text(const mode_reading& r) {
  using motion::homing_phase;
  const homing_phase p = infer_homing_phase(r);
  std::string text = motion::homing_phase_name(p);
  const std::int64_t method = r.homing_method.value_or(0);
  switch (p) {
    case homing_phase::searching_home_switch:
    case homing_phase::searching_limit_switch:
      return text + " at 0x6099:1 = " + value_or_unknown(r.switch_speed_rpm) + " rpm";
    case homing_phase::searching_index_pulse:
      // Without an index pulse (17..30) the slow move finds the switch's edge itself.
      if (method >= 17 && method <= 30) text = "searching the switch edge";
      return text + " at 0x6099:2 = " + value_or_unknown(r.zero_speed_rpm) + " rpm";
    case homing_phase::stopping_past_home: return "in progress: stopping or reversing";
    case homing_phase::not_started:
      // CiA 402-2 gives 13 / 12 / 10 = 0 / 0 / 1 both meanings; without bit 10 the shaft still moves.
      if ((r.status_word & status_bit::target_reached) != 0) return "interrupted or not started";
      return r.velocity_rpm && *r.velocity_rpm != 0 ? "stopping" : text;
    case homing_phase::moving_to_zero: return "homing attained, still stopping";
    default: return text;
  }
}

std::string doing_now(const mode_reading& r) {
  if (!r.enabled) return "no motion: not OPERATION ENABLED";
  if (!r.mode) return "mode not known yet (0x6061 not read)";
  const std::uint16_t sw = r.status_word;
  if ((r.control_word & control_bit::halt) != 0 && *r.mode != mode::homing) {
    return (sw & status_bit::target_reached) != 0 ? "halted (control bit 8), standing" : "halting (control bit 8)";
  }
  switch (*r.mode) {
    case mode::profile_position: {
      const std::string to = value_or_unknown(r.target_position);
      if ((sw & status_bit::following_error) != 0) return "following error (status bit 13)";
      if ((sw & status_bit::target_reached) != 0) return "target reached (0x607A = " + to + ")";
      if ((sw & status_bit::set_point_acknowledge) != 0) return "moving to " + to + " (set-point acknowledged)";
      return "moving to " + to;
    }
    case mode::profile_velocity: {
      const std::string to = value_or_unknown(r.target_velocity);
      if ((sw & status_bit::target_reached) != 0) return "at 0x60FF = " + to + " rpm (target reached)";
      if ((sw & status_bit::speed_zero) != 0) return "standing (speed = 0), 0x60FF = " + to + " rpm";
      return "accelerating to 0x60FF = " + to + " rpm";
    }
    case mode::profile_torque:
      return std::string("torque 0x6071 = ") + value_or_unknown(r.target_torque) + " permille" +
             ((sw & status_bit::target_reached) != 0 ? " (target reached)" : "");
    case mode::homing: return "homing: " + homing_phase_text(r);
    case mode::cyclic_synchronous_position:
    case mode::cyclic_synchronous_velocity:
    case mode::cyclic_synchronous_torque: {
      if ((sw & status_bit::drive_follows_command) == 0) return "ignoring the command value (status bit 12 = 0)";
      const char* what = *r.mode == mode::cyclic_synchronous_position   ? "0x607A = "
                         : *r.mode == mode::cyclic_synchronous_velocity ? "0x60FF = "
                                                                         : "0x6071 = ";
      const auto& v = *r.mode == mode::cyclic_synchronous_position   ? r.target_position
                      : *r.mode == mode::cyclic_synchronous_velocity ? r.target_velocity
                                                                      : r.target_torque;
      return std::string("following the command value (") + what + value_or_unknown(v) + ")";
    }
    default: return "mode " + std::to_string(*r.mode) + ": no words for it";
  }
}

}  // namespace cia402::page::detail
