// The velocity modes: profile velocity's status bits 10 and 12 over the velocity window and
// threshold times (CiA 402-2 mode 3; its motion is the plant's own, velocity_follow() in plant.cpp),
// and cyclic synchronous velocity (mode 9).
#include "../plant_internal.hpp"

namespace cia402::sim::detail {
std::uint16_t pv_timed_bits(const plant_constants& k, axis_state& a) noexcept {
  const mode_objects& o = a.objects;
  const bool in_window = magnitude(a.velocity - a.pv_set_point) <= std::int64_t{o.velocity_window} * micro;
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
  std::int64_t goal = clamp(wanted, -limit, limit);
  if (goal != wanted) status |= status_bit::internal_limit_active;
  // Towards a software limit it brakes as pv does: the shaft stops at the limit, not beyond.
  std::int64_t down = k.max_acceleration_step;
  limit_approach at;
  if (limits_on(a) && brake_for_limit(k, a, s, goal, down, at)) status |= status_bit::internal_limit_active;
  const std::int64_t v_new = approach(s.velocity, goal, k.max_acceleration_step, down);
  motion::advance(s, v_new, k.cycle_us, o.increments_per_rev);
  stand_at_limit(s, at, v_new, down);
  a.demand = s.position;
  return status;
}

}  // namespace cia402::sim::detail
