// Private to src/sim: what the plant's files share. The plant is cut along its concerns: plant.cpp
// (the cycle: the core's decision, the shaft, the brake, the inputs), plant_config.cpp (constants and
// a fresh axis), plant_objects.cpp (the object interface), and plant_modes/ (one file per family of
// operation modes). What a running csp axis's cycle uses without a call is inline here.
#pragma once

#include <cstdint>
#include <type_traits>
#include <utility>

#include "cia402/objects.hpp"
#include "cia402/sim/plant.hpp"
#include "cia402/words.hpp"

namespace cia402::sim::detail {

constexpr std::int64_t micro = 1000000;  // micro-rpm per rpm
// micro-rpm x increments a revolution x cycle [us] of one increment a cycle: 60 s x 1e6 x 1e6.
constexpr std::int64_t csp_velocity_scale = 60'000'000'000'000LL;

__extension__ typedef __int128 wide;

// The most increments a cycle the motor's top speed travels in csp (per_rev_us: increments a
// revolution x cycle in us).
inline std::int64_t csp_reach(const plant_constants& k, std::uint64_t per_rev_us) noexcept {
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(k.max_velocity / micro) * per_rev_us / 60'000'000u);
}

inline std::int64_t magnitude(std::int64_t v) noexcept { return v < 0 ? -v : v; }

constexpr std::int64_t sign_of(std::int64_t v) noexcept { return (v > 0) - (v < 0); }

inline std::int64_t clamp(std::int64_t v, std::int64_t lo, std::int64_t hi) noexcept {
  return v < lo ? lo : (v > hi ? hi : v);
}

// Moves v towards goal: by at most `up` while |v| grows, by at most `down` while it shrinks. A
// change of sign first stops at 0 (the rest of that cycle is not carried over).
inline std::int64_t approach(std::int64_t v, std::int64_t goal, std::int64_t up,
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
inline std::int64_t ramp_step(const plant_constants& k, const axis_state& a, stop_ramp r) noexcept {
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

inline void set_flag(axis_state& a, std::uint8_t flag, bool on) noexcept {
  a.flags = static_cast<std::uint8_t>(on ? (a.flags | flag) : (a.flags & ~flag));
}

// 0x607D: on when the minimum lies below the maximum.
inline bool limits_on(const axis_state& a) noexcept { return a.objects.min_position < a.objects.max_position; }

// Moving outwards at or past a software limit. A shaft between two increments reads the lower one:
// at the lower limit it is past it only when it stands exactly there.
inline bool beyond_limit(const axis_state& a, const motion::shaft& s, std::int64_t velocity) noexcept {
  const mode_objects& o = a.objects;
  const bool at_min = s.position < o.min_position || (s.position == o.min_position && s.fraction == 0);
  return limits_on(a) && ((s.position >= o.max_position && velocity > 0) || (at_min && velocity < 0));
}

// The software limit a mode brakes for this cycle (brake_for_limit): `towards` is +1 for the upper,
// -1 for the lower, 0 while none is braked for.
struct limit_approach {
  std::int64_t edge = 0;
  std::int64_t towards = 0;
};

// Towards a software position limit (0x607D) in pv, csv and the torque modes: no faster than the
// shaft can still stop at the limit on the quick-stop ramp 0x6085 (the cycle's travel counted, as pp
// brakes into its target), and at rest once at or past it. Cuts `goal` (micro-rpm, the velocity the
// mode wants this cycle), raises `down` (micro-rpm a cycle) to the quick-stop ramp, and sets `at` to
// the limit the shaft heads for. True while the limit cuts the goal (status bit 11).
inline bool brake_for_limit(const plant_constants& k, const axis_state& a, const motion::shaft& s,
                            std::int64_t& goal, std::int64_t& down, limit_approach& at) noexcept {
  const mode_objects& o = a.objects;
  const std::int64_t quick_stop = std::int64_t{a.quick_stop_deceleration} * k.cycle_us;
  if (beyond_limit(a, s, goal)) {  // at or past the limit: stop (and stay) there
    goal = 0;
    down = quick_stop;
    return true;
  }
  if (goal == 0) return false;
  const std::int64_t edge = goal > 0 ? o.max_position : o.min_position;
  // Farther from the limit than the braking distance from the top speed (and a cycle's travel)
  // there is nothing to cut: no 128-bit root in the cycles of a shaft far away.
  if (magnitude(edge - s.position) > std::int64_t{a.limit_braking_reach}) return false;
  const std::int64_t cap = motion::stopping_speed(s, edge, a.quick_stop_deceleration, k.cycle_us, o.increments_per_rev);
  if (magnitude(goal) <= cap) return false;
  at.edge = edge;
  at.towards = sign_of(goal);
  goal = at.towards * cap;
  if (down < quick_stop) down = quick_stop;
  return true;
}

// After a cycle's move at `v_new` towards the limit brake_for_limit() cut the goal for: arrived
// within a slow last cycle (no faster than `down` a cycle), the shaft stands exactly there. Arrived
// means at or past the limit in the direction braked towards (a shaft slowing from the other way
// has not arrived, however slow); it stood before it at the start of the cycle.
inline void stand_at_limit(motion::shaft& s, const limit_approach& at, std::int64_t v_new, std::int64_t down) noexcept {
  if (at.towards == 0) return;
  const bool reached = at.towards > 0 ? s.position >= at.edge
                                      : (s.position < at.edge || (s.position == at.edge && s.fraction == 0));
  if (reached && magnitude(v_new) <= down) {
    s.position = at.edge;
    s.fraction = 0;
    s.velocity = 0;
  }
}

// 0x60C2 (value x 10^index s, index -6..0) in microseconds.
inline std::uint32_t interpolation_period_us(std::uint8_t value, std::int8_t index) noexcept {
  std::uint32_t us = value;
  for (int i = -6; i < index; ++i) us *= 10;
  return us;
}

// Adds a cycle to a timer, saturating.
inline std::uint32_t add_cycle(std::uint32_t us, std::uint32_t cycle_us) noexcept {
  const std::uint32_t room = UINT32_MAX - us;
  return us + (cycle_us < room ? cycle_us : room);
}

// The set-point profile velocity follows (micro-rpm): 0x60FF (0 after T4 until written again), cut
// to the speed limit.
inline std::int64_t pv_set_point(const plant_constants& k, const axis_state& a) noexcept {
  const std::int64_t limit = std::int64_t{speed_limit_rpm(k, a)} * micro;
  return clamp(std::int64_t{effective_target(a)} * micro, -limit, limit);
}

// The cyclic modes' interpolation over 0x60C2 (CiA 402-2): a new set-point is taken at the start of
// each period and approached linearly from the last one over the period; with a period of one cycle
// or less each cycle's set-point is taken as it is. The next cycle starts a period from `value`.
inline void restart_interpolation(axis_state& a, std::int64_t value) noexcept {
  a.interpolation_from = value;
  a.interpolation_to = value;
  a.interpolation_elapsed_us = a.objects.interpolation_period_us;
}
// This cycle's set-point on the way to `sample` (plant_modes/cyclic.cpp).
std::int64_t interpolate(const plant_constants& k, axis_state& a, std::int64_t sample) noexcept;

// The fault causes of an axis (plant_objects.cpp): how many are present, one taken out, one added
// as the newest (false when the oldest had to go, or for code 0).
int fault_count(const axis_state& a) noexcept;
void remove_fault_at(axis_state& a, int i) noexcept;
bool add_fault_cause(axis_state& a, std::uint16_t code, std::uint8_t error_class) noexcept;

// The torque a velocity change took (permille): inertia, friction and load. What 0x6077 shows in
// the modes that command a velocity or a position.
inline std::int32_t torque_of_motion(const plant_constants& k, const axis_state& a, std::int64_t v_old,
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

// The demand is within 0x6065's window of the actual position (or there is no window).
inline bool within_window(const axis_state& a, std::int64_t demand) noexcept {
  const std::uint32_t window = a.objects.following_error_window;
  const std::int64_t error = demand - a.position;
  return window == 0xFFFFFFFFu || (error < 0 ? -error : error) <= std::int64_t{window};
}

// Cyclic synchronous position while the drive runs: the set-point of this cycle (sampled at SYNC on
// CANopen) is reached within the cycle unless the motor's top speed cannot. Works on the axis
// directly, apart from the other modes: it is the mode a master streams to many axes every cycle.

// The demand of a csp cycle: 0x607A + 0x60B0, cut to the software limits (status bit 11 then).
inline std::int64_t csp_demand(const axis_state& a, std::uint16_t& status) noexcept {
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
inline void csp_move_usual(const plant_constants& k, axis_state& a, std::int64_t demand) noexcept {
  const std::int64_t step = clamp(demand - a.position, -k.usual_csp_reach, k.usual_csp_reach);
  a.position += step;
  a.position_fraction = 0;
  a.velocity = step * k.usual_velocity_per_increment;
}

// The operation modes (plant_modes/): one cycle of the shaft `s` while the drive runs in the mode.
// Each returns the mode's status bits (10..13) and keeps a.demand.

/// Profile velocity's timed status bits after the cycle's move: 10 once within 0x606D for 0x606E,
/// 12 until beyond 0x606F for longer than 0x6070 (plant_modes/velocity.cpp).
std::uint16_t pv_timed_bits(const plant_constants& k, axis_state& a) noexcept;
/// Cyclic synchronous velocity (plant_modes/velocity.cpp).
std::uint16_t csv_cycle(const plant_constants& k, axis_state& a, motion::shaft& s) noexcept;
/// Profile position (plant_modes/position.cpp).
std::uint16_t pp_cycle(const plant_constants& k, axis_state& a, const drive_outputs& out,
                       motion::shaft& s) noexcept;
/// One running csp cycle on the axis itself (plant_modes/position.cpp).
std::uint16_t csp_follow(const plant_constants& k, axis_state& a) noexcept;
/// Profile torque and cyclic synchronous torque: sets a.torque itself (plant_modes/torque.cpp).
std::uint16_t torque_cycle(const plant_constants& k, axis_state& a, motion::shaft& s) noexcept;
/// Homing (plant_modes/homing.cpp).
std::uint16_t homing_cycle(const plant_constants& k, axis_state& a, motion::shaft& s) noexcept;

// The settings kept as one field each of mode_objects, read and written alike: one row per object
// and sub-index, so reading and writing cannot disagree on where a value lives. The objects whose
// write does more (a set-point, the mode, the homing method, 0x60C2) have cases of their own in
// plant_objects.cpp. A new axis starts each at the one table's default.
inline constexpr std::uint8_t every_sub = 0xFF;

struct plain_setting {
  std::uint16_t index;
  std::uint8_t sub;  ///< the sub-index, or every_sub for an object of one value
  std::int64_t (*read)(const mode_objects&) noexcept;
  void (*write)(mode_objects&, std::int64_t) noexcept;
};

template <auto field>
constexpr plain_setting setting(std::uint16_t index, std::uint8_t sub = every_sub) noexcept {
  using value_type = std::remove_reference_t<decltype(std::declval<mode_objects&>().*field)>;
  return {index, sub, [](const mode_objects& m) noexcept -> std::int64_t { return m.*field; },
          [](mode_objects& m, std::int64_t v) noexcept { m.*field = static_cast<value_type>(v); }};
}

inline constexpr plain_setting plain_settings[] = {
    setting<&mode_objects::position_offset>(object_index::position_offset),
    setting<&mode_objects::velocity_offset>(object_index::velocity_offset),
    setting<&mode_objects::torque_offset>(object_index::torque_offset),
    setting<&mode_objects::home_offset>(object_index::home_offset),
    setting<&mode_objects::min_position>(object_index::software_position_limit, 1),
    setting<&mode_objects::max_position>(object_index::software_position_limit, 2),
    setting<&mode_objects::profile_velocity>(object_index::profile_velocity),
    setting<&mode_objects::end_velocity>(object_index::end_velocity),
    setting<&mode_objects::torque_slope>(object_index::torque_slope),
    setting<&mode_objects::following_error_window>(object_index::following_error_window),
    setting<&mode_objects::following_error_time_out>(object_index::following_error_time_out),
    setting<&mode_objects::position_window>(object_index::position_window),
    setting<&mode_objects::position_window_time>(object_index::position_window_time),
    setting<&mode_objects::homing_switch_speed>(object_index::homing_speeds, 1),
    setting<&mode_objects::homing_zero_speed>(object_index::homing_speeds, 2),
    setting<&mode_objects::homing_acceleration>(object_index::homing_acceleration),
    setting<&mode_objects::max_profile_velocity>(object_index::max_profile_velocity),
    setting<&mode_objects::max_motor_speed>(object_index::max_motor_speed),
    setting<&mode_objects::max_torque>(object_index::max_torque),
    setting<&mode_objects::velocity_window>(object_index::velocity_window),
    setting<&mode_objects::velocity_window_time>(object_index::velocity_window_time),
    setting<&mode_objects::velocity_threshold>(object_index::velocity_threshold),
    setting<&mode_objects::velocity_threshold_time>(object_index::velocity_threshold_time),
};


}  // namespace cia402::sim::detail
