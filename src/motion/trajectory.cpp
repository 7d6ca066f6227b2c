#include "cia402/motion/trajectory.hpp"

#include <cmath>

namespace cia402::motion {
namespace {

// Products of a speed, a resolution and a cycle exceed 64 bits: 128 inside, as GCC and Clang give.
__extension__ typedef __int128 wide;

constexpr std::int64_t micro = 1'000'000;

wide abs_wide(wide v) noexcept { return v < 0 ? -v : v; }

// Floor division and its remainder, so the fraction stays in [0, unit) for either sign of travel.
void add_fraction(shaft& s, wide units) noexcept {
  const wide total = units + s.fraction;
  wide whole = total / shaft::fraction_unit;
  wide rest = total % shaft::fraction_unit;
  if (rest < 0) {
    rest += shaft::fraction_unit;
    whole -= 1;
  }
  s.position += static_cast<std::int64_t>(whole);
  s.fraction = static_cast<std::int64_t>(rest);
}

// floor(sqrt(x)) for x >= 0: a double's estimate, then corrected in integers, so the result is
// exact and the same everywhere.
std::int64_t isqrt(wide x) noexcept {
  if (x <= 0) return 0;
  auto r = static_cast<wide>(std::sqrt(static_cast<double>(x)));
  while (r > 0 && r * r > x) --r;
  while ((r + 1) * (r + 1) <= x) ++r;
  return static_cast<std::int64_t>(r);
}

// The braking speed of a distance in fraction units, which exceeds 64 bits past ~76,000 increments.
std::int64_t cap_speed(wide distance, std::uint32_t deceleration_rpm_s, std::int64_t end_speed,
                       std::uint32_t increments_per_rev) noexcept {
  const wide squared = static_cast<wide>(end_speed) * end_speed +
                       static_cast<wide>(deceleration_rpm_s) * abs_wide(distance) /
                           (increments_per_rev ? increments_per_rev : 1u);
  return isqrt(squared);
}

// The fastest the shaft may end a cycle with, `along` (micro-rpm, towards the target; negative
// moving away) at its start and `distance` (fraction units) to go, so that after the cycle's travel
// it can still slow to `end` at the deceleration: vn^2 <= e^2 + d (D - (v + vn) R dt) / R, which is
// vn^2 + b vn - c <= 0 with b = d dt and c = e^2 + d D / R - b v.
std::int64_t cap_towards(wide distance, std::int64_t along, std::int64_t end, std::uint32_t deceleration_rpm_s,
                         std::uint32_t dt_us, std::uint32_t resolution) noexcept {
  const wide b = static_cast<wide>(deceleration_rpm_s) * dt_us;
  const wide c = static_cast<wide>(end) * end + static_cast<wide>(deceleration_rpm_s) * abs_wide(distance) / resolution -
                 b * along;
  const wide disc = b * b + 4 * c;
  return disc <= b * b ? 0 : static_cast<std::int64_t>((isqrt(disc) - b) / 2);
}

std::int64_t min3(std::int64_t a, std::int64_t b, std::int64_t c) noexcept {
  const std::int64_t m = a < b ? a : b;
  return m < c ? m : c;
}

}  // namespace

void advance(shaft& s, std::int64_t velocity_end, std::uint32_t dt_us,
             std::uint32_t increments_per_rev) noexcept {
  const wide units = (static_cast<wide>(s.velocity) + velocity_end) * increments_per_rev * dt_us;
  add_fraction(s, units);
  s.velocity = velocity_end;
}

std::int64_t braking_speed(std::int64_t distance_increments, std::uint32_t deceleration_rpm_s,
                           std::int64_t end_speed, std::uint32_t increments_per_rev) noexcept {
  return cap_speed(static_cast<wide>(distance_increments) * shaft::fraction_unit, deceleration_rpm_s,
                   end_speed, increments_per_rev);
}

std::int64_t stopping_speed(const shaft& s, std::int64_t target, std::uint32_t deceleration_rpm_s,
                            std::uint32_t dt_us, std::uint32_t increments_per_rev) noexcept {
  const wide distance = (static_cast<wide>(target) - s.position) * shaft::fraction_unit - s.fraction;
  const std::int64_t along = distance < 0 ? -s.velocity : s.velocity;
  return cap_towards(distance, along, 0, deceleration_rpm_s, dt_us, increments_per_rev ? increments_per_rev : 1u);
}

void profile_position::reset(std::int64_t position) noexcept {
  *this = profile_position{};
  shaft_.position = position;
  target_ = position;
}

void profile_position::reset(const shaft& s, bool new_setpoint_now) noexcept {
  *this = profile_position{};
  shaft_ = s;
  target_ = s.position;
  last_new_setpoint_ = new_setpoint_now;
}

pp_status profile_position::step(const pp_command& cmd, const pp_parameters& par,
                                 std::uint32_t dt_us) noexcept {
  // The set-point handshake: an offered set-point (bit 4's rising edge) is taken if there is room:
  // at once with bit 5 or when nothing runs, else into the one-place queue. Bit 12 shows it taken
  // until the master lowers bit 4 and the queue is free again.
  const bool offered = cmd.new_setpoint && !last_new_setpoint_;
  last_new_setpoint_ = cmd.new_setpoint;
  if (offered) {
    const std::int64_t base = queued_valid_ ? queued_ : target_;
    const std::int64_t wanted = cmd.relative ? base + cmd.target : cmd.target;
    const std::int64_t absolute = wanted < par.min_position   ? par.min_position
                                  : wanted > par.max_position ? par.max_position
                                                              : wanted;
    if (cmd.change_immediately || !active_) {
      target_ = absolute;
      limited_ = absolute != wanted;
      active_ = true;
      queued_valid_ = false;
      acknowledge_ = true;
      in_window_us_ = 0;
    } else if (!queued_valid_) {
      queued_ = absolute;
      queued_limited_ = absolute != wanted;
      queued_valid_ = true;
      queued_blends_ = cmd.change_on_setpoint;
      acknowledge_ = true;
    }
  }
  if (!cmd.new_setpoint && !queued_valid_) acknowledge_ = false;

  const std::uint32_t resolution = par.increments_per_rev ? par.increments_per_rev : 1u;
  const std::int64_t accel_step = static_cast<std::int64_t>(par.acceleration_rpm_s) * dt_us;
  const std::int64_t decel_step = static_cast<std::int64_t>(par.deceleration_rpm_s) * dt_us;
  const std::int64_t v_old = shaft_.velocity;

  if (cmd.halt || !active_) {
    // Halt (S8) or nothing to run to: brake to standstill on the deceleration ramp; the target stays.
    std::int64_t v_new = 0;
    if (v_old > decel_step) v_new = v_old - decel_step;
    if (v_old < -decel_step) v_new = v_old + decel_step;
    advance(shaft_, v_new, dt_us, resolution);
  } else {
    const wide distance =
        (static_cast<wide>(target_) - shaft_.position) * shaft::fraction_unit - shaft_.fraction;
    const std::int64_t sign = distance < 0 ? -1 : 1;
    // Passing the running target at speed into the queued one (bit 9) when both lie the same way.
    bool blend = false;
    if (queued_valid_ && queued_blends_) {
      const wide onward = static_cast<wide>(queued_) - target_;
      blend = onward != 0 && ((onward < 0) == (sign < 0));
    }
    const std::int64_t top = static_cast<std::int64_t>(par.profile_velocity_rpm) * micro;
    const std::int64_t end_speed =
        blend ? (par.end_velocity_rpm ? static_cast<std::int64_t>(par.end_velocity_rpm) * micro : top)
              : 0;
    const std::int64_t along = v_old * sign;  // speed towards the target; negative moving away
    // The fastest this cycle may end so that the shaft can still slow to the end speed.
    const std::int64_t end = end_speed < top ? end_speed : top;
    const std::int64_t cap = cap_towards(distance, along, end, par.deceleration_rpm_s, dt_us, resolution);
    // Moving away, the shaft first brakes; towards the target it speeds up to the profile velocity
    // and no faster than it can still stop.
    const std::int64_t up = along < 0 ? along + decel_step : along + accel_step;
    std::int64_t next = min3(top, up, cap);
    if (next < along - decel_step) next = along - decel_step;
    const std::int64_t v_new = next * sign;
    const wide travel = (static_cast<wide>(v_old) + v_new) * resolution * dt_us * sign;
    if (distance == 0 || travel >= abs_wide(distance)) {
      // Arrived within this cycle: exactly at the target, at rest or at the speed into the next one.
      shaft_.position = target_;
      shaft_.fraction = 0;
      shaft_.velocity = blend ? end_speed * sign : 0;
      active_ = false;
      in_window_us_ = 0;
      if (queued_valid_) {
        target_ = queued_;
        limited_ = queued_limited_;
        active_ = true;
        queued_valid_ = false;
      }
    } else {
      advance(shaft_, v_new, dt_us, resolution);
    }
  }

  pp_status st;
  st.demand = shaft_.position;
  st.setpoint_acknowledge = acknowledge_;
  st.limited = limited_;
  const bool at_rest = shaft_.velocity == 0;
  if (cmd.halt) {
    st.target_reached = at_rest;
  } else if (!active_ && !queued_valid_ && at_rest) {
    const std::int64_t off = shaft_.position - target_;
    const bool inside = (off < 0 ? -off : off) <= static_cast<std::int64_t>(par.position_window);
    const std::uint32_t room = UINT32_MAX - in_window_us_;
    in_window_us_ = inside ? in_window_us_ + (dt_us < room ? dt_us : room) : 0;
    st.target_reached = inside && in_window_us_ >= par.position_window_time_ms * 1000u;
  }
  return st;
}

}  // namespace cia402::motion
