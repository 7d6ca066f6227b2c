// Profile position mode on virtual time: the trapezoid's timing (computed here from the textbook
// formulas, never from the code under test), exact arrival, relative moves, the set-point queue,
// change immediately, change on set-point, halt, and the bits 10 and 12.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "cia402/motion/trajectory.hpp"

namespace cia402::motion {
namespace {

constexpr std::uint32_t cycle_us = 1000;

// The analytic time of a point-to-point move from rest to rest, in seconds: a trapezoid when the
// profile velocity is reached, a triangle when not.
double trapezoid_seconds(double distance_rev, double v_rpm, double a_rpm_s, double d_rpm_s) {
  const double v = v_rpm / 60.0, a = a_rpm_s / 60.0, d = d_rpm_s / 60.0;  // rev/s, rev/s^2
  const double ramps = v * v / (2 * a) + v * v / (2 * d);
  if (distance_rev >= ramps) return distance_rev / v + v / (2 * a) + v / (2 * d);
  const double peak = std::sqrt(2 * a * d * distance_rev / (a + d));
  return peak / a + peak / d;
}

pp_parameters profile_of(std::uint32_t velocity_rpm, std::uint32_t acceleration_rpm_s,
                         std::uint32_t deceleration_rpm_s) {
  pp_parameters par;
  par.profile_velocity_rpm = velocity_rpm;
  par.acceleration_rpm_s = acceleration_rpm_s;
  par.deceleration_rpm_s = deceleration_rpm_s;
  return par;
}

// Offers `target` as a master does in one cycle: bit 4 high for that cycle, then low again in
// `cmd` for the cycles that follow; returns that cycle's status.
pp_status offer(profile_position& pp, pp_command& cmd, const pp_parameters& par, std::int64_t target) {
  cmd.target = target;
  cmd.new_setpoint = true;
  const pp_status st = pp.step(cmd, par, cycle_us);
  cmd.new_setpoint = false;
  return st;
}

// From rest at 0: offers `target` and runs on for `cycles` more cycles.
void start_from_rest(profile_position& pp, pp_command& cmd, const pp_parameters& par, std::int64_t target,
                     int cycles) {
  pp.reset(0);
  offer(pp, cmd, par, target);
  for (int c = 0; c < cycles; ++c) pp.step(cmd, par, cycle_us);
}

struct run_result {
  int cycles_to_reach = -1;     // first cycle whose status shows target reached
  int cycles_to_ack = -1;
  std::int64_t final_position = 0;
  std::int64_t peak_speed = 0;  // micro-rpm
};

// Offers one absolute set-point in the first cycle and runs until target reached.
run_result move(profile_position& pp, const pp_parameters& par, std::int64_t target,
                bool relative = false, int limit = 100000) {
  run_result r;
  pp_command cmd;
  cmd.target = target;
  cmd.relative = relative;
  for (int c = 1; c <= limit; ++c) {
    cmd.new_setpoint = c <= 2;  // a master raises bit 4, sees bit 12, lowers it
    const pp_status st = pp.step(cmd, par, cycle_us);
    const std::int64_t v = pp.state().velocity;
    if ((v < 0 ? -v : v) > r.peak_speed) r.peak_speed = v < 0 ? -v : v;
    if (st.setpoint_acknowledge && r.cycles_to_ack < 0) r.cycles_to_ack = c;
    if (st.target_reached && c > 2) {
      r.cycles_to_reach = c;
      break;
    }
  }
  r.final_position = pp.state().position;
  return r;
}

TEST(profile_position, a_move_takes_the_time_the_trapezoid_says_within_one_cycle) {
  struct case_t {
    std::int64_t distance;
    std::uint32_t v, a, d;
  };
  const std::vector<case_t> cases = {
      {50000, 600, 6000, 6000},     // 5 rev: 0.1 s up, 0.4 s at 600 rpm, 0.1 s down
      {50000, 600, 6000, 3000},     // a slower deceleration
      {10000, 600, 6000, 6000},     // 1 rev: exactly a triangle
      {3000, 3000, 1000, 2000},     // a triangle that never reaches 3000 rpm
      {-123457, 1500, 12000, 8000}, // backwards, not a whole number of revolutions
      {2000000, 3000, 20000, 20000},// 200 rev: a distance whose fraction units pass 64 bits
  };
  for (const case_t& c : cases) {
    SCOPED_TRACE(::testing::Message() << c.distance << " inc at " << c.v << " rpm, a " << c.a
                                      << ", d " << c.d);
    const pp_parameters par = profile_of(c.v, c.a, c.d);
    profile_position pp;
    pp.reset(0);
    const run_result r = move(pp, par, c.distance);
    const double expected = trapezoid_seconds(std::fabs(double(c.distance)) / 10000.0, c.v, c.a, c.d);
    const double expected_cycles = expected * 1e6 / cycle_us;
    // The set-point is taken in cycle 1 and the motion starts there; the cycle in which the demand
    // arrives is the one that shows target reached (window time 0).
    EXPECT_NEAR(r.cycles_to_reach, expected_cycles, 1.0);
    EXPECT_EQ(r.final_position, c.distance) << "exactly at the target";
    EXPECT_LE(r.peak_speed, std::int64_t{c.v} * 1000000) << "never above the profile velocity";
    EXPECT_EQ(r.cycles_to_ack, 1) << "bit 12 in the cycle bit 4 rises";
  }
}

TEST(profile_position, bit_12_follows_the_handshake_and_bit_10_waits_for_the_window_time) {
  pp_parameters par = profile_of(600, 6000, 6000);
  par.position_window_time_ms = 5;
  profile_position pp;
  pp.reset(0);
  pp_command cmd;
  cmd.target = 1000;
  cmd.new_setpoint = true;
  EXPECT_TRUE(pp.step(cmd, par, cycle_us).setpoint_acknowledge);
  EXPECT_TRUE(pp.step(cmd, par, cycle_us).setpoint_acknowledge) << "held while bit 4 is high";
  cmd.new_setpoint = false;
  pp_status st = pp.step(cmd, par, cycle_us);
  EXPECT_FALSE(st.setpoint_acknowledge) << "cleared once bit 4 is low and the queue is free";
  EXPECT_FALSE(st.target_reached);
  int arrived = -1, reached = -1;
  for (int c = 4; c < 2000 && reached < 0; ++c) {
    st = pp.step(cmd, par, cycle_us);
    if (arrived < 0 && pp.state().position == 1000 && pp.state().velocity == 0) arrived = c;
    if (st.target_reached) reached = c;
  }
  ASSERT_GT(arrived, 0);
  EXPECT_EQ(reached - arrived, 4) << "5 ms inside the window, counting the cycle of arrival";
}

TEST(profile_position, a_relative_move_adds_to_the_previous_target) {
  pp_parameters par = profile_of(1200, 10000, 10000);
  profile_position pp;
  pp.reset(500);
  EXPECT_EQ(move(pp, par, 20000).final_position, 20000);
  EXPECT_EQ(move(pp, par, 7000, true).final_position, 27000);
  EXPECT_EQ(move(pp, par, -30000, true).final_position, -3000);
}

// Bit 5 = 0: the second set-point waits in the queue until the first is reached; bit 12 stays set
// while it waits. Bit 5 = 1: it replaces the running one at once.
TEST(profile_position, the_queue_and_change_immediately) {
  pp_parameters par = profile_of(600, 6000, 6000);
  profile_position pp;
  pp_command cmd;
  start_from_rest(pp, cmd, par, 10000, 50);
  EXPECT_TRUE(offer(pp, cmd, par, 20000).setpoint_acknowledge) << "queued behind 10000";
  EXPECT_TRUE(pp.step(cmd, par, cycle_us).setpoint_acknowledge) << "still queued";
  EXPECT_EQ(pp.target(), 10000);
  bool stopped_at_first = false;
  for (int c = 0; c < 3000 && !(pp.state().position == 20000 && pp.state().velocity == 0); ++c) {
    pp.step(cmd, par, cycle_us);
    if (pp.state().position == 10000 && pp.state().velocity == 0) stopped_at_first = true;
  }
  EXPECT_TRUE(stopped_at_first) << "without bit 9 the move stops at each set-point";
  EXPECT_EQ(pp.state().position, 20000);

  // Change immediately, while moving to 40000: turn back to 0 at once.
  offer(pp, cmd, par, 40000);
  for (int c = 0; c < 60; ++c) pp.step(cmd, par, cycle_us);
  ASSERT_GT(pp.state().velocity, 0);
  cmd.change_immediately = true;
  offer(pp, cmd, par, 0);
  EXPECT_EQ(pp.target(), 0);
  std::int64_t furthest = 0;
  for (int c = 0; c < 5000 && pp.moving(); ++c) {
    pp.step(cmd, par, cycle_us);
    if (pp.state().position > furthest) furthest = pp.state().position;
  }
  EXPECT_EQ(pp.state().position, 0);
  EXPECT_LT(furthest, 40000) << "it never went on to the replaced target";
}

// Bit 9: the running set-point is passed at speed into the queued one, not stopped at.
TEST(profile_position, change_on_setpoint_blends_into_the_next_target) {
  pp_parameters par = profile_of(600, 6000, 6000);
  profile_position pp;
  pp_command cmd;
  start_from_rest(pp, cmd, par, 20000, 1);
  cmd.change_on_setpoint = true;
  offer(pp, cmd, par, 40000);
  bool passed_at_speed = false;
  int cycles = 3;
  for (; cycles < 5000 && !(pp.state().position == 40000 && pp.state().velocity == 0); ++cycles) {
    pp.step(cmd, par, cycle_us);
    if (pp.state().position == 20000) passed_at_speed = pp.state().velocity == 600 * 1000000;
  }
  EXPECT_TRUE(passed_at_speed);
  // Blended, the two set-points take as long as one 4-revolution move (0.1 s up, 0.3 s at 600 rpm,
  // 0.1 s down); two stops would add 0.1 s.
  EXPECT_NEAR(cycles, trapezoid_seconds(4.0, 600, 6000, 6000) * 1000, 2.0);
}

TEST(profile_position, halt_stops_on_the_deceleration_ramp_and_clearing_it_resumes) {
  pp_parameters par = profile_of(600, 6000, 3000);
  profile_position pp;
  pp_command cmd;
  start_from_rest(pp, cmd, par, 100000, 200);
  ASSERT_EQ(pp.state().velocity, 600 * 1000000);
  cmd.halt = true;
  int cycles = 0;
  pp_status st;
  do {
    st = pp.step(cmd, par, cycle_us);
    ++cycles;
  } while (!st.target_reached && cycles < 1000);
  EXPECT_EQ(cycles, 200) << "600 rpm at 3000 rpm/s: 0.2 s";
  EXPECT_EQ(pp.state().velocity, 0);
  EXPECT_LT(pp.state().position, 100000);
  cmd.halt = false;
  st = pp.step(cmd, par, cycle_us);
  EXPECT_FALSE(st.target_reached) << "moving again";
  for (int c = 0; c < 5000 && !st.target_reached; ++c) st = pp.step(cmd, par, cycle_us);
  EXPECT_EQ(pp.state().position, 100000) << "the target was kept";
}

TEST(kinematics, travel_is_exact_over_many_cycles) {
  // 1 rpm at 10,000 increments per revolution is 1/6 increment a millisecond: after 60,000 cycles
  // (a minute) exactly 10,000 increments, with no drift.
  shaft s;
  s.velocity = 1000000;
  for (int c = 0; c < 60000; ++c) advance(s, 1000000, cycle_us, 10000);
  EXPECT_EQ(s.position, 10000);
  EXPECT_EQ(s.fraction, 0);
  for (int c = 0; c < 60000; ++c) advance(s, -1000000, cycle_us, 10000);
  // The first reverse cycle ramps from +1 to -1 rpm (no travel), so one cycle's 1/6 increment is
  // not undone: 59,999 cycles back leave exactly that.
  EXPECT_EQ(s.position * 6 * shaft::fraction_unit + s.fraction * 6, shaft::fraction_unit)
      << s.position << " + " << s.fraction;
}

}  // namespace
}  // namespace cia402::motion
