// The cyclic synchronous modes interpolate between set-points over the interpolation time period
// 0x60C2 (value x 10^index s, CiA 402-2): a master that sends a set-point every 10 ms to a drive
// with a 1 ms cycle sees its axis move evenly between them. With the period equal to the cycle (the
// default) every set-point is taken as it comes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "mode_support.hpp"

namespace {

using namespace mode_test;

constexpr std::int64_t micro = 1000000;

// 0x60C2 = value x 10^-3 s.
void set_period_ms(virtual_drive& d, int ms) {
  write(d, 0x60C2, -3, 2);
  write(d, 0x60C2, ms, 1);
}

// A csp master that moves its set-point 500 increments every 10 ms (300 rpm at 10,000 increments a
// revolution), for `cycles` 1 ms cycles; the velocities the drive shows after each.
std::vector<std::int64_t> stream_every_10_ms(virtual_drive& d, int cycles) {
  std::vector<std::int64_t> velocities;
  const std::int64_t start = read(d, 0x6064);
  for (int c = 0; c < cycles; ++c) {
    if (c % 10 == 0) write(d, 0x607A, start + 500 * (c / 10 + 1));
    d.step();
    velocities.push_back(d.view().velocity_micro_rpm());
  }
  return velocities;
}

TEST(interpolation, csp_with_a_10_ms_period_moves_evenly_at_300_rpm) {
  virtual_drive d(standard_profile());
  set_period_ms(d, 10);
  enable_in_mode(d, cia402::mode::cyclic_synchronous_position);
  const std::vector<std::int64_t> v = stream_every_10_ms(d, 400);
  // After the first period (which starts from rest), every cycle runs at 300 rpm: 50 increments.
  for (std::size_t c = 20; c < v.size(); ++c) ASSERT_EQ(v[c], 300 * micro) << "cycle " << c;
  EXPECT_NE(status(d) & bit12, 0) << "it follows the command value";
  EXPECT_EQ(status(d) & (bit11 | bit13), 0);
  // One period behind the master: the set-point of the period before is where it stands.
  const std::int64_t error = read(d, 0x607A) - read(d, 0x6064);
  EXPECT_GE(error, 0);
  EXPECT_LE(error, 1000);
}

TEST(interpolation, csp_with_the_default_period_takes_each_set_point_within_the_cycle) {
  virtual_drive d(standard_profile());
  EXPECT_EQ(read(d, 0x60C2, 1), 1);
  EXPECT_EQ(read(d, 0x60C2, 2), -3);
  enable_in_mode(d, cia402::mode::cyclic_synchronous_position);
  const std::vector<std::int64_t> v = stream_every_10_ms(d, 100);
  // 500 increments in one cycle (3000 rpm), then standing until the next set-point.
  EXPECT_EQ(*std::max_element(v.begin(), v.end()), 3000 * micro);
  EXPECT_EQ(std::count(v.begin(), v.end(), 0), 90);
}

TEST(interpolation, csp_moves_evenly_whatever_the_cycle_in_the_period_the_master_writes_in) {
  // A 5 ms period (value 5, index -3), the master writing 250 increments (300 rpm) in the third
  // cycle of each of its periods, or in the first, or the last.
  for (const int phase : {0, 2, 4}) {
    SCOPED_TRACE(phase);
    virtual_drive d(standard_profile());
    set_period_ms(d, 5);
    enable_in_mode(d, cia402::mode::cyclic_synchronous_position);
    const std::int64_t start = read(d, 0x6064);
    std::vector<std::int64_t> positions;
    for (int c = 0; c < 200; ++c) {
      if (c % 5 == phase) write(d, 0x607A, start + 250 * (c / 5 + 1));
      d.step();
      positions.push_back(read(d, 0x6064));
    }
    for (std::size_t c = 20; c + 1 < positions.size(); ++c) {
      ASSERT_EQ(positions[c + 1] - positions[c], 50) << "cycle " << c;
    }
  }
}

// What `sample` reads after each of `cycles` steps.
std::vector<std::int64_t> samples(virtual_drive& d, int cycles, const std::function<std::int64_t()>& sample) {
  std::vector<std::int64_t> v;
  for (int c = 0; c < cycles; ++c) {
    d.step();
    v.push_back(sample());
  }
  return v;
}

// The period under way when a set-point was written still runs towards 0; the next one goes from 0
// to the set-point in ten equal steps of `step`, then it holds.
void expect_ramp_over_the_next_period(const std::vector<std::int64_t>& v, std::int64_t step) {
  const auto first = std::find_if(v.begin(), v.end(), [](std::int64_t x) { return x != 0; });
  ASSERT_NE(first, v.end());
  for (int i = 0; i < 10; ++i) EXPECT_EQ(*(first + i), step * (i + 1)) << i;
  EXPECT_EQ(v.back(), 10 * step);
}

TEST(interpolation, csv_ramps_a_step_of_0x60FF_over_the_period) {
  virtual_drive d(standard_profile());
  set_period_ms(d, 10);
  enable_in_mode(d, cia402::mode::cyclic_synchronous_velocity);
  write(d, 0x60FF, 500);
  // 0 to 500 rpm in ten equal steps of 50 rpm (below the motor's 100 rpm a cycle).
  expect_ramp_over_the_next_period(samples(d, 25, [&] { return d.view().velocity_micro_rpm(); }),
                                   50 * micro);
}

TEST(interpolation, cst_ramps_a_step_of_0x6071_over_the_period) {
  virtual_drive d(standard_profile());
  set_period_ms(d, 10);
  enable_in_mode(d, cia402::mode::cyclic_synchronous_torque);
  write(d, 0x6071, 500);
  expect_ramp_over_the_next_period(samples(d, 25, [&] { return read(d, 0x6077); }), 50);
}

}  // namespace
