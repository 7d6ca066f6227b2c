// The plant and the object interface of a virtual drive. Every state-machine decision is the
// core's (cia402::step); this file only turns its outputs into motion and brake, and the motion and
// brake back into its inputs.
#include "cia402/sim/plant.hpp"

#include <cstring>
#include <limits>
#include <stdexcept>

#include "cia402/sim/virtual_drive.hpp"
#include "cia402/words.hpp"

namespace cia402::sim {
namespace {

constexpr std::int64_t micro = 1000000;  // micro-rpm per rpm
// micro-rpm x increments a revolution x cycle [us] of one increment a cycle: 60 s x 1e6 x 1e6.
constexpr std::int64_t csp_velocity_scale = 60'000'000'000'000LL;

// The most increments a cycle the motor's top speed travels in csp (per_rev_us: increments a
// revolution x cycle in us).
std::int64_t csp_reach(const plant_constants& k, std::uint64_t per_rev_us) noexcept {
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(k.max_velocity / micro) * per_rev_us / 60'000'000u);
}

std::int64_t magnitude(std::int64_t v) noexcept { return v < 0 ? -v : v; }

// Cycles a delay takes, at least one: the drive sees a change in the next cycle at the earliest.
std::uint16_t delay_cycles(std::uint32_t delay_us, std::uint32_t cycle_us) noexcept {
  const std::uint64_t cycles = (std::uint64_t{delay_us} + cycle_us - 1) / cycle_us;
  return static_cast<std::uint16_t>(cycles < 1 ? 1 : cycles);
}

// Moves v towards goal: by at most `up` while |v| grows, by at most `down` while it shrinks. A
// change of sign first stops at 0 (the rest of that cycle is not carried over).
std::int64_t approach(std::int64_t v, std::int64_t goal, std::int64_t up,
                      std::int64_t down) noexcept {
  if (v == goal) return v;
  if (v >= 0 && goal > v) return v + up < goal ? v + up : goal;
  if (v <= 0 && goal < v) return v - up > goal ? v - up : goal;
  if (v > 0) {  // goal < v: slow down towards max(goal, 0)
    const std::int64_t floor = goal > 0 ? goal : 0;
    return v - down > floor ? v - down : floor;
  }
  const std::int64_t ceiling = goal < 0 ? goal : 0;  // v < 0, goal > v
  return v + down < ceiling ? v + down : ceiling;
}

// Micro-rpm per cycle of a stop ramp (not coast, not none).
std::int64_t ramp_step(const plant_constants& k, const axis_state& a, stop_ramp r) noexcept {
  const std::int64_t cycle = k.cycle_us;
  switch (r) {
    case stop_ramp::slow_down: return std::int64_t{a.deceleration} * cycle;
    case stop_ramp::quick_stop: return std::int64_t{a.quick_stop_deceleration} * cycle;
    case stop_ramp::current_limit:
      return std::int64_t{a.quick_stop_deceleration} * cycle * k.current_limit_percent / 100;
    case stop_ramp::voltage_limit:
      return std::int64_t{a.deceleration} * cycle * k.voltage_limit_percent / 100;
    case stop_ramp::none:
    case stop_ramp::coast: break;
  }
  return 0;
}

void set_flag(axis_state& a, std::uint8_t flag, bool on) noexcept {
  a.flags = static_cast<std::uint8_t>(on ? (a.flags | flag) : (a.flags & ~flag));
}

bool add_fault_cause(axis_state& a, std::uint16_t code, std::uint8_t error_class) noexcept;

__extension__ typedef __int128 wide;

constexpr std::int64_t sign_of(std::int64_t v) noexcept { return (v > 0) - (v < 0); }

std::int64_t clamp(std::int64_t v, std::int64_t lo, std::int64_t hi) noexcept {
  return v < lo ? lo : (v > hi ? hi : v);
}

// A mode change takes effect at the start of the next cycle's motion: the new mode takes the shaft
// over as it is (pp with no set-point brakes it, homing waits for its start), and 0x6061 shows it.
[[gnu::noinline]] void enter_mode(axis_state& a) noexcept {
  a.operation_mode = a.requested_mode;
  a.pp.reset(motion::shaft{a.position, a.position_fraction, a.velocity});
  a.homing.reset();
  a.demand = a.position;
  a.torque_demand = a.torque;
  a.following_error_us = 0;
  a.mode_status = 0;
}

// 0x607D: on when the minimum lies below the maximum.
bool limits_on(const axis_state& a) noexcept { return a.objects.min_position < a.objects.max_position; }

// Moving outwards at or past a software limit.
bool beyond_limit(const axis_state& a, std::int64_t position, std::int64_t velocity) noexcept {
  return limits_on(a) && ((position >= a.objects.max_position && velocity > 0) ||
                          (position <= a.objects.min_position && velocity < 0));
}

// Micro-rpm per cycle of a stop ramp (not coast, not none).
std::int64_t ramp_step(const plant_constants& k, const axis_state& a, stop_ramp r) noexcept;

// The velocity modes' plant (profile velocity, and every mode while a stop runs or torque is off):
// the velocity approaches its goal on the ramps, the position integrates it.
void velocity_follow(const profile& p, const plant_constants& k, axis_state& a,
                     const drive_outputs& out, motion::shaft& s, bool brake_holds) noexcept {
  const std::int64_t cycle = k.cycle_us;
  std::int64_t goal = 0;
  std::int64_t up = 0;
  std::int64_t down = 0;
  if (!out.torque) {
    down = k.coast_step;  // coasting: friction only
  } else if (out.ramp != stop_ramp::none && out.ramp != stop_ramp::coast) {
    down = ramp_step(k, a, out.ramp);
  } else if (p.info(out.current).activity == state_activity::run && a.operation_mode == cia402::mode::profile_velocity) {
    goal = std::int64_t{effective_target(a)} * micro;
    up = std::int64_t{a.acceleration} * cycle;
    down = std::int64_t{a.deceleration} * cycle;
    if (beyond_limit(a, s.position, goal)) {  // a software limit stops on the quick-stop ramp
      goal = 0;
      down = std::int64_t{a.quick_stop_deceleration} * cycle;
    }
  } else {
    down = std::int64_t{a.deceleration} * cycle;  // torque held without motion (e.g. hold states)
  }
  if (brake_holds) {
    goal = 0;  // an engaged (or still releasing) brake holds the shaft: nothing accelerates
    up = 0;
    down += k.brake_step;
  }
  motion::advance(s, approach(s.velocity, goal, up, down), k.cycle_us, a.objects.increments_per_rev);
}

// The torque modes' shaft: the motor's torque against friction and the load accelerates the inertia.
void torque_follow(const plant_constants& k, axis_state& a, motion::shaft& s,
                   std::int64_t torque) noexcept {
  const std::int64_t v = s.velocity;
  std::int64_t net = torque - k.load;
  if (v != 0) {
    net -= sign_of(v) * k.friction;
  } else {
    net = net > k.friction ? net - k.friction : (net < -k.friction ? net + k.friction : 0);
  }
  std::int64_t v_new = v + net * k.torque_acceleration / 1000 * std::int64_t{k.cycle_us};
  if (v != 0 && sign_of(v_new) != sign_of(v) && sign_of(torque - k.load) != sign_of(v_new)) {
    v_new = 0;  // friction stops the shaft; it does not turn it back
  }
  v_new = clamp(v_new, -k.max_velocity, k.max_velocity);
  if (beyond_limit(a, s.position, v_new)) {
    v_new = approach(v, 0, 0, std::int64_t{a.quick_stop_deceleration} * k.cycle_us);
    a.mode_status |= status_bit::internal_limit_active;
  }
  motion::advance(s, v_new, k.cycle_us, a.objects.increments_per_rev);
}

// The torque a velocity change took (permille): inertia, friction and load. What 0x6077 shows in
// the modes that command a velocity or a position.
std::int32_t torque_of_motion(const plant_constants& k, const axis_state& a, std::int64_t v_old,
                              std::int64_t v_new) noexcept {
  // micro-rpm per microsecond is rpm/s. At constant speed (standstill, a cruise, a csp ramp) there
  // is no acceleration torque: two divisions a cycle are skipped.
  if (v_new == v_old && v_new != 0) {  // a cruise: friction and load, |t| <= 2000
    return static_cast<std::int32_t>((v_new > 0 ? k.friction : -k.friction) + k.load);
  }
  const std::int64_t inertia =
      v_new == v_old ? 0
                     : (v_new - v_old) / std::int64_t{k.cycle_us} * 1000 /
                           (k.torque_acceleration ? k.torque_acceleration : 1);
  const std::int64_t moving = v_new != 0 ? v_new : v_old;
  const std::int64_t t = inertia + sign_of(moving) * k.friction + (moving != 0 || a.torque != 0 ? k.load : 0);
  return static_cast<std::int32_t>(clamp(t, -32768, 32767));
}

// The following error check of the position modes (0x6065, 0x6066): beyond the window for longer
// than the time out, status bit 13 and the fault 0x8611 (which the drive answers by 0x605E).
// Out of line: a position mode's cycle within the window (nearly all of them) keeps no registers for it.
[[gnu::noinline]] bool following_error_beyond_window(const plant_constants& k, axis_state& a) noexcept;

// The demand is within 0x6065's window of the actual position (or there is no window).
bool within_window(const axis_state& a, std::int64_t demand) noexcept {
  const std::uint32_t window = a.objects.following_error_window;
  const std::int64_t error = demand - a.position;
  return window == 0xFFFFFFFFu || (error < 0 ? -error : error) <= std::int64_t{window};
}

bool following_error_check(const plant_constants& k, axis_state& a) noexcept {
  if (within_window(a, a.demand)) {
    a.following_error_us = 0;
    return false;
  }
  return following_error_beyond_window(k, a);
}

bool following_error_beyond_window(const plant_constants& k, axis_state& a) noexcept {
  const std::uint32_t room = UINT32_MAX - a.following_error_us;
  a.following_error_us += k.cycle_us < room ? k.cycle_us : room;
  if (a.following_error_us <= std::uint32_t{a.objects.following_error_time_out} * 1000u) return false;
  if (!(a.flags & sim_flag::following_error_raised)) {
    a.flags |= sim_flag::following_error_raised;
    add_fault_cause(a, following_error_code, 2);
  }
  return true;
}

// Cyclic synchronous position while the drive runs: the set-point of this cycle (sampled at SYNC on
// CANopen) is reached within the cycle unless the motor's top speed cannot. Works on the axis
// directly, apart from the other modes: it is the mode a master streams to many axes every cycle.

// The demand of a csp cycle: 0x607A + 0x60B0, cut to the software limits (status bit 11 then).
std::int64_t csp_demand(const axis_state& a, std::uint16_t& status) noexcept {
  const mode_objects& o = a.objects;
  std::int64_t demand = std::int64_t{o.target_position} + o.position_offset;
  if (limits_on(a)) {
    const std::int64_t cut = clamp(demand, o.min_position, o.max_position);
    if (cut != demand) status |= status_bit::internal_limit_active;
    demand = cut;
  }
  return demand;
}

// The shaft's move of a csp cycle to the demand at the usual resolution (0x608F as the plant
// constants have it): the reach and the velocity of an increment are worked out beforehand.
void csp_move_usual(const plant_constants& k, axis_state& a, std::int64_t demand) noexcept {
  const std::int64_t step = clamp(demand - a.position, -k.usual_csp_reach, k.usual_csp_reach);
  a.position += step;
  a.position_fraction = 0;
  a.velocity = step * k.usual_velocity_per_increment;
}

// The shaft's move of a csp cycle to the demand.
void csp_move(const plant_constants& k, axis_state& a, std::int64_t demand) noexcept {
  const mode_objects& o = a.objects;
  // (usual_increments_per_rev is 0 when there is no such figure; 0x608F is at least 1.)
  if (o.increments_per_rev == k.usual_increments_per_rev) {
    csp_move_usual(k, a, demand);
    return;
  }
  // Top speed [rpm] x increments a revolution x cycle [us] stays below 2^61 (1e5 x 2^24 x 1e6):
  // 64-bit arithmetic, no 128-bit division in the cycle of a thousand axes.
  const std::uint64_t per_rev_us = std::uint64_t{o.increments_per_rev} * k.cycle_us;
  const std::int64_t reach = csp_reach(k, per_rev_us);
  const std::int64_t step = clamp(demand - a.position, -reach, reach);
  a.position += step;
  a.position_fraction = 0;
  // micro-rpm = step x 60e12 / (increments a revolution x cycle), exact in 64 bits while
  // |step| <= 153,000; beyond, in 128.
  constexpr std::int64_t scale = csp_velocity_scale;
  constexpr std::int64_t exact_64 = INT64_MAX / scale;
  a.velocity = (step <= exact_64 && step >= -exact_64)
                   ? step * scale / static_cast<std::int64_t>(per_rev_us)
                   : static_cast<std::int64_t>(static_cast<wide>(step) * scale / static_cast<wide>(per_rev_us));
}

// One csp cycle. Returns the mode's status bits.
std::uint16_t csp_follow(const plant_constants& k, axis_state& a) noexcept {
  std::uint16_t status = 1u << 12;  // the drive follows the command value
  const std::int64_t demand = csp_demand(a, status);
  a.demand = demand;
  // The following error of this cycle: the new demand against where the shaft was.
  if (following_error_check(k, a)) status |= 1u << 13;
  csp_move(k, a, demand);
  return status;
}

// One cycle of the shaft in a mode other than profile velocity, while the drive runs. Returns the
// mode's status bits (10..13).
std::uint16_t move_in_mode(const plant_constants& k, axis_state& a, const drive_outputs& out,
                           motion::shaft& s, bool& torque_set) noexcept {
  const mode_objects& o = a.objects;
  const std::uint16_t cw = a.control_word;
  const bool cleared = (a.flags & sim_flag::setpoints_cleared) != 0;
  std::uint16_t status = 0;
  switch (a.operation_mode) {
    case cia402::mode::profile_position: {
      motion::pp_command cmd;
      cmd.new_setpoint = (cw & (1u << 4)) != 0;
      cmd.change_immediately = (cw & (1u << 5)) != 0;
      cmd.relative = (cw & (1u << 6)) != 0;
      cmd.halt = out.ramp != stop_ramp::none;  // only a halt reaches here with a ramp (follow)
      cmd.change_on_setpoint = (cw & (1u << 9)) != 0;
      cmd.target = o.target_position;
      motion::pp_parameters par;
      par.profile_velocity_rpm = o.profile_velocity;
      par.end_velocity_rpm = o.end_velocity;
      par.acceleration_rpm_s = a.acceleration;
      // A halt brakes on the ramp 0x605D chose (S8).
      par.deceleration_rpm_s = out.ramp != stop_ramp::none
                                   ? static_cast<std::uint32_t>(ramp_step(k, a, out.ramp) / k.cycle_us)
                                   : a.deceleration;
      par.position_window = o.position_window;
      par.position_window_time_ms = o.position_window_time;
      par.increments_per_rev = o.increments_per_rev;
      if (limits_on(a)) {
        par.min_position = o.min_position;
        par.max_position = o.max_position;
      }
      const motion::pp_status st = a.pp.step(cmd, par, k.cycle_us);
      s = a.pp.state();
      a.demand = st.demand;
      status = static_cast<std::uint16_t>((st.target_reached ? status_bit::target_reached : 0u) |
                                          (st.setpoint_acknowledge ? 1u << 12 : 0u) |
                                          (st.limited ? status_bit::internal_limit_active : 0u));
      break;
    }
    case cia402::mode::homing: {
      motion::homing_parameters par;
      par.method = o.homing_method;
      par.switch_speed_rpm = o.homing_switch_speed;
      par.zero_speed_rpm = o.homing_zero_speed;
      par.acceleration_rpm_s = o.homing_acceleration;
      par.home_offset = o.home_offset;
      par.increments_per_rev = o.increments_per_rev;
      par.home_switch_at = k.home_switch_position;
      par.index_at = k.index_position;
      const motion::homing_status st = a.homing.step((cw & (1u << 4)) != 0, par, s, k.cycle_us);
      a.demand = s.position;
      status = static_cast<std::uint16_t>((st.target_reached ? status_bit::target_reached : 0u) |
                                          (st.attained ? 1u << 12 : 0u) | (st.error ? 1u << 13 : 0u));
      break;
    }
    case cia402::mode::cyclic_synchronous_velocity: {
      const std::int64_t goal = clamp((std::int64_t{cleared ? 0 : a.target_velocity} + o.velocity_offset) * micro,
                                      -k.max_velocity, k.max_velocity);
      std::int64_t v_new = approach(s.velocity, goal, k.max_acceleration_step, k.max_acceleration_step);
      if (beyond_limit(a, s.position, v_new)) {
        v_new = approach(s.velocity, 0, 0, std::int64_t{a.quick_stop_deceleration} * k.cycle_us);
        status |= status_bit::internal_limit_active;
      }
      motion::advance(s, v_new, k.cycle_us, o.increments_per_rev);
      a.demand = s.position;
      status |= 1u << 12;
      break;
    }
    case cia402::mode::profile_torque:
    case cia402::mode::cyclic_synchronous_torque: {
      const std::int64_t target = cleared ? 0 : o.target_torque;
      std::int64_t demand;
      if (a.operation_mode == cia402::mode::profile_torque) {
        // The demand ramps to the target at the torque slope 0x6087.
        const std::int64_t slope = std::int64_t{o.torque_slope} * k.cycle_us / 1'000'000;
        const std::int64_t step_max = slope > 0 ? slope : 1;
        demand = a.torque_demand + clamp(target - a.torque_demand, -step_max, step_max);
        if (demand == target) status |= status_bit::target_reached;
      } else {
        demand = clamp(target + o.torque_offset, -32768, 32767);
        status |= 1u << 12;
      }
      a.torque_demand = static_cast<std::int32_t>(demand);
      a.mode_status = 0;
      torque_follow(k, a, s, demand);
      status |= a.mode_status;
      a.torque = a.torque_demand;
      torque_set = true;
      a.demand = s.position;
      break;
    }
    default: break;
  }
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
                  bool run, bool mode_moves, bool brake_holds) noexcept;

// The plant over one cycle under the outputs the drive just decided: first the shaft (with the
// brake as it was at the start of the cycle), then the brake.
void follow(const profile& p, const plant_constants& k, axis_state& a,
            const drive_outputs& out) noexcept {
  if (a.requested_mode != a.operation_mode) enter_mode(a);  // out of line
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
  shaft_follow(p, k, a, out, run, mode_moves, brake_holds);
}

// Every mode but a running csp. Out of line: the cycle of a csp axis, which a master streams to
// many at once, does not pay for this one's registers.
[[gnu::noinline]] void shaft_follow(const profile& p, const plant_constants& k, axis_state& a,
                                    const drive_outputs& out, bool run, bool mode_moves,
                                    bool brake_holds) noexcept {
  const std::int64_t v_old = a.velocity;
  motion::shaft s{a.position, a.position_fraction, a.velocity};
  std::uint16_t status = 0;
  bool torque_set = false;
  if (mode_moves && a.operation_mode != cia402::mode::profile_velocity) {
    status = move_in_mode(k, a, out, s, torque_set);
  } else {
    velocity_follow(p, k, a, out, s, brake_holds);
    if (a.operation_mode == cia402::mode::profile_position) a.pp.reset(s);  // no set-point survives a stop
    if (a.operation_mode == cia402::mode::homing) a.homing.interrupt();
    a.demand = s.position;
    a.torque_demand = 0;
    a.following_error_us = 0;
    if (a.operation_mode == cia402::mode::profile_velocity && run && out.ramp == stop_ramp::none &&
        beyond_limit(a, s.position, effective_target(a))) {
      status |= status_bit::internal_limit_active;
    }
  }
  a.position = s.position;
  a.position_fraction = s.fraction;
  a.velocity = s.velocity;
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

int fault_count(const axis_state& a) noexcept {
  int n = 0;
  while (n < max_fault_causes && a.fault_codes[n] != 0) ++n;
  return n;
}

void remove_fault_at(axis_state& a, int i) noexcept {
  for (int j = i; j + 1 < max_fault_causes; ++j) {
    a.fault_codes[j] = a.fault_codes[j + 1];
    a.fault_classes[j] = a.fault_classes[j + 1];
  }
  a.fault_codes[max_fault_causes - 1] = 0;
  a.fault_classes[max_fault_causes - 1] = 0;
}

bool add_fault_cause(axis_state& a, std::uint16_t code, std::uint8_t error_class) noexcept {
  if (code == 0) return false;
  for (int i = 0; i < max_fault_causes; ++i) {
    if (a.fault_codes[i] == code) {
      remove_fault_at(a, i);
      break;
    }
  }
  bool kept_all = true;
  if (fault_count(a) == max_fault_causes) {
    remove_fault_at(a, 0);
    kept_all = false;
  }
  const int n = fault_count(a);
  a.fault_codes[n] = code;
  a.fault_classes[n] = error_class;
  return kept_all;
}

}  // namespace

const char* check_plant_config(const plant_config& c) noexcept {
  if (c.cycle_us < 1 || c.cycle_us > 1000000) return "cycle must be 1 us .. 1 s";
  if (std::uint64_t{c.brake_engage_delay_us} > std::uint64_t{c.cycle_us} * 65535) {
    return "brake engage delay must be at most 65535 cycles";
  }
  if (std::uint64_t{c.brake_release_delay_us} > std::uint64_t{c.cycle_us} * 65535) {
    return "brake release delay must be at most 65535 cycles";
  }
  if (c.brake_deceleration < 1) return "brake deceleration must be at least 1 rpm/s";
  if (c.current_limit_percent < 1 || c.current_limit_percent > 1000) {
    return "current limit percent must be 1..1000";
  }
  if (c.voltage_limit_percent < 1 || c.voltage_limit_percent > 1000) {
    return "voltage limit percent must be 1..1000";
  }
  if (c.standstill_window_rpm > 1000000) return "standstill window must be at most 1000000 rpm";
  if (c.target_window_rpm > 1000000) return "target window must be at most 1000000 rpm";
  if (c.max_velocity_rpm < 1 || c.max_velocity_rpm > 100000) return "max velocity must be 1..100000 rpm";
  if (c.max_acceleration_rpm_s < 1 || c.max_acceleration_rpm_s > 100000000) {
    return "max acceleration must be 1..100000000 rpm/s";
  }
  if (c.torque_acceleration_rpm_s < 1 || c.torque_acceleration_rpm_s > 100000000) {
    return "torque acceleration must be 1..100000000 rpm/s";
  }
  if (c.friction_permille > 1000) return "friction must be 0..1000 permille";
  if (c.load_permille < -1000 || c.load_permille > 1000) return "load must be -1000..1000 permille";
  constexpr std::int64_t reach = std::int64_t{1} << 40;
  if (c.home_switch_position < -reach || c.home_switch_position > reach ||
      c.index_position < -reach || c.index_position > reach) {
    return "home switch and index positions must be within +-2^40 increments";
  }
  return nullptr;
}

plant_constants plant_constants::from(const plant_config& c) noexcept {
  plant_constants k;
  k.cycle_us = c.cycle_us;
  k.coast_step = std::int64_t{c.coast_deceleration} * c.cycle_us;
  k.brake_step = std::int64_t{c.brake_deceleration} * c.cycle_us;
  k.standstill_window = std::int64_t{c.standstill_window_rpm} * micro;
  k.target_window = std::int64_t{c.target_window_rpm} * micro;
  k.engage_cycles = delay_cycles(c.brake_engage_delay_us, c.cycle_us);
  k.release_cycles = delay_cycles(c.brake_release_delay_us, c.cycle_us);
  k.current_limit_percent = static_cast<std::uint16_t>(c.current_limit_percent);
  k.voltage_limit_percent = static_cast<std::uint16_t>(c.voltage_limit_percent);
  k.brake_fitted = c.brake_fitted;
  k.max_velocity = std::int64_t{c.max_velocity_rpm} * micro;
  k.max_acceleration_step = std::int64_t{c.max_acceleration_rpm_s} * c.cycle_us;
  k.torque_acceleration = c.torque_acceleration_rpm_s;
  k.friction = static_cast<std::int32_t>(c.friction_permille);
  k.load = c.load_permille;
  k.home_switch_position = c.home_switch_position;
  k.index_position = c.index_position;
  // The csp velocity of one increment a cycle at the default resolution, when it is an integer.
  const object_description* resolution = find_drive_object(object::position_encoder_resolution, 1);
  const std::uint64_t per_rev_us = (resolution != nullptr ? static_cast<std::uint64_t>(resolution->default_value) : 0) *
                                   c.cycle_us;
  if (per_rev_us != 0 && csp_velocity_scale % per_rev_us == 0) {
    k.usual_increments_per_rev = static_cast<std::uint32_t>(resolution->default_value);
    k.usual_velocity_per_increment = static_cast<std::int64_t>(csp_velocity_scale / per_rev_us);
    k.usual_csp_reach = csp_reach(k, per_rev_us);
  }
  return k;
}

namespace {

// The default of an entry of the one object table.
std::int64_t default_of(std::uint16_t index, std::uint8_t sub = 0) noexcept {
  const object_description* o = find_drive_object(index, sub);
  return o != nullptr ? o->default_value : 0;
}

template <typename T>
T default_as(std::uint16_t index, std::uint8_t sub = 0) noexcept {
  return static_cast<T>(default_of(index, sub));
}

}  // namespace

axis_state make_axis_state(const profile& p) noexcept {
  axis_state a;
  a.core = make_axis(p);
  a.acceleration = default_as<std::uint32_t>(object::profile_acceleration);
  a.deceleration = default_as<std::uint32_t>(object::profile_deceleration);
  a.quick_stop_deceleration = default_as<std::uint32_t>(object::quick_stop_deceleration);
  a.requested_mode = a.operation_mode = default_as<std::int8_t>(object::modes_of_operation);
  mode_objects& o = a.objects;
  o.min_position = default_as<std::int32_t>(object::software_position_limit, 1);
  o.max_position = default_as<std::int32_t>(object::software_position_limit, 2);
  o.profile_velocity = default_as<std::uint32_t>(object::profile_velocity);
  o.end_velocity = default_as<std::uint32_t>(object::end_velocity);
  o.torque_slope = default_as<std::uint32_t>(object::torque_slope);
  o.following_error_window = default_as<std::uint32_t>(object::following_error_window);
  o.position_window = default_as<std::uint32_t>(object::position_window);
  o.increments_per_rev = default_as<std::uint32_t>(object::position_encoder_resolution, 1);
  o.homing_switch_speed = default_as<std::uint32_t>(object::homing_speeds, 1);
  o.homing_zero_speed = default_as<std::uint32_t>(object::homing_speeds, 2);
  o.homing_acceleration = default_as<std::uint32_t>(object::homing_acceleration);
  o.following_error_time_out = default_as<std::uint16_t>(object::following_error_time_out);
  o.position_window_time = default_as<std::uint16_t>(object::position_window_time);
  o.homing_method = default_as<std::int8_t>(object::homing_method);
  o.interpolation_value = default_as<std::uint8_t>(object::interpolation_time_period, 1);
  o.interpolation_index = default_as<std::int8_t>(object::interpolation_time_period, 2);
  a.pp.reset(0);
  return a;
}

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
inline void feedback_of(const plant_constants& k, const axis_state& a, drive_inputs& in) noexcept {
  in.control_word = a.control_word;
  const bool standstill = magnitude(a.velocity) <= k.standstill_window;
  in.standstill = standstill;
  in.brake_engaged = brake_engaged(k, a);
  // Profile velocity shows target reached and bit 12 "speed = 0" from the velocity; every other
  // mode what its motion produced last cycle (move_in_mode).
  std::uint16_t mode_bits = a.mode_status;
  if (a.operation_mode == cia402::mode::profile_velocity) {
    const bool target_reached =
        magnitude(a.velocity - std::int64_t{effective_target(a)} * micro) <= k.target_window;
    mode_bits = static_cast<std::uint16_t>((target_reached ? status_bit::target_reached : 0u) |
                                           (standstill ? 0x1000u : 0u) |
                                           (a.mode_status & status_bit::internal_limit_active));
  }
  // Status bit 11 while a stop at the current or voltage limit is still braking.
  const bool internal_limit = !standstill && static_cast<unsigned>(a.last.ramp) -
                                                     static_cast<unsigned>(stop_ramp::current_limit) <= 1u;
  in.status_bits = static_cast<std::uint16_t>(mode_bits |
                                              (internal_limit ? status_bit::internal_limit_active : 0u));
  in.actual_speed_rpm = velocity_rpm(a);
}

inline drive_inputs inputs_of(const plant_constants& k, const axis_state& a) noexcept {
  drive_inputs in;
  if (!usual_inputs(a)) unusual_inputs_of(a, in);
  feedback_of(k, a, in);
  return in;
}

}  // namespace

drive_inputs plant_inputs(const plant_constants& k, const axis_state& a) noexcept {
  return inputs_of(k, a);
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
    a.pp.reset(motion::shaft{a.position, a.position_fraction, a.velocity});
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
  cia402::step(p, a.core, inputs_of(k, a), a.last);
  a.settled_valid = std::memcmp(a.settled, &a.core, sizeof(axis)) == 0;
  // What follow() would ask of a csp cycle, from fields that stay as they are while the axis is
  // settled (last, flags and operation_mode are among the compared bytes; only decide() writes last).
  constexpr std::uint8_t brake_bits = sim_flag::brake_commanded_open | sim_flag::brake_closed;
  const drive_outputs& out = a.last;
  a.settled_csp_runs =
      a.operation_mode == cia402::mode::cyclic_synchronous_position && out.torque &&
      out.ramp == stop_ramp::none && !out.clear_setpoints &&
      (a.flags & sim_flag::following_error_raised) == 0 &&
      (!k.brake_fitted || (out.brake_released && (a.flags & brake_bits) == sim_flag::brake_commanded_open)) &&
      p.info(out.current).activity == state_activity::run;
}

}  // namespace

namespace {

// A cycle in full: the core's decision unless the axis is settled, what it does beyond the
// motion, then the plant in whatever mode and state.
[[gnu::noinline]] const drive_outputs& full_cycle(const profile& p, const plant_constants& k,
                                                  axis_state& a, bool settled) noexcept {
  if (!settled) decide(p, k, a);
  if (a.last.clear_setpoints | ((a.flags & sim_flag::following_error_raised) != 0)) after_decision(a);
  follow(p, k, a, a.last);
  return a.last;
}

}  // namespace

const drive_outputs& step_axis(const profile& p, const plant_constants& k, axis_state& a) noexcept {
  // The common cycle of a machine whose master streams csp set-points, handled here with no call:
  // the core settled as a running csp axis (nothing for after_decision(), no stop, the brake where
  // it was commanded: decide() worked that out), no mode change, the usual resolution, and the
  // demand within the following error window. It does what full_cycle() does for it, byte for
  // byte. Any other cycle goes there.
  const bool settled = core_settled(a);
  const bool usual = settled & a.settled_csp_runs & (a.requested_mode == a.operation_mode) &
                     (a.objects.increments_per_rev == k.usual_increments_per_rev);
  if (!usual) return full_cycle(p, k, a, settled);
  std::uint16_t status = 1u << 12;  // the drive follows the command value
  const std::int64_t demand = csp_demand(a, status);
  if (!within_window(a, demand)) return full_cycle(p, k, a, settled);
  a.demand = demand;
  a.following_error_us = 0;
  const std::int64_t v_old = a.velocity;
  csp_move_usual(k, a, demand);
  a.mode_status = status;
  a.torque = torque_of_motion(k, a, v_old, a.velocity);
  return a.last;
}

namespace {

// The option codes' indices (0x605A..0x605E, 0x6007): one range test.
constexpr bool is_option_index(std::uint16_t index) noexcept {
  return index == 0x6007 || static_cast<unsigned>(index - 0x605A) <= 4u;
}

// Why index/sub is not an object of this drive (find_drive_object found no entry).
sdo_abort missing(std::uint16_t index) noexcept {
  return find_drive_object(index, 0) == nullptr ? sdo_abort::object_does_not_exist
                                                : sdo_abort::sub_index_does_not_exist;
}

// The object at index/sub as this drive has it: from the one object table, an option code only
// where the profile has it. Existence, sub-index, access and range are checked here for every
// object alike; what a value means is the switch's below. One table lookup when the object exists.
sdo_abort describe(const profile& p, std::uint16_t index, std::uint8_t sub,
                   const object_description*& out) noexcept {
  out = find_drive_object(index, sub);
  option o;
  if (is_option_index(index) && option_of_index(index, o) && !p.spec(o).exists()) {
    return sdo_abort::object_does_not_exist;
  }
  return out != nullptr ? sdo_abort::none : missing(index);
}

// The set-point objects end the "set-points cleared" of T4 when written.
void setpoint_written(axis_state& a) noexcept { set_flag(a, sim_flag::setpoints_cleared, false); }

}  // namespace

sdo_abort detail::write_any_object(const profile& p, axis_state& a, std::uint16_t index,
                                   std::uint8_t sub, std::int64_t value) noexcept {
  if (index == object::error_register) {
    return sub != 0 ? sdo_abort::sub_index_does_not_exist : sdo_abort::read_only_object;
  }
  const object_description* o = nullptr;
  if (const sdo_abort r = describe(p, index, sub, o); r != sdo_abort::none) return r;
  if (const sdo_abort r = check_write(*o, value); r != sdo_abort::none) return r;
  if (is_option_index(index)) return write_option(p, a.core, index, static_cast<std::int32_t>(value));
  mode_objects& m = a.objects;
  const auto i32 = static_cast<std::int32_t>(value);
  const auto u32 = static_cast<std::uint32_t>(value);
  switch (index) {
    case object::control_word: a.control_word = static_cast<std::uint16_t>(value); break;
    case object::target_velocity:
      a.target_velocity = i32;
      setpoint_written(a);
      break;
    case object::profile_acceleration: a.acceleration = u32; break;
    case object::profile_deceleration: a.deceleration = u32; break;
    case object::quick_stop_deceleration: a.quick_stop_deceleration = u32; break;
    case object::modes_of_operation: {
      const object_description* supported = find_drive_object(object::supported_drive_modes);
      if (supported == nullptr || !(cia402::mode::supported_bit(value) &
                                    static_cast<std::uint32_t>(supported->default_value))) {
        return sdo_abort::invalid_value;
      }
      a.requested_mode = static_cast<std::int8_t>(value);
      break;
    }
    case object::target_position:
      m.target_position = i32;
      setpoint_written(a);
      break;
    case object::target_torque:
      m.target_torque = static_cast<std::int16_t>(value);
      setpoint_written(a);
      break;
    case object::position_offset: m.position_offset = i32; break;
    case object::velocity_offset: m.velocity_offset = i32; break;
    case object::torque_offset: m.torque_offset = static_cast<std::int16_t>(value); break;
    case object::home_offset: m.home_offset = i32; break;
    case object::software_position_limit:
      (sub == 1 ? m.min_position : m.max_position) = i32;
      break;
    case object::profile_velocity: m.profile_velocity = u32; break;
    case object::end_velocity: m.end_velocity = u32; break;
    case object::torque_slope: m.torque_slope = u32; break;
    case object::following_error_window: m.following_error_window = u32; break;
    case object::following_error_time_out: m.following_error_time_out = static_cast<std::uint16_t>(value); break;
    case object::position_window: m.position_window = u32; break;
    case object::position_window_time: m.position_window_time = static_cast<std::uint16_t>(value); break;
    case object::position_encoder_resolution:
      if (sub == 1) m.increments_per_rev = u32;
      break;  // sub 2 (motor revolutions) takes only 1: the table's limits
    case object::homing_method:
      if (!motion::homing::supports(value)) return sdo_abort::invalid_value;
      m.homing_method = static_cast<std::int8_t>(value);
      break;
    case object::homing_speeds: (sub == 1 ? m.homing_switch_speed : m.homing_zero_speed) = u32; break;
    case object::homing_acceleration: m.homing_acceleration = u32; break;
    case object::interpolation_time_period:
      if (sub == 1) m.interpolation_value = static_cast<std::uint8_t>(value);
      else m.interpolation_index = static_cast<std::int8_t>(value);
      break;
    default: return sdo_abort::object_does_not_exist;
  }
  return sdo_abort::none;
}

sdo_abort read_object(const profile& p, const axis_state& a, std::uint16_t index, std::uint8_t sub,
                      std::int64_t& value) noexcept {
  if (index == object::error_register) {
    if (sub != 0) return sdo_abort::sub_index_does_not_exist;
    value = error_register_of(a.core.error_code);
    return sdo_abort::none;
  }
  const object_description* o = nullptr;
  if (const sdo_abort r = describe(p, index, sub, o); r != sdo_abort::none) return r;
  if (o->access == object_access::write_only) return sdo_abort::write_only_object;
  if (is_option_index(index)) {
    std::int32_t v = 0;
    const sdo_abort r = read_option(p, a.core, index, v);
    if (r == sdo_abort::none) value = v;
    return r;
  }
  if (sub == 0 && o->access == object_access::read_only && o->low == o->high) {
    value = o->default_value;  // sub-index 0 of an array or record: its entry count
    return sdo_abort::none;
  }
  const mode_objects& m = a.objects;
  // Positions are INTEGER32 on the bus: they wrap as a 32-bit encoder count does.
  const auto wrap = [](std::int64_t v) { return static_cast<std::int64_t>(static_cast<std::int32_t>(v)); };
  switch (index) {
    case object::control_word: value = a.control_word; break;
    case object::status_word: value = a.last.status_word; break;
    case object::target_velocity: value = a.target_velocity; break;
    case object::velocity_actual_value: value = velocity_rpm(a); break;
    case object::profile_acceleration: value = a.acceleration; break;
    case object::profile_deceleration: value = a.deceleration; break;
    case object::quick_stop_deceleration: value = a.quick_stop_deceleration; break;
    case object::error_code: value = a.core.error_code; break;
    case object::modes_of_operation: value = a.requested_mode; break;
    case object::modes_of_operation_display: value = a.operation_mode; break;
    case object::supported_drive_modes: value = o->default_value; break;
    case object::position_demand_value: value = wrap(a.demand); break;
    case object::position_actual_value: value = wrap(a.position); break;
    case object::following_error_actual_value: value = wrap(following_error(a)); break;
    case object::torque_actual_value: value = a.torque; break;
    case object::target_position: value = m.target_position; break;
    case object::target_torque: value = m.target_torque; break;
    case object::position_offset: value = m.position_offset; break;
    case object::velocity_offset: value = m.velocity_offset; break;
    case object::torque_offset: value = m.torque_offset; break;
    case object::home_offset: value = m.home_offset; break;
    case object::software_position_limit: value = sub == 1 ? m.min_position : m.max_position; break;
    case object::profile_velocity: value = m.profile_velocity; break;
    case object::end_velocity: value = m.end_velocity; break;
    case object::torque_slope: value = m.torque_slope; break;
    case object::following_error_window: value = m.following_error_window; break;
    case object::following_error_time_out: value = m.following_error_time_out; break;
    case object::position_window: value = m.position_window; break;
    case object::position_window_time: value = m.position_window_time; break;
    case object::position_encoder_resolution: value = sub == 1 ? m.increments_per_rev : 1; break;
    case object::homing_method: value = m.homing_method; break;
    case object::homing_speeds: value = sub == 1 ? m.homing_switch_speed : m.homing_zero_speed; break;
    case object::homing_acceleration: value = m.homing_acceleration; break;
    case object::interpolation_time_period:
      value = sub == 1 ? m.interpolation_value : m.interpolation_index;
      break;
    default: return sdo_abort::object_does_not_exist;
  }
  return sdo_abort::none;
}

bool drive_view::inject_fault(std::uint16_t code, std::uint8_t error_class) noexcept {
  return add_fault_cause(*axis_, code, error_class);
}

bool drive_view::clear_fault(std::uint16_t code) noexcept {
  if (code == 0) return false;
  for (int i = 0; i < max_fault_causes; ++i) {
    if (axis_->fault_codes[i] == code) {
      remove_fault_at(*axis_, i);
      return true;
    }
  }
  return false;
}

void drive_view::clear_faults() noexcept {
  for (int i = 0; i < max_fault_causes; ++i) {
    axis_->fault_codes[i] = 0;
    axis_->fault_classes[i] = 0;
  }
}

std::uint16_t drive_view::fault_cause() const noexcept {
  const int n = fault_count(*axis_);
  return n > 0 ? axis_->fault_codes[n - 1] : std::uint16_t{0};
}

virtual_drive::virtual_drive(const profile& p, const plant_config& config)
    : profile_(&p), axis_(make_axis_state(p)) {
  if (const char* why = check_plant_config(config)) throw std::invalid_argument(why);
  constants_ = plant_constants::from(config);
}

}  // namespace cia402::sim
