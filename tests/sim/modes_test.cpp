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

namespace {

using cia402::sdo_abort;
using cia402::standard_profile;
using cia402::state;
using cia402::sim::virtual_drive;

constexpr std::uint16_t bit10 = 1u << 10, bit11 = 1u << 11, bit12 = 1u << 12, bit13 = 1u << 13;

std::int64_t read(virtual_drive& d, std::uint16_t index, std::uint8_t sub = 0) {
  std::int64_t v = 0;
  EXPECT_EQ(d.read(index, sub, v), sdo_abort::none) << std::hex << index;
  return v;
}

void write(virtual_drive& d, std::uint16_t index, std::int64_t value, std::uint8_t sub = 0) {
  ASSERT_EQ(d.write(index, sub, value), sdo_abort::none) << std::hex << index << " = " << value;
}

std::uint16_t status(virtual_drive& d) { return d.view().outputs().status_word; }

// Shutdown, switch on, enable operation: the brake (30 ms) opens within the 60 cycles each gets.
void enable_in_mode(virtual_drive& d, std::int8_t mode) {
  write(d, 0x6060, mode);
  for (int word : {0x06, 0x07, 0x0F}) {
    write(d, 0x6040, word);
    for (int i = 0; i < 60; ++i) d.step();
  }
  ASSERT_EQ(d.view().current(), state::operation_enabled);
  ASSERT_EQ(read(d, 0x6061), mode);
}

// Steps until `done` holds (at most `limit` cycles); the cycles it took, or -1.
int cycles_until(virtual_drive& d, const std::function<bool()>& done, int limit = 20000) {
  for (int i = 1; i <= limit; ++i) {
    d.step();
    if (done()) return i;
  }
  return -1;
}

// A pp set-point: target, bit 4 up with the given bits, wait for bit 12, bit 4 down.
int offer_setpoint(virtual_drive& d, std::int64_t target, std::uint16_t bits = 0) {
  write(d, 0x607A, target);
  write(d, 0x6040, 0x1F | bits);
  const int ack = cycles_until(d, [&] { return (status(d) & bit12) != 0; }, 10);
  write(d, 0x6040, 0x0F | (bits & ~0x10u));
  d.step();  // the drive sees bit 4 low before the next set-point's edge
  return ack;
}

TEST(profile_position, a_move_takes_the_time_the_trapezoid_says_and_sets_bit_12_then_bit_10) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, cia402::mode::profile_position);
  write(d, 0x6081, 1000);   // rpm
  write(d, 0x6083, 10000);  // rpm/s
  write(d, 0x6084, 10000);
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
  enable_in_mode(d, cia402::mode::profile_position);
  write(d, 0x6083, 10000);
  write(d, 0x6084, 10000);
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
  write(d, 0x607D, -1000, 1);
  write(d, 0x607D, 30000, 2);
  enable_in_mode(d, cia402::mode::profile_position);
  offer_setpoint(d, 50000);
  cycles_until(d, [&] { return (status(d) & bit10) != 0; });
  EXPECT_EQ(read(d, 0x6064), 30000);
  EXPECT_NE(status(d) & bit11, 0);
}

TEST(profile_velocity, runs_into_a_software_limit_and_stops_with_bit_11) {
  virtual_drive d(standard_profile());
  write(d, 0x607D, -100000, 1);
  write(d, 0x607D, 5000, 2);
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
  write(d, 0x6098, 3);
  write(d, 0x607C, 1234);
  enable_in_mode(d, cia402::mode::homing);
  write(d, 0x6040, 0x1F);
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

TEST(homing, an_unsupported_method_is_refused) {
  virtual_drive d(standard_profile());
  EXPECT_EQ(d.write(0x6098, 0, 1), sdo_abort::invalid_value);
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
  // 500,000 increments away: at the motor's 6000 rpm (10,000 increments a ms) the error stays beyond
  // the 10,000-increment window for longer than the 10 ms time out.
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

}  // namespace
