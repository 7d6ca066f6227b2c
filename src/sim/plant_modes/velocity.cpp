// The velocity modes: profile velocity (CiA 402-2 mode 3), which is also how every mode's shaft
// moves while a stop runs or torque is off, and cyclic synchronous velocity (mode 9).
#include "../plant_internal.hpp"

namespace cia402::sim::detail {

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

std::uint16_t csv_cycle(const plant_constants& k, axis_state& a, motion::shaft& s) noexcept {
  const mode_objects& o = a.objects;
  const bool cleared = (a.flags & sim_flag::setpoints_cleared) != 0;
  std::uint16_t status = 0;
  const std::int64_t goal = clamp((std::int64_t{cleared ? 0 : a.target_velocity} + o.velocity_offset) * micro,
                                  -k.max_velocity, k.max_velocity);
  std::int64_t v_new = approach(s.velocity, goal, k.max_acceleration_step, k.max_acceleration_step);
  if (beyond_limit(a, s.position, v_new)) {
    v_new = approach(s.velocity, 0, 0, std::int64_t{a.quick_stop_deceleration} * k.cycle_us);
    status |= status_bit::internal_limit_active;
  }
  motion::advance(s, v_new, k.cycle_us, o.increments_per_rev);
  a.demand = s.position;
  status |= status_bit::drive_follows_command;
  return status;
}

}  // namespace cia402::sim::detail
