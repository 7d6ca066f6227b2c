// The plant of a virtual drive over one cycle: the core's decision from the plant's feedback (or
// none, when the axis is settled), then the shaft in the operation mode (plant_modes/) and the
// brake. Every state-machine decision is the core's (cia402::step); this file only turns its outputs
// into motion and brake, and the motion and brake back into its inputs.
#include "cia402/sim/plant.hpp"

#include <cstring>

#include "cia402/sim/virtual_drive.hpp"
#include "cia402/words.hpp"
#include "plant_internal.hpp"

namespace cia402::sim {
namespace {

using namespace detail;

// A cyclic mode's interpolation starts again from where the shaft is (csp), how fast it turns
// (csv) or the torque it has (cst).
void restart_cyclic(axis_state& a) noexcept {
  restart_interpolation(a, a.operation_mode == cia402::mode::cyclic_synchronous_velocity ? a.velocity
                           : a.operation_mode == cia402::mode::cyclic_synchronous_torque ? a.torque_demand
                                                                                          : a.position);
}

// Control bit 4 (new set-point in pp, homing operation start in hm) as the control word has it now.
bool bit_4(const axis_state& a) noexcept { return (a.control_word & control_bit::new_set_point) != 0; }

// A mode change takes effect at the start of the next cycle, before the core's decision: the new
// mode takes the shaft over as it is (pp with no set-point brakes it, homing waits for its start),
// 0x6061 shows it, and that cycle's status word shows none of the old mode's bits (10..13). Bit 4 acts on its 0->1 edge seen while the mode is active: its value now counts as the previous
// one, so entering a mode with bit 4 already 1 starts nothing (and bit 12 is 0); the next edge acts.
[[gnu::noinline]] void enter_mode(axis_state& a) noexcept {
  a.operation_mode = a.requested_mode;
  a.pp.reset(motion::shaft{a.position, a.position_fraction, a.velocity}, bit_4(a));
  a.homing.reset(bit_4(a));
  a.demand = a.position;
  a.torque_demand = a.torque;
  a.following_error_us = 0;
  a.in_velocity_window_us = 0;
  a.above_velocity_threshold_us = 0;
  a.mode_status = 0;
  restart_cyclic(a);
}

// One cycle of the shaft in a mode other than profile velocity, while the drive runs. Returns the
// mode's status bits (10..13); torque_set when the mode set the torque itself.
std::uint16_t move_in_mode(const plant_constants& k, axis_state& a, const drive_outputs& out,
                           motion::shaft& s, bool& torque_set) noexcept {
  switch (a.operation_mode) {
    case cia402::mode::profile_position: return pp_cycle(k, a, out, s);
    case cia402::mode::homing: return homing_cycle(k, a, s);
    case cia402::mode::cyclic_synchronous_velocity: return csv_cycle(k, a, s);
    case cia402::mode::profile_torque:
    case cia402::mode::cyclic_synchronous_torque:
      torque_set = true;
      return torque_cycle(k, a, s);
    default: return 0;
  }
}

// Profile velocity, and every mode while a stop runs or torque is off: the velocity approaches its
// goal on the ramps, the position integrates it. Returns bit 11 while profile velocity's set-point
// is cut (speed limit, software position limit). Here, not in plant_modes/: every cycle of every
// mode but a running one runs it, inlined into shaft_follow().
std::uint16_t velocity_follow(const profile& p, const plant_constants& k, axis_state& a,
                              const drive_outputs& out, motion::shaft& s, bool brake_holds) noexcept {
  const std::int64_t cycle = k.cycle_us;
  std::int64_t goal = 0;
  std::int64_t up = 0;
  std::int64_t down = 0;
  std::uint16_t status = 0;
  limit_approach at;
  if (!out.torque) {
    down = k.coast_step;  // coasting: friction only
  } else if (out.ramp != stop_ramp::none && out.ramp != stop_ramp::coast) {
    down = ramp_step(k, a, out.ramp);
  } else if (p.info(out.current).activity == state_activity::run && a.operation_mode == cia402::mode::profile_velocity) {
    goal = a.pv_set_point;
    if (a.pv_set_point_cut) status |= status_bit::internal_limit_active;
    up = std::int64_t{a.acceleration} * cycle;
    down = std::int64_t{a.deceleration} * cycle;
    if (limits_on(a) && brake_for_limit(k, a, s, goal, down, at)) status |= status_bit::internal_limit_active;
  } else {
    down = std::int64_t{a.deceleration} * cycle;  // torque held without motion (e.g. hold states)
  }
  if (brake_holds) {
    goal = 0;  // an engaged (or still releasing) brake holds the shaft: nothing accelerates
    up = 0;
    down += k.brake_step;
    at.towards = 0;
  }
  const std::int64_t v_new = approach(s.velocity, goal, up, down);
  motion::advance(s, v_new, k.cycle_us, a.objects.increments_per_rev);
  stand_at_limit(s, at, v_new, down);
  return status;
}

[[gnu::noinline]] void brake_moves(const plant_constants& k, axis_state& a, bool open) noexcept;

// The brake over one cycle: it reaches what the drive commands after its delay. Where it was
// commanded, and commanded so before (the usual cycle), nothing moves.
inline void brake_follow(const plant_constants& k, axis_state& a, const drive_outputs& out) noexcept {
  constexpr std::uint8_t brake_bits = sim_flag::brake_commanded_open | sim_flag::brake_closed;
  const bool open = out.brake_released;
  if (!k.brake_fitted ||
      (a.flags & brake_bits) == (open ? sim_flag::brake_commanded_open : sim_flag::brake_closed)) {
    return;
  }
  brake_moves(k, a, open);
}

void shaft_follow(const profile& p, const plant_constants& k, axis_state& a, const drive_outputs& out,
                  bool mode_moves, bool brake_holds) noexcept;

// The plant over one cycle under the outputs the drive just decided: first the shaft (with the
// brake as it was at the start of the cycle), then the brake.
void follow(const profile& p, const plant_constants& k, axis_state& a,
            const drive_outputs& out) noexcept {
  a.previous_position = a.position;
  const std::int64_t v_old = a.velocity;
  const bool brake_holds = k.brake_fitted && (a.flags & sim_flag::brake_closed);
  const bool run = out.torque && !brake_holds && p.info(out.current).activity == state_activity::run;
  // The mode moves the shaft while the drive runs and no stop does; in pp a halt too (the target
  // stays and the move resumes when bit 8 falls).
  const bool halt = (a.control_word & control_bit::halt) != 0 && !stop_running(a.core);
  const bool mode_moves = run && (out.ramp == stop_ramp::none ||
                                  (halt && a.operation_mode == cia402::mode::profile_position));
  if (mode_moves && a.operation_mode == cia402::mode::cyclic_synchronous_position) {
    a.mode_status = csp_follow(k, a);
    a.torque = torque_of_motion(k, a, v_old, a.velocity);  // run: torque is on
    brake_follow(k, a, out);
    return;
  }
  shaft_follow(p, k, a, out, mode_moves, brake_holds);
}

// Every mode but a running csp. Out of line: the cycle of a csp axis, which a master streams to
// many at once, does not pay for this one's registers.
[[gnu::noinline]] void shaft_follow(const profile& p, const plant_constants& k, axis_state& a,
                                    const drive_outputs& out, bool mode_moves, bool brake_holds) noexcept {
  const std::int64_t v_old = a.velocity;
  motion::shaft s{a.position, a.position_fraction, a.velocity};
  std::uint16_t status = 0;
  bool torque_set = false;
  if (mode_moves && a.operation_mode != cia402::mode::profile_velocity) {
    status = move_in_mode(k, a, out, s, torque_set);
  } else {
    status = velocity_follow(p, k, a, out, s, brake_holds);
    // No set-point survives a stop, and no run. Bit 4 held high through it is no new edge; one that
    // falls and rises while the mode cannot move (the brake still releasing) waits for it.
    if (a.operation_mode == cia402::mode::profile_position) a.pp.reset(s, a.pp.new_setpoint_seen() && bit_4(a));
    if (a.operation_mode == cia402::mode::homing) a.homing.stand_by(bit_4(a));
    a.demand = s.position;
    a.torque_demand = 0;
    a.following_error_us = 0;
  }
  a.position = s.position;
  a.position_fraction = s.fraction;
  a.velocity = s.velocity;
  if (a.operation_mode == cia402::mode::profile_velocity) {
    if (a.pv_timed) status |= pv_timed_bits(k, a);  // only while 0x606E or 0x6070 asks for it
  } else if (!mode_moves) {
    restart_cyclic(a);  // a cyclic mode resumes from here
  }
  a.mode_status = status;
  if (!torque_set) a.torque = out.torque ? torque_of_motion(k, a, v_old, s.velocity) : 0;
  brake_follow(k, a, out);
}

// The brake on its way to what was commanded, or a new command.
void brake_moves(const plant_constants& k, axis_state& a, bool open) noexcept {
  if (open != ((a.flags & sim_flag::brake_commanded_open) != 0)) {
    set_flag(a, sim_flag::brake_commanded_open, open);
    a.brake_timer = open ? k.release_cycles : k.engage_cycles;
  }
  const bool closed = (a.flags & sim_flag::brake_closed) != 0;
  if (closed == open) {  // not yet where commanded; a command taken back cancels the change
    if (a.brake_timer > 0) --a.brake_timer;
    if (a.brake_timer == 0) set_flag(a, sim_flag::brake_closed, !open);
  }
}

}  // namespace

namespace {

// The inputs a healthy drive has: no fault cause, DC link on, no STO, the connection up.
bool usual_inputs(const axis_state& a) noexcept {
  constexpr std::uint8_t unusual = sim_flag::sto | sim_flag::connection_lost;
  return a.fault_codes[0] == 0 && (a.flags & (sim_flag::dc_link | unusual)) == sim_flag::dc_link;
}

// The fault cause, DC link, STO and connection into the inputs: what usual_inputs() leaves at the
// defaults.
void unusual_inputs_of(const axis_state& a, drive_inputs& in) noexcept {
  const int n = fault_count(a);
  if (n > 0) {
    in.fault_code = a.fault_codes[n - 1];
    in.fault_class = a.fault_classes[n - 1];
  }
  in.dc_link = (a.flags & sim_flag::dc_link) != 0;
  in.sto = (a.flags & sim_flag::sto) != 0;
  in.connection_lost = (a.flags & sim_flag::connection_lost) != 0;
}

// The plant's feedback and the control word into the inputs.
// `set_point`: profile velocity's (pv_set_point()).
inline void feedback_of(const plant_constants& k, const axis_state& a, std::int64_t set_point,
                        drive_inputs& in) noexcept {
  in.control_word = a.control_word;
  const bool standstill = magnitude(a.velocity) <= k.standstill_window;
  in.standstill = standstill;
  in.brake_engaged = brake_engaged(k, a);
  // Profile velocity shows target reached and bit 12 "speed = 0" from the velocity now, held by the
  // times 0x606E and 0x6070 its last cycle counted (pv_timed_bits); every other mode what its
  // motion produced last cycle (move_in_mode).
  std::uint16_t mode_bits = a.mode_status;
  if (a.operation_mode == cia402::mode::profile_velocity) {
    const mode_objects& o = a.objects;
    const bool in_window = magnitude(a.velocity - set_point) <= std::int64_t{o.velocity_window} * micro;
    const bool target_reached =
        in_window && (o.velocity_window_time == 0 || (a.mode_status & status_bit::target_reached) != 0);
    const bool speed_zero = magnitude(a.velocity) <= std::int64_t{o.velocity_threshold} * micro ||
                            (o.velocity_threshold_time != 0 && (a.mode_status & status_bit::speed_zero) != 0);
    mode_bits = static_cast<std::uint16_t>((target_reached ? status_bit::target_reached : 0u) |
                                           (speed_zero ? status_bit::speed_zero : 0u) |
                                           (a.mode_status & status_bit::internal_limit_active));
  }
  // Status bit 11 while a stop at the current or voltage limit is still braking.
  const bool internal_limit = !standstill && static_cast<unsigned>(a.last.ramp) -
                                                     static_cast<unsigned>(stop_ramp::current_limit) <= 1u;
  in.status_bits = static_cast<std::uint16_t>(mode_bits |
                                              (internal_limit ? status_bit::internal_limit_active : 0u));
  in.actual_speed_rpm = velocity_rpm(a);
}

inline drive_inputs inputs_of(const plant_constants& k, const axis_state& a, std::int64_t pv_set_point) noexcept {
  drive_inputs in;
  if (!usual_inputs(a)) unusual_inputs_of(a, in);
  feedback_of(k, a, pv_set_point, in);
  return in;
}

}  // namespace

drive_inputs plant_inputs(const plant_constants& k, const axis_state& a) noexcept {
  return inputs_of(k, a, pv_set_point(k, a));
}

namespace {

// Which bytes of axis_state's first core_source_bytes belong to a field: padding, which a
// struct's assignment need not keep, must not tell a settled axis from a changed one.
struct source_mask {
  unsigned char bytes[core_source_bytes] = {};
  constexpr void mark(std::size_t at, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) bytes[at + i] = 0xFF;
  }
};

constexpr source_mask make_source_mask() {
  source_mask m;
  constexpr std::size_t core = offsetof(axis_state, core);
  m.mark(core + offsetof(axis, current), sizeof(state));
  m.mark(core + offsetof(axis, flags), 1);
  m.mark(core + offsetof(axis, pending_row), 1);
  m.mark(core + offsetof(axis, last_transition), 1);
  m.mark(core + offsetof(axis, error_code), 2);
  m.mark(core + offsetof(axis, options), sizeof(axis::options));
  m.mark(core + offsetof(axis, stop_code), 1);
  constexpr std::size_t last = offsetof(axis_state, last);
  m.mark(last + offsetof(drive_outputs, current), sizeof(state));
  m.mark(last + offsetof(drive_outputs, status_word), 2);
  m.mark(last + offsetof(drive_outputs, transition), 1);
  m.mark(last + offsetof(drive_outputs, ramp), sizeof(stop_ramp));
  m.mark(last + offsetof(drive_outputs, torque), 1);
  m.mark(last + offsetof(drive_outputs, brake_released), 1);
  m.mark(last + offsetof(drive_outputs, clear_setpoints), 1);
  m.mark(last + offsetof(drive_outputs, error_code), 2);
  m.mark(last + offsetof(drive_outputs, error_register), 1);
  m.mark(offsetof(axis_state, control_word), 2);
  m.mark(offsetof(axis_state, mode_status), 2);
  m.mark(offsetof(axis_state, velocity), 8);
  m.mark(offsetof(axis_state, target_velocity), 4);
  m.mark(offsetof(axis_state, fault_codes), sizeof(axis_state::fault_codes));
  m.mark(offsetof(axis_state, fault_classes), sizeof(axis_state::fault_classes));
  m.mark(offsetof(axis_state, flags), 1);
  m.mark(offsetof(axis_state, operation_mode), 1);
  return m;
}

constexpr source_mask source_bytes = make_source_mask();

// The core's axis and its inputs' sources are as a cycle whose step changed nothing left them.
// Eight bytes at a time, padding masked out, ORed into one test (the last word overlaps the one
// before it): a call to memcmp would cost more than the compare.
bool core_settled(const axis_state& a) noexcept {
  static_assert(core_source_bytes >= 8);
  const auto* now = reinterpret_cast<const unsigned char*>(&a);
  const auto word = [](const unsigned char* at) {
    std::uint64_t w;
    std::memcpy(&w, at, 8);
    return w;
  };
  std::uint64_t differ = a.settled_valid ? 0u : 1u;
  for (std::size_t at = 0; at + 8 < core_source_bytes; at += 8) {
    differ |= (word(a.settled + at) ^ word(now + at)) & word(source_bytes.bytes + at);
  }
  constexpr std::size_t tail = core_source_bytes - 8;
  differ |= (word(a.settled + tail) ^ word(now + tail)) & word(source_bytes.bytes + tail);
  return differ == 0;
}

}  // namespace

namespace {

// What the core's decision does to the plant beyond the motion: the set-points it clears, and the
// following error it has reacted to. Out of line: it is rare.
[[gnu::noinline]] void after_decision(axis_state& a) noexcept {
  if (a.last.clear_setpoints) {
    a.flags |= sim_flag::setpoints_cleared;
    // Bit 4 as last seen: an edge in this very cycle (Enable operation with bit 4) still offers one.
    a.pp.reset(motion::shaft{a.position, a.position_fraction, a.velocity}, a.pp.new_setpoint_seen());
  }
  // A following error is an event: once the drive has reacted (FAULT), its cause is gone and a
  // fault reset can clear 0x603F.
  if ((a.flags & sim_flag::following_error_raised) && a.last.current == state::fault) {
    for (int i = 0; i < max_fault_causes; ++i) {
      if (a.fault_codes[i] == following_error_code) {
        remove_fault_at(a, i);
        break;
      }
    }
    a.flags &= static_cast<std::uint8_t>(~sim_flag::following_error_raised);
  }
}

// The core's step, into a.last, from the plant's feedback; the axis is settled after it if the step
// left the core's axis as it was. Out of line: a settled axis (most cycles) does not pay for its
// registers.
[[gnu::noinline]] void decide(const profile& p, const plant_constants& k, axis_state& a) noexcept {
  std::memcpy(a.settled, &a, core_source_bytes);
  // Profile velocity's set-point, kept for the cycles the axis is settled: 0x60FF and the flags are
  // among the compared bytes, the objects are written through write_any_object() only.
  a.pv_set_point = pv_set_point(k, a);
  a.pv_set_point_cut = a.pv_set_point != std::int64_t{effective_target(a)} * micro;
  cia402::step(p, a.core, inputs_of(k, a, a.pv_set_point), a.last);
  a.settled_valid = std::memcmp(a.settled, &a.core, sizeof(axis)) == 0;
  // What follow() would ask of a csp cycle, from fields that stay as they are while the axis is
  // settled (last, flags and operation_mode are among the compared bytes; only decide() writes last).
  constexpr std::uint8_t brake_bits = sim_flag::brake_commanded_open | sim_flag::brake_closed;
  const drive_outputs& out = a.last;
  // The objects it reads here are written only through write_any_object(), which drops the settled
  // copy, so they too stay as they are while the axis is settled.
  const mode_objects& o = a.objects;
  a.settled_csp_runs =
      a.operation_mode == cia402::mode::cyclic_synchronous_position && a.requested_mode == a.operation_mode &&
      out.torque && out.ramp == stop_ramp::none && !out.clear_setpoints &&
      (a.flags & sim_flag::following_error_raised) == 0 &&
      (!k.brake_fitted || (out.brake_released && (a.flags & brake_bits) == sim_flag::brake_commanded_open)) &&
      p.info(out.current).activity == state_activity::run &&
      o.increments_per_rev == k.usual_increments_per_rev && o.interpolation_period_us <= k.cycle_us &&
      speed_limit_rpm(k, a) == k.max_velocity_rpm;
  // What depends on the objects alone, worked out when one was written. Pv, csv and the torque modes
  // need to brake for a software limit only within the braking distance from the top speed (no mode
  // turns the motor faster): beyond it, no root to draw (brake_for_limit). A settled csp axis's demand
  // within the following error window and a cycle's travel has no check to count, no cut to make.
  if (a.objects_written) {
    a.objects_written = false;
    a.pv_timed = (o.velocity_window_time | o.velocity_threshold_time) != 0;
    if (!a.pv_timed) {
      a.in_velocity_window_us = 0;
      a.above_velocity_threshold_us = 0;
    }
    const std::uint64_t rpm = std::uint64_t{k.max_velocity_rpm} + 1;
    const std::uint64_t reach = rpm * rpm * o.increments_per_rev / (120u * std::uint64_t{a.quick_stop_deceleration}) +
                                rpm * o.increments_per_rev * k.cycle_us / 60'000'000u + 2u;
    a.limit_braking_reach = reach < UINT32_MAX ? static_cast<std::uint32_t>(reach) : UINT32_MAX;
    const std::int64_t window =
        o.following_error_window == 0xFFFFFFFFu ? INT64_MAX : std::int64_t{o.following_error_window};
    a.settled_csp_reach = static_cast<std::uint32_t>(window < k.usual_csp_reach ? window : k.usual_csp_reach);
  }
}

}  // namespace

namespace {

// A cycle in full: the core's decision unless the axis is settled, what it does beyond the
// motion, then the plant in whatever mode and state.
[[gnu::noinline]] const drive_outputs& full_cycle(const profile& p, const plant_constants& k,
                                                  axis_state& a, bool settled) noexcept {
  if (a.requested_mode != a.operation_mode) {
    enter_mode(a);  // out of line; the core decides again, on the new mode's (empty) status bits
    settled = false;
  }
  if (!settled) decide(p, k, a);
  if (a.last.clear_setpoints | ((a.flags & sim_flag::following_error_raised) != 0)) after_decision(a);
  follow(p, k, a, a.last);
  return a.last;
}

}  // namespace

const drive_outputs& step_axis(const profile& p, const plant_constants& k, axis_state& a) noexcept {
  // The common cycle of a machine whose master streams csp set-points, handled here with no call:
  // the core settled as a running csp axis (nothing for after_decision(), no stop, the brake where
  // it was commanded, no mode change, the usual resolution, no interpolation, no speed limit below
  // the motor's: decide() worked that out), and the demand within the following error window and a
  // cycle's travel. It does what full_cycle() does for it, byte for byte. Any other cycle goes
  // there.
  const bool settled = core_settled(a);
  if (!(settled & a.settled_csp_runs)) return full_cycle(p, k, a, settled);
  std::uint16_t status = status_bit::drive_follows_command;
  const std::int64_t demand = csp_demand(a, status);
  const std::int64_t step = demand - a.position;
  if (magnitude(step) > std::int64_t{a.settled_csp_reach}) return full_cycle(p, k, a, settled);
  a.demand = demand;
  a.following_error_us = 0;
  const std::int64_t v_old = a.velocity;
  a.previous_position = a.position;
  a.position = demand;
  a.position_fraction = 0;
  a.velocity = step * k.usual_velocity_per_increment;
  a.mode_status = status;
  a.torque = torque_of_motion(k, a, v_old, a.velocity);
  return a.last;
}

}  // namespace cia402::sim
