// The quiet cycle of the drive-side machine, inline so a controller's loop over its axes compiles
// it in place. Most cycles of a running drive change nothing: the control word asks for the state
// the drive is in, with no fault, voltage on, no STO. This path handles exactly those, in a few
// dozen instructions, and returns false, touching nothing, whenever anything else might happen;
// detail::full_step (src/core/drive.cpp) then does the whole work.
#pragma once


namespace cia402::detail {

/// The facts 0x605A's value raises (S5): 1..4 end QUICK STOP ACTIVE by themselves, 5..8 stay.
constexpr std::uint32_t quick_stop_facts(std::int8_t code) noexcept {
  const unsigned qs = static_cast<std::uint8_t>(code);
  return qs - 1u < 4u   ? static_cast<std::uint32_t>(fact::quick_stop_ends)
         : qs - 5u < 4u ? static_cast<std::uint32_t>(fact::quick_stop_stays)
                        : 0u;
}

inline bool quiet_step(const profile& p, axis& a, const drive_inputs& in, drive_outputs& out) noexcept {
  // Field by field rather than one 8-byte load: callers fill inputs field by field, and a wide
  // load over narrow stores stalls store forwarding. Bitwise ORs keep it to one branch.
  const bool unusual_inputs = (in.fault_code != 0) | !in.dc_link | in.sto | !in.remote |
                              in.connection_lost | in.local_enable | in.local_disable;
  const std::uint16_t cw = in.control_word;
  // Bit 7 as the axis keeps it (axis_flag::fault_reset_bit).
  const unsigned reset_bit = (cw >> 4) & axis_flag::fault_reset_bit;
  const unsigned flags = a.flags;
  const std::int32_t limit = p.speed_limit_rpm;  // seed 001: T2/T7 watch the speed
  const bool overspeed = limit != 0 && (in.actual_speed_rpm > limit || in.actual_speed_rpm < -limit);
  if (unusual_inputs | (a.pending_row != 0xFF) | ((reset_bit & ~flags) != 0) | overspeed) {
    return false;
  }
  const std::size_t s = static_cast<std::size_t>(a.current);
  const std::uint32_t qs_fact = quick_stop_facts(a.options[0]);
  const bool slow = limit == 0 || (in.actual_speed_rpm < limit && in.actual_speed_rpm > -limit);
  const std::uint32_t f = static_cast<std::uint32_t>(fact::automatic) |
                          static_cast<std::uint32_t>(fact::dc_link) |
                          (slow ? static_cast<std::uint32_t>(fact::below_speed_limit) : 0u) |
                          (1u << p.command_of_bits[cw & 0x1Fu]) | qs_fact;
  if (p.busy_from[s] & f) return false;

  // Nothing leaves the state and it is idle, holding or running: only outputs remain.
  const state_info info = p.states[s];
  const bool torque = info.activity != state_activity::idle;
  const bool run = info.activity == state_activity::run;
  const bool halt = run && (cw & 0x100u) && p.options[3].supported != 0;  // 0x605D (S8)
  a.flags = static_cast<std::uint8_t>((flags & ~(axis_flag::torque_on | axis_flag::fault_reset_bit)) |
                                      (torque ? axis_flag::torque_on : 0u) | reset_bit);
  out.current = a.current;
  out.transition = no_transition;
  // 605D: 1 slow-down, 2 quick-stop, 3 current limit, 4 voltage limit (stop_ramp's values).
  out.ramp = halt ? static_cast<stop_ramp>(a.options[3]) : stop_ramp::none;
  out.torque = torque;
  out.brake_released = torque;
  out.clear_setpoints = false;
  const bool target =
      run && (halt ? in.standstill : (in.status_bits & status_bit::target_reached) != 0);
  out.status_word = static_cast<std::uint16_t>(
      info.status_pattern | 0x0210u /* voltage enabled, remote */ |
      (in.status_bits & (status_bit::reported & ~status_bit::target_reached)) |
      (static_cast<unsigned>(target) << 10));
  out.error_code = a.error_code;
  out.error_register = a.error_code ? error_register_of(a.error_code) : std::uint8_t{0};
  return true;
}

}  // namespace cia402::detail
