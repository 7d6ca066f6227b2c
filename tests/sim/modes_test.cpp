// The operation modes of the virtual drive, driven through its objects as a master drives them:
// each expectation is computed from the physics (trapezoid, inertia, ramps) or read off CiA 402-2's
// bit definitions, never copied from a run.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/words.hpp"
#include "mode_support.hpp"

namespace {

using namespace mode_test;

// A pp set-point: target, bit 4 up with the given bits, wait for bit 12, bit 4 down.
int offer_setpoint(virtual_drive& d, std::int64_t target, std::uint16_t bits = 0) {
  write(d, 0x607A, target);
  write(d, 0x6040, 0x1F | bits);
  const int ack = cycles_until(d, [&] { return (status(d) & bit12) != 0; }, 10);
  write(d, 0x6040, 0x0F | (bits & ~0x10u));
  d.step();  // the drive sees bit 4 low before the next set-point's edge
  return ack;
}

// Profile position mode with the same acceleration (0x6083) and deceleration (0x6084), rpm/s.
void enable_pp_with_ramps(virtual_drive& d, std::int64_t rpm_s) {
  enable_in_mode(d, cia402::mode::profile_position);
  write(d, 0x6083, rpm_s);
  write(d, 0x6084, rpm_s);
}

TEST(profile_position, a_move_takes_the_time_the_trapezoid_says_and_sets_bit_12_then_bit_10) {
  virtual_drive d(standard_profile());
  enable_pp_with_ramps(d, 10000);
  write(d, 0x6081, 1000);  // rpm
  // 10 revolutions at 1000 rpm: 0.1 s up (0.8333 rev), 0.1 s down, 8.3333 rev at 16.667 rev/s in
  // between: 0.7 s in all.
  const int ack = offer_setpoint(d, 100000);
  EXPECT_GE(ack, 1);
  EXPECT_LE(ack, 2) << "bit 12 in the cycle after the drive took the set-point";
  EXPECT_EQ(status(d) & bit10, 0) << "moving: not at the target";
  const int reached = cycles_until(d, [&] { return (status(d) & bit10) != 0; });
  EXPECT_NEAR(ack + reached, 700, 2);
  EXPECT_EQ(read(d, 0x6064), 100000);
  EXPECT_EQ(read(d, 0x6062), 100000);
  EXPECT_EQ(read(d, 0x606C), 0);
  EXPECT_EQ(status(d) & bit12, 0) << "bit 4 is down and the queue empty";
}

TEST(profile_position, a_short_move_is_a_triangle) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::profile_position);
  // 2 revolutions at 1000 rpm/s never reach 1000 rpm: 2 sqrt(1 rev / (1000/60 rev/s^2)) = 0.6928 s.
  const int ack = offer_setpoint(d, 20000);
  const int reached = cycles_until(d, [&] { return (status(d) & bit10) != 0; });
  EXPECT_NEAR(ack + reached, 693, 2);
  EXPECT_EQ(read(d, 0x6064), 20000);
}

TEST(profile_position, a_relative_move_adds_to_the_previous_target) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::profile_position);
  offer_setpoint(d, 20000);
  cycles_until(d, [&] { return (status(d) & bit10) != 0; });
  offer_setpoint(d, -5000, 0x40);
  cycles_until(d, [&] { return (status(d) & bit10) != 0; });
  EXPECT_EQ(read(d, 0x6064), 15000);
}

TEST(profile_position, change_on_setpoint_passes_the_first_target_at_speed) {
  virtual_drive d(standard_profile());
  enable_pp_with_ramps(d, 10000);
  offer_setpoint(d, 50000);
  EXPECT_GE(offer_setpoint(d, 100000, 0x200), 1) << "queued behind the running one, acknowledged";
  std::int64_t slowest_after_start = 1 << 30;
  bool passed = false;
  cycles_until(d, [&] {
    const auto v = d.view().velocity_rpm();
    if (d.view().position() > 10000 && d.view().position() < 90000) slowest_after_start = std::min<std::int64_t>(slowest_after_start, v);
    passed = passed || d.view().position() > 50000;
    return (status(d) & bit10) != 0;
  });
  EXPECT_TRUE(passed);
  EXPECT_GT(slowest_after_start, 900) << "no stop at 50000: the move blends into the next";
  EXPECT_EQ(read(d, 0x6064), 100000);
}

TEST(profile_position, halt_ramps_by_0x605D_and_the_move_resumes) {
  for (const auto& [code, decel] : {std::pair{1, 1000}, std::pair{2, 10000}}) {
    virtual_drive d(standard_profile());
    enable_in_mode(d, cia402::mode::profile_position);
    write(d, 0x605D, code);
    write(d, 0x6081, 600);
    offer_setpoint(d, 200000);
    cycles_until(d, [&] { return d.view().velocity_rpm() >= 600; });
    write(d, 0x6040, 0x10F);  // halt
    d.step();
    const std::int64_t v0 = d.view().velocity_micro_rpm();
    d.step();
    EXPECT_EQ(v0 - d.view().velocity_micro_rpm(), std::int64_t{decel} * 1000) << "0x605D = " << code;
    const int stopped = cycles_until(d, [&] { return (status(d) & bit10) != 0; });
    EXPECT_NEAR(stopped, 600 * 1000 / decel, 3) << "bit 10 at standstill under halt";
    write(d, 0x6040, 0x0F);
    cycles_until(d, [&] { return (status(d) & bit10) != 0 && d.view().position() == 200000; });
    EXPECT_EQ(read(d, 0x6064), 200000) << "the target was kept";
  }
}

TEST(profile_position, a_target_beyond_the_software_limit_stops_at_it_with_bit_11) {
  virtual_drive d(standard_profile());
  write_position_limits(d, -1000, 30000);
  enable_in_mode(d, cia402::mode::profile_position);
  offer_setpoint(d, 50000);
  cycles_until(d, [&] { return (status(d) & bit10) != 0; });
  EXPECT_EQ(read(d, 0x6064), 30000);
  EXPECT_NE(status(d) & bit11, 0);
}

TEST(profile_velocity, runs_into_a_software_limit_and_stops_with_bit_11) {
  virtual_drive d(standard_profile());
  write_position_limits(d, -100000, 5000);
  enable_in_mode(d, cia402::mode::profile_velocity);
  write(d, 0x60FF, 100);
  const int stopped = cycles_until(d, [&] { return d.view().position() >= 5000 && d.view().velocity_micro_rpm() == 0; });
  ASSERT_GT(stopped, 0);
  d.step();
  EXPECT_NE(status(d) & bit11, 0);
  EXPECT_LT(read(d, 0x6064), 5100) << "stopped on the quick-stop ramp right behind the limit";
}

TEST(homing, methods_35_and_37_take_the_present_position_as_home) {
  for (int method : {35, 37}) {
    virtual_drive d(standard_profile());
    write(d, 0x6098, method);
    write(d, 0x607C, 777);
    enable_in_mode(d, cia402::mode::homing);
    EXPECT_EQ(status(d) & (bit12 | bit13), 0);
    write(d, 0x6040, 0x1F);
    const int done = cycles_until(d, [&] { return (status(d) & (bit10 | bit12)) == (bit10 | bit12); }, 5);
    EXPECT_GT(done, 0) << method;
    EXPECT_EQ(read(d, 0x6064), 777);
    EXPECT_EQ(status(d) & bit13, 0);
  }
}

TEST(homing, method_3_homes_on_the_index_pulse_left_of_the_home_switch_edge) {
  // The plant's switch is active from 50,000 increments up; index pulses every 10,000 from 0: the
  // pulse left of the edge is at 40,000, which then reads as the home offset.
  virtual_drive d(standard_profile());
  write(d, 0x607C, 1234);
  start_homing(d, 3);
  std::int64_t last = d.view().position();
  std::int64_t jump = 0;
  std::int64_t highest = last;
  const int done = cycles_until(d, [&] {
    const std::int64_t p = d.view().position();
    if (std::llabs(p - last) > 1000) jump = p - last;
    highest = std::max(highest, p);
    last = p;
    return (status(d) & (bit10 | bit12)) == (bit10 | bit12);
  }, 60000);
  ASSERT_GT(done, 0);
  EXPECT_GE(highest, 50000) << "it searched the switch in the positive direction";
  EXPECT_NEAR(jump, 1234 - 40000, 2) << "the redefinition maps the pulse at 40,000 to the home offset";
  EXPECT_EQ(read(d, 0x6064), 1234) << "and it stands at home";
  EXPECT_EQ(status(d) & bit13, 0);
}

TEST(homing, a_reserved_method_is_refused) {
  virtual_drive d(standard_profile());
  for (const int reserved : {0, 15, 16, 31, 32, 36, 38, -1}) {
    EXPECT_EQ(d.write(0x6098, 0, reserved), sdo_abort::invalid_value) << reserved;
  }
  EXPECT_EQ(read(d, 0x6098), 35);
}

TEST(cyclic_synchronous_position, tracks_a_ramp_and_faults_on_a_jump_beyond_the_window) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::cyclic_synchronous_position);
  std::int64_t worst = 0;
  for (int i = 1; i <= 1000; ++i) {
    write(d, 0x607A, i * 10);  // 10 increments a 1 ms cycle: 60 rpm
    d.step();
    worst = std::max<std::int64_t>(worst, std::llabs(read(d, 0x607A) - read(d, 0x6064)));
  }
  EXPECT_LE(worst, 10) << "within one cycle's travel";
  EXPECT_EQ(read(d, 0x606C), 60);
  EXPECT_NE(status(d) & bit12, 0) << "the drive follows the command value";
  EXPECT_EQ(status(d) & bit13, 0);
  // 500,000 increments away: at the motor's 6000 rpm (100 rev/s, 1,000 increments a ms) the error
  // stays beyond the 10,000-increment window for longer than the 10 ms time out.
  write(d, 0x607A, 510000);
  bool bit13_seen = false;
  const int faulted = cycles_until(d, [&] {
    bit13_seen = bit13_seen || (status(d) & bit13) != 0;
    return d.view().current() == state::fault_reaction_active;
  }, 100);
  EXPECT_NEAR(faulted, 12, 2);
  EXPECT_TRUE(bit13_seen) << "bit 13 shows the following error before the reaction";
  EXPECT_EQ(read(d, 0x603F), 0x8611);
  EXPECT_GT(cycles_until(d, [&] { return d.view().current() == state::fault; }, 3000), 0);
  // The cause is gone once the drive is in FAULT: a fault reset clears 0x603F.
  write(d, 0x6040, 0x80);
  d.step();
  EXPECT_EQ(read(d, 0x603F), 0);
}

TEST(cyclic_synchronous_torque, a_torque_step_accelerates_the_inertia) {
  // 500 permille against 20 of friction: 480 x 20,000 / 1000 = 9,600 rpm/s, 9.6 rpm a cycle.
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::cyclic_synchronous_torque);
  write(d, 0x6071, 500);
  for (int i = 0; i < 100; ++i) d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), 960'000'000);
  EXPECT_EQ(read(d, 0x6077), 500);
  EXPECT_NE(status(d) & bit12, 0);
}

TEST(profile_torque, the_demand_ramps_by_the_torque_slope_then_sets_bit_10) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::profile_torque);
  write(d, 0x6087, 10000);  // permille/s: 10 a cycle
  write(d, 0x6071, 300);
  // The motion of a cycle shows in the next cycle's status word.
  d.step();
  d.step();
  EXPECT_EQ(status(d) & bit10, 0) << "the new target is not reached yet";
  const int reached = cycles_until(d, [&] { return (status(d) & bit10) != 0; }, 200);
  EXPECT_NEAR(2 + reached, 31, 1) << "30 cycles of slope, shown the cycle after";
  EXPECT_EQ(read(d, 0x6077), 300);
}

TEST(profile_torque, halt_ramps_by_0x605D) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::profile_torque);
  write(d, 0x6071, 300);
  cycles_until(d, [&] { return d.view().velocity_rpm() >= 500; });
  write(d, 0x6040, 0x10F);
  d.step();
  const std::int64_t v0 = d.view().velocity_micro_rpm();
  d.step();
  EXPECT_EQ(v0 - d.view().velocity_micro_rpm(), 1000 * 1000) << "0x605D = 1: the slow-down ramp 0x6084";
}

TEST(modes, a_change_while_moving_hands_the_shaft_over) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::profile_velocity);
  write(d, 0x60FF, 1000);
  cycles_until(d, [&] { return d.view().velocity_rpm() == 1000; });
  write(d, 0x6060, cia402::mode::profile_position);
  EXPECT_EQ(read(d, 0x6061), cia402::mode::profile_velocity) << "until the drive has switched";
  d.step();
  EXPECT_EQ(read(d, 0x6061), cia402::mode::profile_position);
  const int stopped = cycles_until(d, [&] { return d.view().velocity_micro_rpm() == 0; });
  EXPECT_NEAR(stopped, 1000, 2) << "pp with no set-point brakes on 0x6084 (1000 rpm/s)";
  EXPECT_EQ(d.view().current(), state::operation_enabled);
}

TEST(modes, only_the_announced_modes_are_taken) {
  virtual_drive d(standard_profile());
  const std::int64_t supported = read(d, 0x6502);
  for (std::int64_t m = -3; m <= 12; ++m) {
    const bool announced = cia402::mode::supported_bit(m) & static_cast<std::uint32_t>(supported);
    EXPECT_EQ(d.write(0x6060, 0, m), announced ? sdo_abort::none : sdo_abort::invalid_value) << m;
  }
}

TEST(modes, the_same_commands_give_the_same_motion) {
  const auto run = [] {
    virtual_drive d(standard_profile());
    enable_in_mode(d, cia402::mode::homing);
    write(d, 0x6098, 3);
    write(d, 0x6040, 0x1F);
    std::vector<std::int64_t> positions;
    for (int i = 0; i < 3000; ++i) {
      d.step();
      positions.push_back(d.view().position());
    }
    return positions;
  };
  EXPECT_EQ(run(), run());
}

// ---- Exact cycles, halt in every mode, csv, the load, homing on the index pulse alone ----

// The trapezoid's time for d increments at profile velocity v [rpm], acceleration and deceleration a
// [rpm/s], with 0x608F = 10,000 increments a revolution: d/v + v/a when v is reached, else the
// triangle 2 sqrt(d/a).
double trapezoid_ms(double d, double v_rpm, double a_rpm_s) {
  const double d_rev = d / 10000.0, v = v_rpm / 60.0, a = a_rpm_s / 60.0;  // rev, rev/s, rev/s^2
  const double t = d_rev * a >= v * v ? d_rev / v + v / a : 2.0 * std::sqrt(d_rev / a);
  return t * 1000.0;
}

// Runs a pp move from rest and reports, counted from the cycle whose step first sees bit 4 (cycle
// 1, the cycle the motion starts in): when bit 12 first shows, the last cycle of motion, when bit 10
// first shows.
struct pp_timing {
  int ack = -1, arrived = -1, reached = -1;
};
pp_timing time_pp_move(virtual_drive& d, std::int64_t target) {
  pp_timing t;
  bool left_target = false;
  write(d, 0x607A, target);
  write(d, 0x6040, 0x1F);
  for (int cycle = 1; cycle <= 20000 && t.reached < 0; ++cycle) {
    if (cycle == 3) write(d, 0x6040, 0x0F);
    d.step();
    if (t.ack < 0 && (status(d) & bit12)) t.ack = cycle;
    if (t.arrived < 0 && d.view().position() == target && d.view().velocity_micro_rpm() == 0) t.arrived = cycle;
    // At rest before the move the drive shows bit 10 (the old target is reached): it falls once the
    // new set-point runs, and the first bit 10 after that is the new target's.
    if (!(status(d) & bit10)) left_target = true;
    if (t.reached < 0 && left_target && (status(d) & bit10)) t.reached = cycle;
  }
  return t;
}

TEST(profile_position, bit_12_then_bit_10_in_the_cycles_the_trapezoid_says) {
  struct move {
    std::int64_t d;
    std::uint32_t v, a;
  };
  for (const move m : {move{100000, 1000, 10000}, move{20000, 1000, 1000}, move{123457, 1500, 3000},
                       move{-40000, 600, 2000}}) {
    virtual_drive d(standard_profile());
    enable_in_mode(d, cia402::mode::profile_position);
    write(d, 0x6081, m.v);
    write(d, 0x6083, m.a);
    write(d, 0x6084, m.a);
    const pp_timing t = time_pp_move(d, m.d);
    const double expected = trapezoid_ms(static_cast<double>(std::llabs(m.d)), m.v, m.a);
    // Cycle n covers (n-1) ms .. n ms: the move ends in cycle ceil(t), or the one after.
    EXPECT_GE(t.arrived, static_cast<int>(std::ceil(expected - 1e-9))) << m.d;
    EXPECT_LE(t.arrived, static_cast<int>(std::ceil(expected - 1e-9)) + 1) << m.d;
    EXPECT_EQ(t.ack, 2) << "bit 12 in the status word of the cycle after the drive took the set-point";
    EXPECT_EQ(t.reached, t.arrived + 1) << "bit 10 in the status word of the cycle after arrival";
    EXPECT_EQ(read(d, 0x6064), m.d);
  }
}

TEST(profile_position, bit_10_waits_for_the_position_window_time) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::profile_position);
  write(d, 0x6068, 25);  // ms
  const pp_timing t = time_pp_move(d, 20000);
  // Inside the window from the arrival cycle on: 25 ms of it is the 25th cycle from arrival.
  EXPECT_EQ(t.reached, t.arrived + 24 + 1);
}

TEST(profile_position, change_immediately_replaces_the_running_set_point) {
  virtual_drive d(standard_profile());
  enable_pp_with_ramps(d, 10000);
  offer_setpoint(d, 100000);
  for (int i = 0; i < 150; ++i) d.step();
  ASSERT_GT(d.view().position(), 0);
  ASSERT_LT(d.view().position(), 20000);
  offer_setpoint(d, 20000, 0x20);  // bit 5: now
  std::int64_t highest = 0;
  cycles_until(d, [&] {
    highest = std::max(highest, d.view().position());
    return (status(d) & bit10) != 0;
  });
  // From 1000 rpm at 10,000 rpm/s the stop takes v^2 / 2a = 0.833 rev: well short of 100,000.
  EXPECT_LT(highest, 30000);
  EXPECT_EQ(read(d, 0x6064), 20000);
}

// Halt (bit 8) with 0x605D = 1 brakes on 0x6084, = 2 on 0x6085: the velocity falls by that rate x
// the cycle each cycle, and the state stays OPERATION ENABLED with bit 10 at standstill.
void expect_halt_ramps(virtual_drive& d, int code, std::int64_t rate_rpm_s, const std::function<void()>& each_cycle = [] {}) {
  write(d, 0x605D, code);
  const std::uint16_t cw = static_cast<std::uint16_t>(read(d, 0x6040));
  write(d, 0x6040, cw | 0x100);
  each_cycle();
  d.step();
  const std::int64_t v0 = d.view().velocity_micro_rpm();
  ASSERT_NE(v0, 0);
  each_cycle();
  d.step();
  EXPECT_EQ(std::llabs(v0) - std::llabs(d.view().velocity_micro_rpm()), rate_rpm_s * 1000) << "0x605D = " << code;
  const int stopped = cycles_until(d, [&] {
    each_cycle();
    return d.view().velocity_micro_rpm() == 0;
  });
  EXPECT_NEAR(stopped, std::llabs(v0) / (rate_rpm_s * 1000), 1);
  d.step();
  EXPECT_EQ(d.view().current(), state::operation_enabled);
  EXPECT_NE(status(d) & bit10, 0) << "halted at standstill";
}

TEST(profile_velocity, halt_ramps_by_0x605D_and_releasing_it_resumes) {
  for (const auto& [code, rate] : {std::pair{1, 1000}, std::pair{2, 10000}}) {
    virtual_drive d(standard_profile());
    enable_in_mode(d, cia402::mode::profile_velocity);
    write(d, 0x60FF, 600);
    cycles_until(d, [&] { return d.view().velocity_rpm() == 600; });
    expect_halt_ramps(d, code, rate);
    write(d, 0x6040, 0x0F);
    EXPECT_NEAR(cycles_until(d, [&] { return d.view().velocity_rpm() == 600; }), 600, 2)
        << "back up on 0x6083 (1000 rpm/s)";
  }
}

TEST(cyclic_synchronous_velocity, follows_0x60FF_plus_0x60B1_at_the_motor_acceleration_and_halts) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::cyclic_synchronous_velocity);
  write(d, 0x60FF, 1000);
  write(d, 0x60B1, 200);
  // The plant's max_acceleration, 100,000 rpm/s: 100 rpm a cycle, 1200 rpm in 12 cycles.
  EXPECT_EQ(cycles_until(d, [&] { return d.view().velocity_rpm() == 1200; }, 100), 12);
  d.step();
  EXPECT_NE(status(d) & bit12, 0) << "the drive follows the command value";
  expect_halt_ramps(d, 2, 10000);
  EXPECT_EQ(status(d) & bit12, 0) << "halted: not following";
}

TEST(cyclic_synchronous_torque, halt_ramps_by_0x605D) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::cyclic_synchronous_torque);
  write(d, 0x6071, 300);
  cycles_until(d, [&] { return d.view().velocity_rpm() >= 800; });
  expect_halt_ramps(d, 1, 1000);
}

TEST(cyclic_synchronous_torque, a_load_pulls_the_shaft_once_it_beats_friction) {
  // A load of 100 permille against 20 of friction: (100 - 20) x 20,000 / 1000 = 1,600 rpm/s
  // negative, 1.6 rpm a cycle; a torque of 100 holds it, 150 lifts it at (150 - 100 - 20) x 20 =
  // 600 rpm/s.
  cia402::sim::plant_config c;
  c.load_permille = 100;
  virtual_drive d(standard_profile(), c);
  enable_in_mode(d, cia402::mode::cyclic_synchronous_torque);
  const std::int64_t v_enabled = d.view().velocity_micro_rpm();  // the load pulls from brake release on
  EXPECT_LT(v_enabled, 0);
  for (int i = 0; i < 100; ++i) d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm() - v_enabled, -160'000'000);
  write(d, 0x6071, 150);
  // Friction acts against the (negative) motion: (150 - 100 + 20) x 20 = 1,400 rpm/s while it
  // still turns negative, 160 rpm gone in 115 cycles; from rest upwards 600 rpm/s.
  cycles_until(d, [&] { return d.view().velocity_micro_rpm() >= 0; }, 200);
  const std::int64_t v0 = d.view().velocity_micro_rpm();
  d.step();
  d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), v0 + 2 * 600'000) << "600 rpm/s upwards";
  EXPECT_EQ(read(d, 0x6077), 150);
}

TEST(profile_torque, a_torque_step_accelerates_as_torque_acceleration_says) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::profile_torque);
  write(d, 0x6087, 1000000);  // 1000 permille a cycle: a step
  write(d, 0x6071, 270);
  d.step();
  const std::int64_t v0 = d.view().velocity_micro_rpm();
  for (int i = 0; i < 50; ++i) d.step();
  // (270 - 20) x 20,000 / 1000 = 5,000 rpm/s: 5 rpm a cycle.
  EXPECT_EQ(d.view().velocity_micro_rpm() - v0, 50 * 5'000'000);
  EXPECT_EQ(read(d, 0x6077), 270);
}

TEST(cyclic_synchronous_position, halt_stops_following_on_the_0x605D_ramp) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::cyclic_synchronous_position);
  std::int64_t target = 0;
  const auto next = [&] {
    target += 100;  // 100 increments a ms: 600 rpm
    write(d, 0x607A, target);
  };
  for (int i = 0; i < 50; ++i) {
    next();
    d.step();
  }
  ASSERT_EQ(d.view().velocity_rpm(), 600);
  expect_halt_ramps(d, 2, 10000, next);
  EXPECT_EQ(status(d) & bit12, 0) << "halted: the drive does not follow the command value";
}

TEST(cyclic_synchronous_position, a_set_point_beyond_the_software_limit_is_cut_with_bit_11) {
  virtual_drive d(standard_profile());
  write_position_limits(d, -500, 500);
  enable_in_mode(d, cia402::mode::cyclic_synchronous_position);
  write(d, 0x607A, 400);
  d.step();
  d.step();
  EXPECT_EQ(read(d, 0x6064), 400);
  EXPECT_EQ(status(d) & bit11, 0);
  write(d, 0x607A, 900);
  d.step();
  d.step();
  EXPECT_EQ(read(d, 0x6064), 500);
  EXPECT_EQ(read(d, 0x6062), 500);
  EXPECT_NE(status(d) & bit11, 0);
}

TEST(homing, halt_interrupts_the_search_on_the_0x605D_ramp) {
  virtual_drive d(standard_profile());
  write(d, 0x6099, 600, 1);
  start_homing(d, 3);
  cycles_until(d, [&] { return d.view().velocity_rpm() == 600; });
  expect_halt_ramps(d, 1, 1000);
  // Interrupted (CiA 402-2: bit 13 = 0, bit 12 = 0, bit 10 = 1), then bit 8 falls: still interrupted
  // until a new rising edge of bit 4.
  EXPECT_EQ(status(d) & (bit10 | bit12 | bit13), bit10);
  write(d, 0x6040, 0x1F);
  for (int i = 0; i < 10; ++i) d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), 0);
  EXPECT_EQ(status(d) & (bit10 | bit12 | bit13), bit10);
  write(d, 0x6040, 0x0F);
  d.step();
  write(d, 0x6040, 0x1F);
  const int done = cycles_until(d, [&] { return (status(d) & (bit10 | bit12)) == (bit10 | bit12); }, 60000);
  EXPECT_GT(done, 0) << "a new start homes";
  EXPECT_EQ(read(d, 0x6064), 0);
}

TEST(homing, methods_33_and_34_home_on_the_next_index_pulse_below_or_above) {
  // Index pulses every revolution from 3,000: the next one below 0 is at -7,000, above at 3,000.
  for (const auto& [method, pulse] : {std::pair{33, -7000}, std::pair{34, 3000}}) {
    cia402::sim::plant_config c;
    c.index_position = 3000;
    virtual_drive d(standard_profile(), c);
    write(d, 0x607C, 100);
    start_homing(d, method);
    std::int64_t last = d.view().position(), jump = 0;
    const int done = cycles_until(d, [&] {
      const std::int64_t p = d.view().position();
      if (std::llabs(p - last) > 1000) jump = p - last;
      last = p;
      return (status(d) & (bit10 | bit12)) == (bit10 | bit12);
    }, 60000);
    ASSERT_GT(done, 0) << method;
    // The redefinition happens in the cycle the shaft comes to rest: at most one increment of that
    // cycle's travel goes with it.
    EXPECT_NEAR(jump, 100 - pulse, 1) << method << ": the pulse reads as the home offset";
    EXPECT_EQ(read(d, 0x6064), 100);
  }
}

}  // namespace
