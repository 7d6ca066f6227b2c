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

constexpr std::int64_t sign_of(std::int64_t v) noexcept { return (v > 0) - (v < 0); }

}  // namespace

bool homing_machine::index_pulse_between(std::int64_t from, std::int64_t to,
                                         std::uint32_t increments_per_rev) const noexcept {
  const std::int64_t r = increments_per_rev ? increments_per_rev : 1;
  if (from == to) return floor_div(to - index_at, r) * r == to - index_at;
  // (from, to] going up, [to, from) going down: a pulse counts in the cycle the shaft reaches it.
  const std::int64_t lo = from < to ? from + 1 : to;
  const std::int64_t hi = from < to ? to : from - 1;
  return index_at + floor_div(hi - index_at, r) * r >= lo;
}

const char* homing_phase_name(homing_phase p) noexcept {
  switch (p) {
    case homing_phase::not_started: return "not started";
    case homing_phase::searching_home_switch: return "searching home switch";
    case homing_phase::searching_limit_switch: return "searching limit switch";
    case homing_phase::searching_index_pulse: return "searching index pulse";
    case homing_phase::stopping_past_home: return "stopping past home";
    case homing_phase::moving_to_zero: return "moving to zero";
    case homing_phase::attained: return "homing attained";
    case homing_phase::interrupted: return "interrupted";
    case homing_phase::error: return "homing error";
  }
  return "unknown";
}

namespace {

// The moves of the methods 1..14 (17..30 are the same without the index pulse), from the figures of
// CiA 402-2: which switch's state at the start picks the plan, the plan when it is inactive, when
// it is active, and (7..14) the plan after the first move met the limit switch ahead and reversed.
struct leg_code {
  std::int8_t direction;
  std::uint8_t what;  // 0 home switch, 1 negative limit switch, 2 positive limit switch
  bool becomes_active;
};
struct plan_code {
  leg_code legs[3];
  std::uint8_t count;
};
struct method_shape {
  std::uint8_t start_sensor;
  plan_code inactive;
  plan_code active;
  plan_code after_limit;  // count 0: the method meets no limit switch on purpose
};

constexpr leg_code up_on{+1, 0, true};     // positive, until the home switch is active
constexpr leg_code up_off{+1, 0, false};   // positive, until it is inactive
constexpr leg_code down_on{-1, 0, true};
constexpr leg_code down_off{-1, 0, false};
constexpr leg_code to_negative_limit{-1, 1, true};
constexpr leg_code off_negative_limit{+1, 1, false};
constexpr leg_code to_positive_limit{+1, 2, true};
constexpr leg_code off_positive_limit{-1, 2, false};

constexpr method_shape shapes[15] = {
    {0, {{}, 0}, {{}, 0}, {{}, 0}},
    {1, {{to_negative_limit, off_negative_limit}, 2}, {{off_negative_limit}, 1}, {{}, 0}},  // 1
    {2, {{to_positive_limit, off_positive_limit}, 2}, {{off_positive_limit}, 1}, {{}, 0}},  // 2
    {0, {{up_on, down_off}, 2}, {{down_off}, 1}, {{}, 0}},                                   // 3
    {0, {{up_on}, 1}, {{down_off, up_on}, 2}, {{}, 0}},                                      // 4
    {0, {{down_on, up_off}, 2}, {{up_off}, 1}, {{}, 0}},                                     // 5
    {0, {{down_on}, 1}, {{up_off, down_on}, 2}, {{}, 0}},                                    // 6
    {0, {{up_on, down_off}, 2}, {{down_off}, 1}, {{down_on, down_off}, 2}},                  // 7
    {0, {{up_on}, 1}, {{down_off, up_on}, 2}, {{down_on, down_off, up_on}, 3}},              // 8
    {0, {{up_on, up_off, down_on}, 3}, {{up_off, down_on}, 2}, {{down_on}, 1}},              // 9
    {0, {{up_on, up_off}, 2}, {{up_off}, 1}, {{down_on, up_off}, 2}},                        // 10
    {0, {{down_on, up_off}, 2}, {{up_off}, 1}, {{up_on, up_off}, 2}},                        // 11
    {0, {{down_on}, 1}, {{up_off, down_on}, 2}, {{up_on, up_off, down_on}, 3}},              // 12
    {0, {{down_on, down_off, up_on}, 3}, {{down_off, up_on}, 2}, {{up_on}, 1}},              // 13
    {0, {{down_on, down_off}, 2}, {{down_off}, 1}, {{up_on, down_off}, 2}},                  // 14
};

enum plan_choice : std::uint8_t { plan_inactive, plan_active, plan_after_limit };

// Methods 1..14 and 17..30 (the same without the index pulse); any other method has no moves.
const method_shape& shape_of(std::int8_t method) noexcept {
  const int base = method > 16 ? method - 16 : method;
  return shapes[base >= 1 && base <= 14 ? base : 0];
}

const plan_code& plan_of(std::int8_t method, std::uint8_t plan) noexcept {
  const method_shape& shape = shape_of(method);
  return plan == plan_active ? shape.active : plan == plan_after_limit ? shape.after_limit : shape.inactive;
}

bool sensor_active(const homing_machine& m, std::uint8_t what, std::int64_t at) noexcept {
  return what == 0 ? m.home_switch_active(at) : what == 1 ? m.negative_limit_active(at) : m.positive_limit_active(at);
}

// Moving in `direction` into the limit switch on that side.
bool limit_met(const homing_machine& m, const shaft& s, std::int64_t direction) noexcept {
  if (sign_of(s.velocity) != direction) return false;
  return direction > 0 ? m.positive_limit_active(s.position) : m.negative_limit_active(s.position);
}

}  // namespace

void homing::interrupt() noexcept {
  if (running()) {
    stage_ = stage::idle;
    interrupted_ = true;
  }
}

homing_phase homing::phase() const noexcept {
  switch (stage_) {
    case stage::idle: return interrupted_ ? homing_phase::interrupted : homing_phase::not_started;
    case stage::searching:
      return plan_of(method_, plan_).legs[leg_at_].what == 0 ? homing_phase::searching_home_switch
                                                              : homing_phase::searching_limit_switch;
    case stage::index: return homing_phase::searching_index_pulse;
    case stage::stopping: return homing_phase::stopping_past_home;
    case stage::returning: return homing_phase::moving_to_zero;
    case stage::done: return homing_phase::attained;
    case stage::failed: return homing_phase::error;
  }
  return homing_phase::not_started;
}

void homing::follow_plan(std::int8_t method, const homing_machine& m, std::int64_t here,
                         bool after_limit) noexcept {
  if (after_limit) {
    plan_ = plan_after_limit;
  } else {
    // What the switch the method starts from shows picks the plan.
    plan_ = sensor_active(m, shape_of(method).start_sensor, here) ? plan_active : plan_inactive;
  }
  const plan_code& plan = plan_of(method, plan_);
  leg_at_ = 0;
  final_direction_ = plan.legs[plan.count - 1].direction;
  stage_ = stage::searching;
}

void homing::start(const homing_parameters& par, const homing_machine& m, shaft& s,
                   std::int64_t& offset) noexcept {
  travelled_ = 0;
  interrupted_ = false;
  method_ = par.method;
  home_at_ = s.position;
  if (method_ == 35 || method_ == 37) {
    // Home is here: the position reads as the home offset from this cycle on.
    offset = par.home_offset - s.position;
    stage_ = s.velocity == 0 ? stage::done : stage::stopping;
    return;
  }
  if (method_ == 33 || method_ == 34) {
    final_direction_ = method_ == 34 ? 1 : -1;
    home_at_ = first_pulse_ahead(m, par.increments_per_rev ? par.increments_per_rev : 1, s);
    stage_ = stage::index;
    return;
  }
  if (!supports(method_)) {
    stage_ = stage::failed;
    return;
  }
  index_after_edge_ = method_ <= 14;
  follow_plan(method_, m, s.position, false);
}

// Methods 33 / 34: the first index pulse the shaft reaches in the final direction. A pulse is
// latched on its edge as the shaft moves across it: one exactly under the standing shaft was passed
// before the run and is not taken (the search goes on to the next, a revolution on); a shaft a
// fraction above a pulse still crosses it going down.
std::int64_t homing::first_pulse_ahead(const homing_machine& m, std::int64_t resolution,
                                       const shaft& s) const noexcept {
  const std::int64_t below = m.index_at + floor_div(s.position - m.index_at, resolution) * resolution;
  if (final_direction_ > 0) return below + resolution;
  return below == s.position && s.fraction == 0 ? below - resolution : below;
}

// Home is measured from `home_at_` (the edge of methods 1..14): the edge itself, or the
// first index pulse at or beyond it in the final direction, which the search then runs to unless the
// shaft is there already (or past it).
void homing::edge_found(const homing_machine& m, std::int64_t resolution, std::int64_t here) noexcept {
  stage_ = stage::stopping;
  if (index_after_edge_) {
    const std::int64_t below = m.index_at + floor_div(home_at_ - m.index_at, resolution) * resolution;
    home_at_ = final_direction_ < 0 || below == home_at_ ? below : below + resolution;
    if (final_direction_ > 0 ? here < home_at_ : here > home_at_) stage_ = stage::index;
  }
}

// A cycle of the search for a switch: the move's switch in the state it waits for, moving its way,
// ends the move (the last one finds the edge home is measured from); a limit switch ahead that the
// move does not wait for turns the first move of 7..14 back, and is an error anywhere else.
void homing::search(const homing_parameters& par, const homing_machine& m, const shaft& s) noexcept {
  const plan_code& plan = plan_of(method_, plan_);
  const leg_code& l = plan.legs[leg_at_];
  if (sign_of(s.velocity) == l.direction && sensor_active(m, l.what, s.position) == l.becomes_active) {
    if (leg_at_ + 1 < plan.count) {
      ++leg_at_;
      return;
    }
    // The edge: the first position in the switch's new state. A switch that reaches to the end of
    // travel (or is not fitted) has no edge there: its state holds, the search goes on.
    const bool up = l.direction > 0;
    const bool low_edge = l.what == 0 && up == l.becomes_active;
    const std::int64_t bound = l.what == 1 ? m.negative_limit
                               : l.what == 2 ? m.positive_limit
                               : low_edge    ? m.home_switch_low
                                             : m.home_switch_high;
    if (bound == homing_machine::none_below || bound == homing_machine::none_above) return;
    home_at_ = l.what != 0 ? bound : (l.becomes_active ? bound : (up ? bound + 1 : bound - 1));
    edge_found(m, par.increments_per_rev ? par.increments_per_rev : 1, s.position);
  } else if (limit_met(m, s, l.direction)) {
    if (plan_ == plan_inactive && leg_at_ == 0 && shape_of(method_).after_limit.count > 0) {
      follow_plan(method_, m, s.position, true);
    } else {
      stage_ = stage::failed;  // a limit switch the method does not expect
    }
  }
}

homing_status homing::step(bool start_bit, const homing_parameters& par, const homing_machine& m,
                           shaft& s, std::int64_t& offset, std::uint32_t dt_us,
                           std::uint32_t speed_limit_rpm) noexcept {
  const bool started = start_bit && !last_start_;
  const bool dropped = !start_bit && last_start_;
  last_start_ = start_bit;
  const std::int64_t resolution = par.increments_per_rev ? par.increments_per_rev : 1;
  const std::uint32_t switch_rpm = par.switch_speed_rpm < speed_limit_rpm ? par.switch_speed_rpm : speed_limit_rpm;
  const std::uint32_t zero_rpm = par.zero_speed_rpm < speed_limit_rpm ? par.zero_speed_rpm : speed_limit_rpm;
  const std::int64_t switch_speed = static_cast<std::int64_t>(switch_rpm) * micro;
  const std::int64_t zero_speed = static_cast<std::int64_t>(zero_rpm) * micro;
  const std::int64_t accel_step = static_cast<std::int64_t>(par.acceleration_rpm_s) * dt_us;

  if (started) {
    start(par, m, s, offset);
  } else if (dropped) {
    interrupt();
  }

  // Where this cycle drives the shaft.
  std::int64_t goal = 0;
  switch (stage_) {
    case stage::searching:
      goal = plan_of(method_, plan_).legs[leg_at_].direction * (leg_at_ == 0 ? switch_speed : zero_speed);
      break;
    case stage::index: goal = final_direction_ * zero_speed; break;
    case stage::returning: {
      // Back to home, no faster than it can still stop there (this cycle's travel counted).
      const std::int64_t cap = stopping_speed(s, home_at_, par.acceleration_rpm_s, dt_us,
                                              static_cast<std::uint32_t>(resolution));
      goal = sign_of(home_at_ - s.position) * (cap < zero_speed ? cap : zero_speed);
      break;
    }
    case stage::idle:
    case stage::stopping:
    case stage::done:
    case stage::failed: goal = 0; break;
  }
  const std::int64_t before = s.position;
  advance(s, towards(s.velocity, goal, accel_step), dt_us, static_cast<std::uint32_t>(resolution));
  if (stage_ == stage::returning && sign_of(before - home_at_) * sign_of(s.position - home_at_) <= 0) {
    // Arrived within this cycle, slow enough to stop (the cap saw to it): exactly at home, at rest.
    s.position = home_at_;
    s.fraction = 0;
    s.velocity = 0;
  }
  const std::int64_t after = s.position;
  travelled_ += after > before ? after - before : before - after;

  if (stage_ == stage::searching) search(par, m, s);
  if (stage_ == stage::index) {
    // Reached: at or past the pulse (a shaft a fraction above it has not yet reached it going down).
    if (final_direction_ > 0 ? after >= home_at_ : after < home_at_ || (after == home_at_ && s.fraction == 0)) {
      stage_ = stage::stopping;
    } else if (limit_met(m, s, final_direction_)) {
      stage_ = stage::failed;
    }
  }
  if (stage_ == stage::stopping && s.velocity == 0) {
    // Home found and the shaft at rest past it: home now reads as the home offset, and the shaft
    // goes back to stand there.
    if (method_ != 35 && method_ != 37) offset = par.home_offset - home_at_;
    stage_ = s.position == home_at_ ? stage::done : stage::returning;
  }
  if (stage_ == stage::returning && s.position == home_at_ && s.velocity == 0) stage_ = stage::done;
  if ((stage_ == stage::searching || stage_ == stage::index) &&
      travelled_ > max_search_revolutions * resolution) {
    stage_ = stage::failed;
  }

  homing_status st;
  const bool at_rest = s.velocity == 0;
  st.attained = stage_ == stage::done || stage_ == stage::stopping || stage_ == stage::returning;
  st.target_reached = stage_ == stage::done || ((stage_ == stage::idle || stage_ == stage::failed) && at_rest);
  st.error = stage_ == stage::failed;
  st.limited = running() && (par.switch_speed_rpm > speed_limit_rpm || par.zero_speed_rpm > speed_limit_rpm);
  return st;
}

}  // namespace cia402::motion
