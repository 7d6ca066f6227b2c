// The velocity modes: profile velocity (CiA 402-2 mode 3), which is also how every mode's shaft
// moves while a stop runs or torque is off, and cyclic synchronous velocity (mode 9).
#include "../plant_internal.hpp"

namespace cia402::sim::detail {
namespace {

// Profile velocity towards a software position limit (0x607D): no faster than the shaft can still
// stop at the limit on the quick-stop ramp 0x6085, and standing exactly there once it arrives.
// Returns true while the limit cuts the goal.
bool brake_for_limit(const plant_constants& k, const axis_state& a, const motion::shaft& s,
                     std::int64_t& goal, std::int64_t& down, std::int64_t& edge) noexcept {
  const mode_objects& o = a.objects;
  const std::int64_t quick_stop = std::int64_t{a.quick_stop_deceleration} * k.cycle_us;
  if (beyond_limit(a, s.position, goal)) {  // at or past the limit: stop (and stay) there
    goal = 0;
    down = quick_stop;
    return true;
  }
  if (goal == 0) return false;
  edge = goal > 0 ? o.max_position : o.min_position;
  const std::int64_t cap = motion::stopping_speed(s, edge, a.quick_stop_deceleration, k.cycle_us, o.increments_per_rev);
  if (magnitude(goal) <= cap) return false;
  goal = sign_of(goal) * cap;
  if (down < quick_stop) down = quick_stop;
  return true;
}

}  // namespace

std::uint16_t velocity_follow(const profile& p, const plant_constants& k, axis_state& a,
                              const drive_outputs& out, motion::shaft& s, bool brake_holds) noexcept {
  const std::int64_t cycle = k.cycle_us;
  std::int64_t goal = 0;
  std::int64_t up = 0;
  std::int64_t down = 0;
  std::uint16_t status = 0;
  bool towards_limit = false;
  std::int64_t edge = 0;
  if (!out.torque) {
    down = k.coast_step;  // coasting: friction only
  } else if (out.ramp != stop_ramp::none && out.ramp != stop_ramp::coast) {
    down = ramp_step(k, a, out.ramp);
  } else if (p.info(out.current).activity == state_activity::run && a.operation_mode == cia402::mode::profile_velocity) {
    goal = pv_set_point(k, a);
    if (goal != std::int64_t{effective_target(a)} * micro) status |= status_bit::internal_limit_active;
    up = std::int64_t{a.acceleration} * cycle;
    down = std::int64_t{a.deceleration} * cycle;
    if (limits_on(a) && brake_for_limit(k, a, s, goal, down, edge)) {
      status |= status_bit::internal_limit_active;
      towards_limit = goal != 0;
    }
  } else {
    down = std::int64_t{a.deceleration} * cycle;  // torque held without motion (e.g. hold states)
  }
  if (brake_holds) {
    goal = 0;  // an engaged (or still releasing) brake holds the shaft: nothing accelerates
    up = 0;
    down += k.brake_step;
    towards_limit = false;
  }
  const std::int64_t v_new = approach(s.velocity, goal, up, down);
  motion::advance(s, v_new, k.cycle_us, a.objects.increments_per_rev);
  // Arrived at the limit within a slow last cycle: exactly there, at rest.
  const bool reached = v_new > 0 ? s.position >= edge : (s.position < edge || (s.position == edge && s.fraction == 0));
  if (towards_limit && reached && magnitude(v_new) <= down) {
    s.position = edge;
    s.fraction = 0;
    s.velocity = 0;
  }
  return status;
}

std::uint16_t pv_timed_bits(const plant_constants& k, axis_state& a) noexcept {
  const mode_objects& o = a.objects;
  const bool in_window = magnitude(a.velocity - pv_set_point(k, a)) <= std::int64_t{o.velocity_window} * micro;
  a.in_velocity_window_us = in_window ? add_cycle(a.in_velocity_window_us, k.cycle_us) : 0;
  const bool above = magnitude(a.velocity) > std::int64_t{o.velocity_threshold} * micro;
  a.above_velocity_threshold_us = above ? add_cycle(a.above_velocity_threshold_us, k.cycle_us) : 0;
  const bool window_held = in_window && a.in_velocity_window_us >= std::uint32_t{o.velocity_window_time} * 1000u;
  const bool speed_zero = a.above_velocity_threshold_us <= std::uint32_t{o.velocity_threshold_time} * 1000u;
  return static_cast<std::uint16_t>((window_held ? status_bit::target_reached : 0u) |
                                    (speed_zero ? status_bit::speed_zero : 0u));
}

std::uint16_t csv_cycle(const plant_constants& k, axis_state& a, motion::shaft& s) noexcept {
  const mode_objects& o = a.objects;
  const bool cleared = (a.flags & sim_flag::setpoints_cleared) != 0;
  std::uint16_t status = status_bit::drive_follows_command;
  const std::int64_t wanted =
      interpolate(k, a, (std::int64_t{cleared ? 0 : a.target_velocity} + o.velocity_offset) * micro);
  const std::int64_t limit = std::int64_t{speed_limit_rpm(k, a)} * micro;
  const std::int64_t goal = clamp(wanted, -limit, limit);
  if (goal != wanted) status |= status_bit::internal_limit_active;
  std::int64_t v_new = approach(s.velocity, goal, k.max_acceleration_step, k.max_acceleration_step);
  if (beyond_limit(a, s.position, v_new)) {
    v_new = approach(s.velocity, 0, 0, std::int64_t{a.quick_stop_deceleration} * k.cycle_us);
    status |= status_bit::internal_limit_active;
  }
  motion::advance(s, v_new, k.cycle_us, o.increments_per_rev);
  a.demand = s.position;
  return status;
}

}  // namespace cia402::sim::detail
