// A machine of N drives stepped together: each axis behaves exactly as a lone virtual drive given
// the same inputs, axes do not affect one another, and an axis stays small.
#include <gtest/gtest.h>

#include <cstring>
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
  // The core's axis (14 bytes) plus the plant, the objects of every operation mode, the profile
  // position generator and homing, and the injected inputs: 1,000 axes in a quarter megabyte.
  EXPECT_EQ(machine::bytes_per_axis, sizeof(axis_state));
  EXPECT_LE(sizeof(axis_state), 288u);
  std::printf("sizeof(cia402::sim::axis_state) = %zu bytes (cia402::axis %zu)\n",
              sizeof(axis_state), sizeof(axis));
}

TEST(machine, a_refused_configuration_throws) {
  plant_config c;
  c.cycle_us = 2000000;
  EXPECT_THROW({ machine refused(standard_profile(), 4, c); }, std::invalid_argument);
}

}  // namespace
