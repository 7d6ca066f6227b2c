// The torque modes: profile torque (CiA 402-2 mode 4) and cyclic synchronous torque (mode 10). The
// motor's torque against friction and a constant load accelerates an inertia.
#include "../plant_internal.hpp"

namespace cia402::sim::detail {
namespace {

// The shaft under a torque: against friction and the load it accelerates the inertia.
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
  // The shaft saturates at the speed limit (0x607F, 0x6080, the motor's top speed): bit 11.
  const std::int64_t limit = std::int64_t{speed_limit_rpm(k, a)} * micro;
  if (v_new > limit || v_new < -limit) {
    v_new = clamp(v_new, -limit, limit);
    a.mode_status |= status_bit::internal_limit_active;
  }
  // Towards a software limit the drive overrides the torque as pv brakes: the shaft stops at the
  // limit, not beyond. Slower than the cut (or reversing) it keeps what the torque gives, up to the
  // cut; faster, it brakes on the quick-stop ramp.
  std::int64_t goal = v_new;
  std::int64_t down = 0;
  limit_approach at;
  if (limits_on(a) && brake_for_limit(k, a, s, goal, down, at)) {
    const bool braking = magnitude(v) > magnitude(goal) && sign_of(v) != -sign_of(goal);
    v_new = braking ? approach(v, goal, 0, down) : goal;
    a.mode_status |= status_bit::internal_limit_active;
  }
  motion::advance(s, v_new, k.cycle_us, a.objects.increments_per_rev);
  stand_at_limit(s, at, v_new, down);
}

}  // namespace

std::uint16_t torque_cycle(const plant_constants& k, axis_state& a, motion::shaft& s) noexcept {
  const mode_objects& o = a.objects;
  const bool cleared = (a.flags & sim_flag::setpoints_cleared) != 0;
  std::uint16_t status = 0;
  // The set-point is cut to the max torque 0x6072 (bit 11 then).
  const std::int64_t most = o.max_torque < 32767 ? o.max_torque : 32767;
  std::int64_t demand;
  if (a.operation_mode == cia402::mode::profile_torque) {
    // The demand ramps to the target at the torque slope 0x6087.
    const std::int64_t wanted = cleared ? 0 : o.target_torque;
    const std::int64_t target = clamp(wanted, -most, most);
    if (target != wanted) status |= status_bit::internal_limit_active;
    const std::int64_t slope = std::int64_t{o.torque_slope} * k.cycle_us / 1'000'000;
    const std::int64_t step_max = slope > 0 ? slope : 1;
    demand = a.torque_demand + clamp(target - a.torque_demand, -step_max, step_max);
    if (demand == target) status |= status_bit::target_reached;
  } else {
    const std::int64_t wanted = interpolate(k, a, std::int64_t{cleared ? 0 : o.target_torque} + o.torque_offset);
    demand = clamp(wanted, -most, most);
    if (demand != wanted) status |= status_bit::internal_limit_active;
    status |= status_bit::drive_follows_command;
  }
  a.torque_demand = static_cast<std::int32_t>(demand);
  a.mode_status = 0;
  torque_follow(k, a, s, demand);
  status |= a.mode_status;
  a.torque = a.torque_demand;
  a.demand = s.position;
  return status;
}

}  // namespace cia402::sim::detail
