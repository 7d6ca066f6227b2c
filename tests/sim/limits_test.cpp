// The limits a strict drive protects its motor and machine with (CiA 402-2): max profile velocity
// 0x607F and max motor speed 0x6080 in every mode, max torque 0x6072 in the torque modes, each with
// status bit 11 while it cuts; pv, csv and the torque modes stopping *at* a software position limit
// 0x607D; the velocity window and threshold 0x606D..0x6070 behind pv's bits 10 and 12. Expectations
// come from the ramps and limits as written, never from a run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>

#include "cia402/words.hpp"
#include "mode_support.hpp"

namespace {

using namespace mode_test;
using cia402::sim::plant_config;

constexpr std::int64_t micro = 1000000;

TEST(speed_limit, the_objects_exist_and_0x6080_powers_on_at_the_plants_top_speed) {
  plant_config c;
  c.max_velocity_rpm = 4000;
  virtual_drive d(standard_profile(), c);
  EXPECT_EQ(read(d, 0x607F), 6000);
  EXPECT_EQ(read(d, 0x6080), 4000);
  EXPECT_EQ(read(d, 0x6072), 3000);
  write(d, 0x6080, 2500);
  EXPECT_EQ(read(d, 0x6080), 2500);
  EXPECT_EQ(d.write(0x6072, 0, 70000), sdo_abort::value_too_high) << "UNSIGNED16";
}

TEST(speed_limit, pv_beyond_0x6080_runs_at_the_motor_speed_with_bit_11) {
  virtual_drive d(standard_profile());
  write(d, 0x6083, 10000);
  enable_in_mode(d, cia402::mode::profile_velocity);
  write(d, 0x60FF, 20000);
  std::int64_t fastest = 0;
  for (int i = 0; i < 3000; ++i) {
    d.step();
    fastest = std::max(fastest, d.view().velocity_micro_rpm());
  }
  EXPECT_EQ(fastest, 6000 * micro);
  EXPECT_NE(status(d) & bit11, 0) << "internal limit active while the set-point is cut";
  EXPECT_NE(status(d) & bit10, 0) << "at the set-point as limited";
  write(d, 0x60FF, 5000);
  d.step();
  d.step();
  EXPECT_EQ(status(d) & bit11, 0) << "within the limit: bit 11 falls";
}

TEST(speed_limit, pv_backwards_is_cut_as_forwards) {
  virtual_drive d(standard_profile());
  write(d, 0x607F, 1500);
  write(d, 0x6083, 10000);
  enable_in_mode(d, cia402::mode::profile_velocity);
  write(d, 0x60FF, -3000);
  EXPECT_GT(cycles_until(d, [&] { return d.view().velocity_micro_rpm() == -1500 * micro; }), 0);
  for (int i = 0; i < 100; ++i) d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), -1500 * micro);
  EXPECT_NE(status(d) & bit11, 0);
}

TEST(speed_limit, pp_runs_a_move_at_0x607F_when_0x6081_asks_for_more) {
  virtual_drive d(standard_profile());
  write(d, 0x607F, 3000);
  write(d, 0x6081, 20000);
  write(d, 0x6083, 10000);
  write(d, 0x6084, 10000);
  enable_in_mode(d, cia402::mode::profile_position);
  write(d, 0x607A, 400000);  // 40 revolutions: long enough to cruise
  write(d, 0x6040, 0x1F);
  std::int64_t fastest = 0;
  bool limited_while_moving = false;
  const int reached = cycles_until(d, [&] {
    fastest = std::max(fastest, d.view().velocity_micro_rpm());
    if (d.view().velocity_micro_rpm() == 3000 * micro) limited_while_moving |= (status(d) & bit11) != 0;
    return (status(d) & bit10) != 0 && d.view().velocity_micro_rpm() == 0 && read(d, 0x6064) == 400000;
  });
  ASSERT_GT(reached, 0);
  EXPECT_EQ(fastest, 3000 * micro);
  EXPECT_TRUE(limited_while_moving);
  EXPECT_EQ(status(d) & bit11, 0) << "at rest at the target nothing is cut";
}

TEST(speed_limit, csv_and_the_torque_modes_saturate_at_0x6080_with_bit_11) {
  for (const std::int8_t mode : {cia402::mode::cyclic_synchronous_velocity, cia402::mode::cyclic_synchronous_torque,
                                 cia402::mode::profile_torque}) {
    SCOPED_TRACE(static_cast<int>(mode));
    virtual_drive d(standard_profile());
    write(d, 0x6080, 1200);
    write(d, 0x6087, 1000000);
    enable_in_mode(d, mode);
    write(d, 0x60FF, 5000);
    write(d, 0x6071, 900);
    std::int64_t fastest = 0;
    for (int i = 0; i < 2000; ++i) {
      d.step();
      fastest = std::max(fastest, d.view().velocity_micro_rpm());
    }
    EXPECT_EQ(fastest, 1200 * micro);
    EXPECT_NE(status(d) & bit11, 0);
  }
}

TEST(speed_limit, csp_travels_no_faster_than_0x6080_and_says_so) {
  virtual_drive d(standard_profile());
  write(d, 0x6080, 600);  // 100 increments a 1 ms cycle at 10,000 a revolution
  enable_in_mode(d, cia402::mode::cyclic_synchronous_position);
  const std::int64_t start = read(d, 0x6064);
  for (int i = 1; i <= 50; ++i) {
    write(d, 0x607A, start + 200 * i);  // asks for 1200 rpm
    d.step();
  }
  EXPECT_EQ(read(d, 0x6064), start + 50 * 100);
  EXPECT_EQ(d.view().velocity_micro_rpm(), 600 * micro);
  EXPECT_NE(status(d) & bit11, 0);
}

TEST(speed_limit, homing_searches_no_faster_than_0x607F) {
  virtual_drive d(standard_profile());
  write(d, 0x607F, 400);
  start_homing(d, 3);
  std::int64_t fastest = 0;
  bool limited = false;
  const int done = cycles_until(d, [&] {
    fastest = std::max<std::int64_t>(fastest, std::llabs(d.view().velocity_micro_rpm()));
    limited |= (status(d) & bit11) != 0;
    return (status(d) & (bit10 | bit12)) == (bit10 | bit12);
  }, 60000);
  ASSERT_GT(done, 0);
  EXPECT_EQ(fastest, 400 * micro) << "0x6099 sub 1 (1000 rpm) cut to 0x607F";
  EXPECT_TRUE(limited);
}

TEST(max_torque, cst_and_tq_cut_the_demand_to_0x6072_with_bit_11) {
  for (const std::int8_t mode : {cia402::mode::cyclic_synchronous_torque, cia402::mode::profile_torque}) {
    SCOPED_TRACE(static_cast<int>(mode));
    virtual_drive d(standard_profile());
    write(d, 0x6072, 400);
    write(d, 0x6087, 100000);
    enable_in_mode(d, mode);
    write(d, 0x6071, -700);
    for (int i = 0; i < 50; ++i) d.step();
    EXPECT_EQ(read(d, 0x6077), -400);
    EXPECT_NE(status(d) & bit11, 0);
    write(d, 0x6071, 300);
    for (int i = 0; i < 50; ++i) d.step();
    EXPECT_EQ(read(d, 0x6077), 300);
    EXPECT_EQ(status(d) & bit11, 0);
  }
}

TEST(software_limit, pv_brakes_so_as_to_stand_at_the_limit_not_beyond_it) {
  // 3000 rpm towards a limit 30 revolutions out: the quick-stop ramp (10,000 rpm/s) needs 7.5
  // revolutions, so braking starts before the limit and the shaft stands exactly on it.
  for (const std::int32_t rpm : {3000, -3000, 100, 5999}) {
    SCOPED_TRACE(rpm);
    virtual_drive d(standard_profile());
    write_position_limits(d, -300000, 300000);
    write(d, 0x6083, 10000);
    enable_in_mode(d, cia402::mode::profile_velocity);
    write(d, 0x60FF, rpm);
    const std::int64_t limit = rpm > 0 ? 300000 : -300000;
    std::int64_t farthest = 0;
    const int stopped = cycles_until(d, [&] {
      farthest = rpm > 0 ? std::max(farthest, d.view().position()) : std::min(farthest, d.view().position());
      return d.view().velocity_micro_rpm() == 0;
    }, 400000);
    ASSERT_GT(stopped, 0);
    EXPECT_EQ(d.view().position(), limit);
    EXPECT_EQ(farthest, limit) << "never past it";
    for (int i = 0; i < 100; ++i) d.step();
    EXPECT_EQ(d.view().position(), limit) << "and stays there";
    EXPECT_NE(status(d) & bit11, 0) << "while 0x60FF points outwards";
    write(d, 0x60FF, -rpm);
    for (int i = 0; i < 100; ++i) d.step();
    EXPECT_LT(std::llabs(d.view().position()), 300000) << "inwards it moves again";
  }
}

// How far the shaft travels in one 1 ms plant cycle at `rpm` (10,000 increments a revolution).
std::int64_t cycle_travel(std::int64_t rpm) { return std::llabs(rpm) * 10000 / 60000 + 1; }

TEST(software_limit, csv_brakes_so_as_to_stand_at_the_limit_not_beyond_it) {
  // As pv: 0x60FF towards a limit 30 revolutions out brakes on the quick-stop ramp 0x6085 early
  // enough to stand at the limit (before, csv braked only once there: 7.5 revolutions beyond).
  for (const std::int32_t rpm : {3000, -3000, 100, 5999}) {
    SCOPED_TRACE(rpm);
    virtual_drive d(standard_profile());
    write_position_limits(d, -300000, 300000);
    enable_in_mode(d, cia402::mode::cyclic_synchronous_velocity);
    write(d, 0x60FF, rpm);
    const std::int64_t limit = rpm > 0 ? 300000 : -300000;
    std::int64_t farthest = 0;
    bool limited_before_the_limit = false;
    const int stopped = cycles_until(d, [&] {
      farthest = rpm > 0 ? std::max(farthest, d.view().position()) : std::min(farthest, d.view().position());
      limited_before_the_limit |= (status(d) & bit11) != 0 && d.view().position() != limit;
      return d.view().velocity_micro_rpm() == 0;
    }, 400000);
    ASSERT_GT(stopped, 0);
    EXPECT_LE(std::llabs(farthest), 300000) << "never past it";
    EXPECT_GE(std::llabs(d.view().position()), 300000 - cycle_travel(rpm)) << "stands at it";
    EXPECT_TRUE(limited_before_the_limit) << "bit 11 while braking for it";
    const std::int64_t stood = d.view().position();
    for (int i = 0; i < 100; ++i) d.step();
    EXPECT_EQ(d.view().position(), stood) << "and stays there";
    EXPECT_NE(status(d) & bit11, 0) << "while 0x60FF points outwards";
    write(d, 0x60FF, -rpm);
    for (int i = 0; i < 100; ++i) d.step();
    EXPECT_LT(std::llabs(d.view().position()), std::llabs(stood)) << "inwards it moves again";
    EXPECT_EQ(status(d) & bit11, 0) << "nothing cuts the way back";
  }
}

TEST(software_limit, the_torque_modes_brake_so_as_to_stand_at_the_limit_not_beyond_it) {
  // A torque towards a limit 30 revolutions out accelerates the shaft to the motor's top speed; the
  // drive brakes on 0x6085 so as to stand at the limit, whatever the torque asks.
  for (const std::int8_t mode : {cia402::mode::cyclic_synchronous_torque, cia402::mode::profile_torque}) {
    for (const std::int32_t torque : {1000, -1000, 150}) {
      SCOPED_TRACE(testing::Message() << "mode " << static_cast<int>(mode) << " torque " << torque);
      virtual_drive d(standard_profile());
      write_position_limits(d, -300000, 300000);
      write(d, 0x6087, 1000000);
      enable_in_mode(d, mode);
      write(d, 0x6071, torque);
      const std::int64_t limit = torque > 0 ? 300000 : -300000;
      std::int64_t farthest = 0;
      std::int64_t fastest = 0;
      bool limited_before_the_limit = false;
      const int stopped = cycles_until(d, [&] {
        const std::int64_t at = d.view().position();
        farthest = torque > 0 ? std::max(farthest, at) : std::min(farthest, at);
        fastest = std::max<std::int64_t>(fastest, std::llabs(d.view().velocity_micro_rpm()));
        limited_before_the_limit |= (status(d) & bit11) != 0 && at != limit;
        return std::llabs(at) > 100000 && d.view().velocity_micro_rpm() == 0;
      }, 400000);
      ASSERT_GT(stopped, 0);
      EXPECT_LE(std::llabs(farthest), 300000) << "never past it";
      EXPECT_GE(std::llabs(d.view().position()), 300000 - cycle_travel(fastest / micro)) << "stands at it";
      EXPECT_TRUE(limited_before_the_limit) << "bit 11 while braking for it";
      const std::int64_t stood = d.view().position();
      for (int i = 0; i < 100; ++i) d.step();
      EXPECT_EQ(d.view().position(), stood) << "and stays there";
      EXPECT_NE(status(d) & bit11, 0) << "while the torque points outwards";
      write(d, 0x6071, -torque);
      for (int i = 0; i < 200; ++i) d.step();
      EXPECT_LT(std::llabs(d.view().position()), std::llabs(stood)) << "inwards it moves again";
    }
  }
}

TEST(software_limit, turning_back_towards_a_near_limit_moves_the_shaft_no_faster_than_it_turns) {
  // Away from the upper limit, then towards it: where the limit cuts the way back, the velocity
  // passes through 0 far from it. The shaft must not take that for arriving and jump to the limit.
  for (const std::int8_t mode : {cia402::mode::profile_velocity, cia402::mode::cyclic_synchronous_velocity}) {
    SCOPED_TRACE(static_cast<int>(mode));
    virtual_drive d(standard_profile());
    write_position_limits(d, -300000, 5000);
    write(d, 0x6083, 10000);
    enable_in_mode(d, mode);
    write(d, 0x60FF, -600);
    for (int i = 0; i < 500; ++i) d.step();
    write(d, 0x60FF, 3000);
    std::int64_t last = d.view().position();
    std::int64_t largest_step = 0;
    for (int i = 0; i < 3000; ++i) {
      d.step();
      largest_step = std::max<std::int64_t>(largest_step, std::llabs(d.view().position() - last));
      last = d.view().position();
    }
    EXPECT_LE(largest_step, cycle_travel(3000));
    EXPECT_EQ(last, 5000) << "and it still ends at the limit";
  }
}

TEST(velocity_window, pv_bit_10_waits_for_0x606E_within_0x606D) {
  virtual_drive d(standard_profile());
  write(d, 0x606D, 20);
  write(d, 0x606E, 50);
  enable_in_mode(d, cia402::mode::profile_velocity);
  write(d, 0x60FF, 1000);  // 1000 rpm/s: one rpm a cycle
  const int inside = cycles_until(d, [&] { return d.view().velocity_micro_rpm() >= 980 * micro; });
  ASSERT_GT(inside, 0);
  EXPECT_EQ(status(d) & bit10, 0);
  // Within the window from now on; bit 10 after 50 ms of it, shown the cycle after.
  const int reached = cycles_until(d, [&] { return (status(d) & bit10) != 0; }, 200);
  EXPECT_NEAR(reached, 50, 1);
  write(d, 0x60FF, 0);
  d.step();
  EXPECT_EQ(status(d) & bit10, 0) << "a new set-point takes bit 10 away at once";
}

TEST(velocity_threshold, pv_bit_12_falls_once_beyond_0x606F_for_longer_than_0x6070) {
  virtual_drive d(standard_profile());
  write(d, 0x606F, 100);
  write(d, 0x6070, 30);
  enable_in_mode(d, cia402::mode::profile_velocity);
  EXPECT_NE(status(d) & bit12, 0) << "at rest: speed 0";
  write(d, 0x60FF, 1000);
  const int beyond = cycles_until(d, [&] { return d.view().velocity_micro_rpm() > 100 * micro; });
  ASSERT_GT(beyond, 0);
  EXPECT_NE(status(d) & bit12, 0) << "beyond the threshold, not yet for 30 ms";
  const int fell = cycles_until(d, [&] { return (status(d) & bit12) == 0; }, 200);
  EXPECT_NEAR(fell, 31, 1) << "30 ms beyond it, shown the cycle after";
  write(d, 0x60FF, 0);
  EXPECT_GT(cycles_until(d, [&] { return d.view().velocity_micro_rpm() <= 100 * micro; }), 0);
  d.step();
  EXPECT_NE(status(d) & bit12, 0) << "within the threshold bit 12 is set at once";
}

TEST(velocity_window, the_plants_windows_give_0x606D_and_0x606F_their_power_on_values) {
  plant_config c;
  c.target_window_rpm = 25;
  c.standstill_window_rpm = 3;
  virtual_drive d(standard_profile(), c);
  EXPECT_EQ(read(d, 0x606D), 25);
  EXPECT_EQ(read(d, 0x606F), 3);
  EXPECT_EQ(read(d, 0x606E), 0);
  EXPECT_EQ(read(d, 0x6070), 0);
  c.target_window_rpm = 70000;
  EXPECT_STRNE(cia402::sim::check_plant_config(c), nullptr) << "0x606D is UNSIGNED16";
}

}  // namespace
