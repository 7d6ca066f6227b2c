// A machine of N drives stepped together: each axis behaves exactly as a lone virtual drive given
// the same inputs, axes do not affect one another, and an axis stays small.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#include "cia402/sim/machine.hpp"
#include "sim_support.hpp"

namespace {

using namespace sim_test;

// Inputs for axis i at cycle c: a staggered enable, per-axis targets, and some axes disturbed.
void drive_inputs_for(drive_view v, std::size_t i, std::uint64_t c) {
  const std::uint64_t start = i % 17;
  if (c == start) v.write(0x6040, 0, 0x0006);
  if (c == start + 5) v.write(0x6040, 0, 0x000F);
  if (c == start + 8) v.write(0x60FF, 0, static_cast<std::int64_t>(i % 50) * 20 - 400);
  if (c == 150 && i % 7 == 0) v.write(0x6040, 0, 0x000B);     // quick stop
  if (c == 160 && i % 11 == 0) v.inject_fault(0x2310);        // fault
  if (c == 170 && i % 13 == 0) v.set_sto(true);
  if (c == 175 && i % 19 == 0) v.set_dc_link(false);
}

bool same(const axis_state& a, const axis_state& b) {
  return a.core.current == b.core.current && a.core.flags == b.core.flags &&
         a.core.error_code == b.core.error_code && a.core.pending_row == b.core.pending_row &&
         a.velocity == b.velocity && a.flags == b.flags && a.brake_timer == b.brake_timer &&
         a.last.status_word == b.last.status_word && a.last.torque == b.last.torque &&
         a.last.brake_released == b.last.brake_released;
}

TEST(machine, each_axis_steps_exactly_as_a_lone_virtual_drive_with_the_same_inputs) {
  constexpr std::size_t n = 300;
  machine m(standard_profile(), n);
  std::vector<std::unique_ptr<virtual_drive>> lone;
  for (std::size_t i = 0; i < n; ++i) lone.push_back(std::make_unique<virtual_drive>(standard_profile()));
  for (std::uint64_t c = 0; c < 400; ++c) {
    for (std::size_t i = 0; i < n; ++i) {
      drive_inputs_for(m.drive(i), i, c);
      drive_inputs_for(lone[i]->view(), i, c);
    }
    m.step();
    for (auto& d : lone) d->step();
  }
  std::size_t moving = 0, faulted = 0, stopped = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(same(m.axis_at(i), lone[i]->view().state_of_axis())) << "axis " << i;
    moving += m.drive(i).velocity_rpm() != 0;
    faulted += m.drive(i).current() == state::fault;
    stopped += m.drive(i).current() == state::switch_on_disabled;
  }
  EXPECT_GT(moving, 100u);  // the run is not trivial
  EXPECT_GT(faulted, 30u);
  EXPECT_GT(stopped, 10u);
  EXPECT_EQ(m.cycle(), 400u);
  EXPECT_EQ(m.time_us(), 400000u);
}

TEST(machine, a_fault_on_one_axis_leaves_its_neighbours_running) {
  machine m(standard_profile(), 3);
  for (std::size_t i = 0; i < 3; ++i) m.drive(i).write(0x6040, 0, 0x0006);
  for (int c = 0; c < 5; ++c) m.step();
  for (std::size_t i = 0; i < 3; ++i) m.drive(i).write(0x6040, 0, 0x000F);
  for (int c = 0; c < 5; ++c) m.step();
  m.drive(1).inject_fault(0x2310);
  for (int c = 0; c < 100; ++c) m.step();
  EXPECT_EQ(m.drive(0).current(), state::operation_enabled);
  EXPECT_EQ(m.drive(1).current(), state::fault);
  EXPECT_EQ(m.drive(2).current(), state::operation_enabled);
}

TEST(machine, ten_thousand_axes_enable_together) {
  machine m(standard_profile(), 10000);
  for (std::size_t i = 0; i < m.size(); ++i) m.drive(i).write(0x6040, 0, 0x0006);
  for (int c = 0; c < 3; ++c) m.step();
  for (std::size_t i = 0; i < m.size(); ++i) m.drive(i).write(0x6040, 0, 0x000F);
  for (int c = 0; c < 3; ++c) m.step();
  for (std::size_t i = 0; i < m.size(); ++i) {
    ASSERT_EQ(m.drive(i).current(), state::operation_enabled) << i;
  }
}

TEST(machine, an_axis_is_small) {
  // The core's axis (16 bytes) plus the plant (with the shaft's own position beside 0x6064), the
  // objects of every operation mode, the cyclic modes' interpolation, the profile position
  // generator and homing, the injected inputs, and the settled core's 62-byte snapshot (which lets
  // a cycle skip the core): 1,000 axes in 0.4 MB.
  EXPECT_EQ(machine::bytes_per_axis, sizeof(axis_state));
  EXPECT_LE(sizeof(axis_state), 416u);
  std::printf("sizeof(cia402::sim::axis_state) = %zu bytes (cia402::axis %zu)\n",
              sizeof(axis_state), sizeof(axis));
}

bool same_motion(const axis_state& a, const axis_state& b) {
  return same(a, b) && a.position == b.position && a.position_fraction == b.position_fraction &&
         a.demand == b.demand && a.torque == b.torque && a.mode_status == b.mode_status &&
         a.operation_mode == b.operation_mode && a.following_error_us == b.following_error_us;
}

TEST(machine, on_several_threads_every_axis_ends_bit_for_bit_as_on_one) {
  constexpr std::size_t n = 1000;
  machine one(standard_profile(), n, {}, 1);
  machine two(standard_profile(), n, {}, 2);
  machine three(standard_profile(), n, {}, 3);
  ASSERT_EQ(one.threads(), 1u);
  ASSERT_EQ(two.threads(), 2u);
  ASSERT_EQ(three.threads(), 3u);
  for (std::uint64_t c = 0; c < 400; ++c) {
    for (std::size_t i = 0; i < n; ++i) {
      drive_inputs_for(one.drive(i), i, c);
      drive_inputs_for(two.drive(i), i, c);
      drive_inputs_for(three.drive(i), i, c);
    }
    one.step();
    two.step();
    three.step();
  }
  std::size_t moving = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(same_motion(one.axis_at(i), two.axis_at(i))) << "axis " << i;
    ASSERT_TRUE(same_motion(one.axis_at(i), three.axis_at(i))) << "axis " << i;
    moving += one.drive(i).velocity_rpm() != 0;
  }
  EXPECT_GT(moving, 300u);
  EXPECT_EQ(two.cycle(), 400u);
}

TEST(machine, threads_are_not_spent_on_a_few_axes) {
  EXPECT_EQ(machine(standard_profile(), 10, {}, 4).threads(), 1u);
  EXPECT_EQ(machine(standard_profile(), 2 * machine::axes_per_thread_at_least, {}, 4).threads(), 2u);
  const machine hardware(standard_profile(), 100000, {}, 0);
  EXPECT_GE(hardware.threads(), 1u);
  EXPECT_LE(hardware.threads(), std::max(1u, std::thread::hardware_concurrency()));
}

// A cyclic master's set-points given inside the step: each axis's before it steps, once, on the
// thread that steps it. In csp the demand of a cycle is the set-point written in that cycle, so an
// axis that had stepped before its write would show last cycle's.
TEST(machine, a_per_axis_master_writes_each_axis_once_right_before_it_steps) {
  constexpr std::size_t n = 500;
  machine m(standard_profile(), n, {}, 2);
  ASSERT_EQ(m.threads(), 2u);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(m.drive(i).write(0x6060, 0, mode::cyclic_synchronous_position), sdo_abort::none);
    m.drive(i).write(0x6040, 0, 0x0006);
  }
  for (int c = 0; c < 3; ++c) m.step();
  for (std::size_t i = 0; i < n; ++i) m.drive(i).write(0x6040, 0, 0x000F);
  for (int c = 0; c < 60; ++c) m.step();  // past the brake release
  std::vector<int> calls(n, 0);
  for (std::int64_t c = 1; c <= 50; ++c) {
    m.step([&](drive_view d, std::size_t i) {
      ++calls[i];
      d.write(0x607A, 0, c * 10 + static_cast<std::int64_t>(i));
    });
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(m.drive(i).current(), state::operation_enabled) << i;
      ASSERT_EQ(m.drive(i).position_demand(), c * 10 + static_cast<std::int64_t>(i)) << "axis " << i;
      ASSERT_EQ(calls[i], c) << "axis " << i;
    }
  }
  // Followed within reach: the last set-point is where the shaft is.
  EXPECT_EQ(m.drive(n - 1).position(), 500 + static_cast<std::int64_t>(n - 1));
}

TEST(machine, helpers_asleep_between_cycles_wake_for_the_next_and_end_with_the_machine) {
  machine m(standard_profile(), 400, {}, 2);
  for (std::size_t i = 0; i < m.size(); ++i) m.drive(i).write(0x6040, 0, 0x0006);
  for (int c = 0; c < 3; ++c) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // past the helpers' spinning
    m.step();
  }
  for (std::size_t i = 0; i < m.size(); ++i) EXPECT_EQ(m.drive(i).current(), state::ready_to_switch_on) << i;
  EXPECT_EQ(m.cycle(), 3u);
}

TEST(machine, a_refused_configuration_throws) {
  plant_config c;
  c.cycle_us = 2000000;
  EXPECT_THROW({ machine refused(standard_profile(), 4, c); }, std::invalid_argument);
}

}  // namespace
