// The ordinary cycle of the drive-side machine, inline so a controller's loop over its axes compiles
// it in place. Most cycles of a running drive are ordinary: no fault, voltage on, no STO, remote
// control, no stop running, and the control word either asks for the state the drive is in or for
// a transition that takes effect at once (T2, T3, T4, T6, T7, T9, T10, ...). This path handles
// exactly those, by one lookup in the profile's ordinary_rows (computed from the rows by finalize():
// at compile time for the built-in profiles, at load for a profile file), and returns false,
// touching nothing, whenever anything else might happen; detail::full_step (src/core/drive.cpp)
// then does the whole work. The model check (tests/core/model_check.hpp) holds the two equal on
// every reachable pair of every built-in profile.
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
  // Bit 7 as the axis keeps it (axis_flag::fault_reset_bit), and its 0->1 edge (S2).
  const unsigned reset_bit = (cw >> 4) & axis_flag::fault_reset_bit;
  const unsigned flags = a.flags;
  const unsigned edge = reset_bit & ~flags;
  // Not |speed| < limit (seed 001's T2/T7 watch it): speed + limit - 1 in [0, 2 limit - 2], one
  // unsigned compare that no speed or limit can overflow (mod 2^32 it is a shift of the interval).
  const std::int32_t limit = p.speed_limit_rpm;
  const std::uint32_t span = static_cast<std::uint32_t>(limit) - 1u;
  const bool beyond_limit =
      limit > 0 && static_cast<std::uint32_t>(in.actual_speed_rpm) + span > 2u * span;
  // Halt (S8) ramps by 0x605D; a value outside 1..4 is the full step's to decide.
  const bool halt_asked = (cw & 0x100u) && p.options[3].supported != 0;
  const bool odd_halt = halt_asked && static_cast<std::uint8_t>(a.options[3] - 1) >= 4u;
  const std::uint8_t entry = p.ordinary_rows[profile::ordinary_index(static_cast<int>(a.current),
                                                                    p.command_of_bits[cw & 0x1Fu])];
  const bool torque_was_on = (flags & axis_flag::torque_on) != 0;
  if (unusual_inputs | (a.pending_row != 0xFF) | beyond_limit | odd_halt | (entry == ordinary::full) |
      ((edge != 0) & ((entry & ordinary::reset_reads) != 0)) |
      (torque_was_on & ((entry & ordinary::stops) != 0))) {
    return false;
  }

  unsigned kept = flags;
  std::uint8_t transition = no_transition;
  bool clear = false;
  const unsigned fired = entry & ordinary::row;
  if (fired != 0) {
    // A row that fires at once, with no fault fact and no fault reset among its reasons.
    const stored_row& r = p.rows[fired - 1];
    a.current = r.to;
    a.stop_code = 0;  // the new state stops by no option code
    a.last_transition = r.number;
    transition = r.number;
    clear = (r.flags & row_flag::clears_setpoints) != 0;
    kept &= ~static_cast<unsigned>(axis_flag::entered_by_fault);
  }

  // The state is idle, holding or running: only outputs remain.
  const state_info info = p.states[static_cast<std::size_t>(a.current)];
  const bool torque = info.activity != state_activity::idle;
  const bool run = info.activity == state_activity::run;
  const bool halt = run && halt_asked;
  a.flags = static_cast<std::uint8_t>((kept & ~(axis_flag::torque_on | axis_flag::fault_reset_bit)) |
                                      (torque ? axis_flag::torque_on : 0u) | reset_bit);
  out.current = a.current;
  out.transition = transition;
  // 605D: 1 slow-down, 2 quick-stop, 3 current limit, 4 voltage limit (stop_ramp's values).
  out.ramp = halt ? static_cast<stop_ramp>(a.options[3]) : stop_ramp::none;
  out.torque = torque;
  out.brake_released = torque;
  out.clear_setpoints = clear;
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
