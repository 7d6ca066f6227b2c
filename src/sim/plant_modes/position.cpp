// The position modes: profile position (CiA 402-2 mode 1), with motion::profile_position's
// trapezoid and set-point handshake, and cyclic synchronous position (mode 8) with the following
// error check 0x6065 / 0x6066.
#include "../plant_internal.hpp"

namespace cia402::sim::detail {
namespace {

// The following error check of the position modes (0x6065, 0x6066): beyond the window for longer
// than the time out, status bit 13 and the fault 0x8611 (which the drive answers by 0x605E).
// Out of line: a position mode's cycle within the window (nearly all of them) keeps no registers for it.
[[gnu::noinline]] bool following_error_beyond_window(const plant_constants& k, axis_state& a) noexcept {
  const std::uint32_t room = UINT32_MAX - a.following_error_us;
  a.following_error_us += k.cycle_us < room ? k.cycle_us : room;
  if (a.following_error_us <= std::uint32_t{a.objects.following_error_time_out} * 1000u) return false;
  if (!(a.flags & sim_flag::following_error_raised)) {
    a.flags |= sim_flag::following_error_raised;
    add_fault_cause(a, following_error_code, 2);
  }
  return true;
}

bool following_error_check(const plant_constants& k, axis_state& a) noexcept {
  if (within_window(a, a.demand)) {
    a.following_error_us = 0;
    return false;
  }
  return following_error_beyond_window(k, a);
}

// The shaft's move of a csp cycle to the demand; true when the speed limit cut it short.
bool csp_move(const plant_constants& k, axis_state& a, std::int64_t demand) noexcept {
  const mode_objects& o = a.objects;
  const std::uint32_t limit = speed_limit_rpm(k, a);
  // (usual_increments_per_rev is 0 when there is no such figure; 0x608F is at least 1.)
  if (o.increments_per_rev == k.usual_increments_per_rev && limit == k.max_velocity_rpm) {
    csp_move_usual(k, a, demand);
    return a.position != demand;
  }
  // Top speed [rpm] x increments a revolution x cycle [us] stays below 2^61 (1e5 x 2^24 x 1e6):
  // 64-bit arithmetic, no 128-bit division in the cycle of a thousand axes.
  const std::uint64_t per_rev_us = std::uint64_t{o.increments_per_rev} * k.cycle_us;
  const std::int64_t reach = static_cast<std::int64_t>(std::uint64_t{limit} * per_rev_us / 60'000'000u);
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
  return a.position != demand;
}

}  // namespace

std::uint16_t csp_follow(const plant_constants& k, axis_state& a) noexcept {
  std::uint16_t status = status_bit::drive_follows_command;
  const std::int64_t demand = interpolate(k, a, csp_demand(a, status));
  a.demand = demand;
  // The following error of this cycle: the new demand against where the shaft was.
  if (following_error_check(k, a)) status |= status_bit::following_error;
  if (csp_move(k, a, demand)) status |= status_bit::internal_limit_active;
  return status;
}

std::uint16_t pp_cycle(const plant_constants& k, axis_state& a, const drive_outputs& out,
                       motion::shaft& s) noexcept {
  const mode_objects& o = a.objects;
  const std::uint16_t cw = a.control_word;
  motion::pp_command cmd;
  cmd.new_setpoint = (cw & control_bit::new_set_point) != 0;
  cmd.change_immediately = (cw & control_bit::change_set_immediately) != 0;
  cmd.relative = (cw & control_bit::relative) != 0;
  cmd.halt = out.ramp != stop_ramp::none;  // only a halt reaches here with a ramp (follow)
  cmd.change_on_setpoint = (cw & control_bit::change_on_set_point) != 0;
  cmd.target = o.target_position;
  motion::pp_parameters par;
  const std::uint32_t limit = speed_limit_rpm(k, a);
  par.profile_velocity_rpm = o.profile_velocity < limit ? o.profile_velocity : limit;
  par.end_velocity_rpm = o.end_velocity < limit ? o.end_velocity : limit;
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
  // Bit 11 while the set-point is cut to 0x607D, or a move runs with its speed cut to the limit.
  const bool speed_cut = (o.profile_velocity > limit || o.end_velocity > limit) && a.pp.moving();
  return static_cast<std::uint16_t>((st.target_reached ? status_bit::target_reached : 0u) |
                                    (st.setpoint_acknowledge ? status_bit::set_point_acknowledge : 0u) |
                                    (st.limited || speed_cut ? status_bit::internal_limit_active : 0u));
}

}  // namespace cia402::sim::detail
