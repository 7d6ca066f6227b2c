#include "cia402/motion/homing.hpp"

namespace cia402::motion {
namespace {

constexpr std::int64_t micro = 1'000'000;

// The velocity after one cycle towards `goal` at `accel_step` micro-rpm a cycle.
std::int64_t towards(std::int64_t v, std::int64_t goal, std::int64_t accel_step) noexcept {
  if (v < goal) return v + accel_step < goal ? v + accel_step : goal;
  if (v > goal) return v - accel_step > goal ? v - accel_step : goal;
  return v;
}

// floor(x / d) for d > 0.
std::int64_t floor_div(std::int64_t x, std::int64_t d) noexcept {
  const std::int64_t q = x / d;
  return (x % d != 0 && x < 0) ? q - 1 : q;
}

}  // namespace

void homing::interrupt() noexcept {
  if (running()) phase_ = phase::idle;
}

homing_status homing::step(bool start, const homing_parameters& par, shaft& s,
                           std::uint32_t dt_us) noexcept {
  const bool started = start && !last_start_;
  const bool dropped = !start && last_start_;
  last_start_ = start;
  const std::int64_t resolution = par.increments_per_rev ? par.increments_per_rev : 1;
  const std::int64_t switch_speed = static_cast<std::int64_t>(par.switch_speed_rpm) * micro;
  const std::int64_t zero_speed = static_cast<std::int64_t>(par.zero_speed_rpm) * micro;
  const std::int64_t accel_step = static_cast<std::int64_t>(par.acceleration_rpm_s) * dt_us;

  if (started) {
    travelled_ = 0;
    switch (par.method) {
      case 35:
      case 37:
        // Home is here: the position reads as the home offset from this cycle on.
        s.position = par.home_offset;
        s.fraction = 0;
        phase_ = s.velocity == 0 ? phase::done : phase::stopping;
        home_at_ = par.home_offset;
        break;
      case 3: phase_ = s.position >= par.home_switch_at ? phase::leave_switch : phase::search_switch; break;
      case 33:
      case 34: phase_ = phase::search_index; break;
      default: phase_ = phase::failed; break;
    }
  } else if (dropped) {
    interrupt();
  }

  // Where this cycle drives the shaft.
  std::int64_t goal = 0;
  switch (phase_) {
    case phase::search_switch: goal = switch_speed; break;
    case phase::leave_switch: goal = -zero_speed; break;
    case phase::search_index: goal = par.method == 34 ? zero_speed : -zero_speed; break;
    case phase::returning: {
      // Back to the home position found, no faster than it can still stop there.
      const std::int64_t distance = home_at_ - s.position;
      const std::int64_t cap = braking_speed(distance < 0 ? -distance : distance, par.acceleration_rpm_s, 0,
                                             static_cast<std::uint32_t>(resolution));
      const std::int64_t speed = cap < zero_speed ? cap : zero_speed;
      goal = distance > 0 ? speed : (distance < 0 ? -speed : 0);
      break;
    }
    case phase::idle:
    case phase::stopping:
    case phase::done:
    case phase::failed: goal = 0; break;
  }
  const std::int64_t before = s.position;
  advance(s, towards(s.velocity, goal, accel_step), dt_us, static_cast<std::uint32_t>(resolution));
  if (phase_ == phase::returning) {
    // Arrived within a slow last cycle: exactly at home, at rest.
    const bool passed = (before - home_at_) * (s.position - home_at_) <= 0;
    const std::int64_t slow = accel_step > 0 ? accel_step : 1;
    if (passed && (s.velocity <= slow && s.velocity >= -slow)) {
      s.position = home_at_;
      s.fraction = 0;
      s.velocity = 0;
    }
  }
  const std::int64_t after = s.position;
  travelled_ += after > before ? after - before : before - after;

  switch (phase_) {
    case phase::search_switch:
      if (after >= par.home_switch_at) phase_ = phase::leave_switch;
      break;
    case phase::leave_switch:
      // Moving negative (once the reversal is through): the switch goes inactive below its edge.
      if (s.velocity < 0 && after < par.home_switch_at) phase_ = phase::search_index;
      break;
    case phase::search_index: {
      const bool forward = par.method == 34;
      const bool moving_right_way = forward ? s.velocity > 0 : s.velocity < 0;
      const std::int64_t old_pulse = floor_div(before - par.index_at, resolution);
      const std::int64_t new_pulse = floor_div(after - par.index_at, resolution);
      if (moving_right_way && old_pulse != new_pulse) {
        // The pulse passed this cycle: the one just above `after` going up, at or below `before`
        // going down.
        home_at_ = par.index_at + (forward ? new_pulse : old_pulse) * resolution;
        phase_ = phase::stopping;
      }
      break;
    }
    case phase::stopping:
    case phase::returning:
    case phase::idle:
    case phase::done:
    case phase::failed: break;
  }
  if (phase_ == phase::stopping && s.velocity == 0) {
    // Home found and the shaft at rest past it: it now reads home as the home offset, and goes back
    // to stand there.
    if (par.method != 35 && par.method != 37) {
      s.position += par.home_offset - home_at_;
      home_at_ = par.home_offset;
    }
    phase_ = s.position == home_at_ ? phase::done : phase::returning;
  }
  if (phase_ == phase::returning && s.position == home_at_ && s.velocity == 0) phase_ = phase::done;
  if (running() && phase_ != phase::stopping && phase_ != phase::returning &&
      travelled_ > max_search_revolutions * resolution) {
    phase_ = phase::failed;
  }

  homing_status st;
  const bool at_rest = s.velocity == 0;
  st.attained = phase_ == phase::done || phase_ == phase::stopping || phase_ == phase::returning;
  st.target_reached = (phase_ == phase::done) || ((phase_ == phase::idle || phase_ == phase::failed) && at_rest);
  st.error = phase_ == phase::failed;
  return st;
}

}  // namespace cia402::motion
