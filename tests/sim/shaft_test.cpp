// The plant's shaft and the places on it: limit switches, a home switch and the encoder's index
// pulses are fixed on the shaft, and homing changes what 0x6064 reads, never where they are
// (issue 34: the second method-3 run from home redefined home 4 revolutions away). 0x60FD shows
// the switches; 0x60E3 lists the homing methods 0x6098 takes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "cia402/motion/homing.hpp"
#include "mode_support.hpp"

namespace {

using namespace mode_test;
using cia402::sim::plant_config;

constexpr std::uint32_t negative_limit = 1u << 0, positive_limit = 1u << 1, home_switch = 1u << 2;
constexpr std::uint32_t index_pulse = 1u << 16;

// Starts a homing run (bit 4 rising) and steps until it is attained and at rest, or fails; the
// status word it ended with. The status word shows a cycle's motion in the next cycle: the first
// one after the start still shows the run before.
std::uint16_t run_homing(virtual_drive& d, int limit = 200000) {
  write(d, 0x6040, 0x0F);
  d.step();
  write(d, 0x6040, 0x1F);
  d.step();
  cycles_until(d, [&] { return (status(d) & bit13) != 0 || (status(d) & (bit10 | bit12)) == (bit10 | bit12); },
               limit);
  return status(d);
}

TEST(physical_shaft, method_3_run_again_from_its_home_finds_the_same_home) {
  virtual_drive d(standard_profile());
  write(d, 0x6098, 3);
  write(d, 0x607C, 1234);
  enable_in_mode(d, cia402::mode::homing);
  ASSERT_EQ(run_homing(d) & (bit10 | bit12 | bit13), bit10 | bit12);
  EXPECT_EQ(read(d, 0x6064), 1234);
  EXPECT_EQ(d.view().shaft_position(), 40000) << "the pulse left of the switch's edge at 50,000";
  std::int64_t farthest = 0;
  write(d, 0x6040, 0x0F);
  d.step();
  write(d, 0x6040, 0x1F);
  d.step();
  cycles_until(d, [&] {
    farthest = std::max<std::int64_t>(farthest, std::llabs(d.view().shaft_position() - 40000));
    return (status(d) & (bit10 | bit12)) == (bit10 | bit12) && d.view().velocity_micro_rpm() == 0;
  }, 100000);
  EXPECT_EQ(status(d) & bit13, 0);
  EXPECT_EQ(read(d, 0x6064), 1234);
  EXPECT_EQ(d.view().shaft_position(), 40000);
  EXPECT_LT(farthest, 2 * 10000) << "one revolution to the switch and back, not four";
}

// An index pulse is latched on its edge as the shaft moves across it (docs/semantics.md S19): each
// run starts standing on a pulse (the plant's first lies under the shaft at power-up) and goes on to
// the next, a revolution on; home reads as 0x607C each time.
TEST(physical_shaft, method_34_with_a_home_offset_run_again_goes_on_to_the_next_pulse) {
  virtual_drive d(standard_profile());
  write(d, 0x6098, 34);
  write(d, 0x607C, 2500);
  enable_in_mode(d, cia402::mode::homing);
  for (int run = 0; run < 3; ++run) {
    SCOPED_TRACE(run);
    ASSERT_EQ(run_homing(d) & (bit10 | bit12 | bit13), bit10 | bit12);
    EXPECT_EQ(read(d, 0x6064), 2500);
    EXPECT_EQ(d.view().shaft_position(), 10000 * (run + 1)) << "not the pulse under the shaft at the start";
  }
}

// The plant each method suits: its home switch on the side the method expects, limit switches at
// -200,000 and +300,000, index pulses every revolution from 3,000.
plant_config plant_for(int method) {
  plant_config c;
  c.negative_limit_switch = -200000;
  c.positive_limit_switch = 300000;
  c.index_position = 3000;
  const int base = method > 16 && method <= 30 ? method - 16 : method;
  if (base == 5 || base == 6) {
    c.home_switch_position.reset();  // a negative home switch: from the negative end up to 50,000
    c.home_switch_end = 50000;
  } else if (base >= 7 && base <= 14) {
    c.home_switch_end = 80000;  // a cam from 50,000 to 80,000
  }
  return c;
}

TEST(physical_shaft, every_method_of_0x60E3_run_twice_on_the_drive_ends_where_it_ended_the_first_time) {
  virtual_drive probe(standard_profile());
  const std::int64_t count = read(probe, 0x60E3, 0);
  for (int sub = 1; sub <= count; ++sub) {
    const int method = static_cast<int>(read(probe, 0x60E3, static_cast<std::uint8_t>(sub)));
    SCOPED_TRACE("method " + std::to_string(method));
    virtual_drive d(standard_profile(), plant_for(method));
    write(d, 0x6098, method);
    write(d, 0x607C, -321);
    enable_in_mode(d, cia402::mode::homing);
    ASSERT_EQ(run_homing(d) & (bit10 | bit12 | bit13), bit10 | bit12);
    const std::int64_t home = d.view().shaft_position();
    EXPECT_EQ(read(d, 0x6064), -321);
    ASSERT_EQ(run_homing(d) & (bit10 | bit12 | bit13), bit10 | bit12);
    // 33 and 34 start standing on their pulse, which is not latched: the next one, a revolution on.
    const std::int64_t again = method == 33 ? home - 10000 : method == 34 ? home + 10000 : home;
    EXPECT_EQ(d.view().shaft_position(), again);
    EXPECT_EQ(read(d, 0x6064), -321);
  }
}

TEST(supported_homing_methods, 0x60E3_lists_exactly_the_methods_0x6098_takes) {
  virtual_drive d(standard_profile());
  std::vector<std::int64_t> listed;
  const std::int64_t count = read(d, 0x60E3, 0);
  for (int sub = 1; sub <= count; ++sub) listed.push_back(read(d, 0x60E3, static_cast<std::uint8_t>(sub)));
  std::int64_t v = 0;
  EXPECT_EQ(d.read(0x60E3, static_cast<std::uint8_t>(count + 1), v), sdo_abort::sub_index_does_not_exist);
  EXPECT_EQ(d.write(0x60E3, 1, 3), sdo_abort::read_only_object);
  std::vector<std::int64_t> taken;
  for (int m = -128; m <= 127; ++m) {
    if (d.write(0x6098, 0, m) == sdo_abort::none) taken.push_back(m);
    EXPECT_EQ(cia402::motion::homing::supports(m), d.write(0x6098, 0, m) == sdo_abort::none) << m;
  }
  EXPECT_EQ(listed, taken);
  EXPECT_EQ(listed.size(), 32u) << "1..14, 17..30, 33, 34, 35, 37";
}

TEST(digital_inputs, 0x60FD_shows_the_switches_where_the_shaft_is_and_each_index_pulse_it_passes) {
  plant_config c;
  c.negative_limit_switch = -30000;
  c.positive_limit_switch = 70000;
  c.index_position = 5000;  // not under the shaft at the start
  virtual_drive d(standard_profile(), c);
  EXPECT_EQ(read(d, 0x60FD) & 0x7u, 0u);
  write(d, 0x6083, 10000);
  enable_in_mode(d, cia402::mode::profile_velocity);
  write(d, 0x60FF, 600);  // 100 increments a cycle: a pulse every 100 cycles
  int pulses = 0;
  for (int i = 0; i < 1000; ++i) {
    d.step();
    const std::uint32_t in = static_cast<std::uint32_t>(read(d, 0x60FD));
    const std::int64_t at = d.view().shaft_position();
    ASSERT_EQ((in & home_switch) != 0, at >= 50000) << at;
    ASSERT_EQ((in & positive_limit) != 0, at > 70000) << at;
    ASSERT_EQ(in & negative_limit, 0u);
    pulses += (in & index_pulse) != 0;
  }
  EXPECT_GT(d.view().shaft_position(), 70000);
  EXPECT_EQ(pulses, static_cast<int>((d.view().shaft_position() - 5000) / 10000 + 1)) << "one cycle per pulse passed";
  write(d, 0x60FF, -6000);
  EXPECT_GT(cycles_until(d, [&] { return (read(d, 0x60FD) & negative_limit) != 0; }), 0);
  EXPECT_LT(d.view().shaft_position(), -30000);
  EXPECT_EQ(d.write(0x60FD, 0, 0), sdo_abort::read_only_object);
}

TEST(digital_inputs, after_homing_the_switches_are_where_they_were_on_the_shaft) {
  virtual_drive d(standard_profile());
  write(d, 0x6098, 37);
  write(d, 0x607C, 100000);  // here reads 100,000 from now on
  enable_in_mode(d, cia402::mode::homing);
  ASSERT_EQ(run_homing(d) & (bit10 | bit12), bit10 | bit12);
  EXPECT_EQ(read(d, 0x6064), 100000);
  write(d, 0x6060, cia402::mode::profile_velocity);
  write(d, 0x60FF, 600);
  const int on = cycles_until(d, [&] { return (read(d, 0x60FD) & home_switch) != 0; }, 5000);
  ASSERT_GT(on, 0);
  EXPECT_EQ(d.view().shaft_position() >= 50000 && d.view().shaft_position() < 50100, true);
  EXPECT_EQ(read(d, 0x6064), d.view().shaft_position() + 100000);
}

TEST(physical_shaft, a_limit_switch_the_method_does_not_expect_ends_the_run_with_bit_13) {
  // Method 3 expects a home switch reaching to the positive end; right of a cam it finds the
  // positive limit switch instead.
  virtual_drive d(standard_profile(), plant_for(7));
  write(d, 0x6083, 10000);
  enable_in_mode(d, cia402::mode::profile_velocity);
  write(d, 0x60FF, 3000);
  ASSERT_GT(cycles_until(d, [&] { return d.view().shaft_position() > 150000; }), 0);
  write(d, 0x60FF, 0);
  ASSERT_GT(cycles_until(d, [&] { return d.view().velocity_micro_rpm() == 0; }), 0);
  write(d, 0x6098, 3);
  write(d, 0x6060, cia402::mode::homing);
  const std::int64_t shift = read(d, 0x6064) - d.view().shaft_position();
  const std::uint16_t ended = run_homing(d);
  EXPECT_NE(ended & bit13, 0);
  EXPECT_EQ(ended & bit12, 0);
  EXPECT_GT(d.view().shaft_position(), 300000) << "it met the positive limit switch";
  EXPECT_EQ(read(d, 0x6064) - d.view().shaft_position(), shift) << "nothing redefined";
  EXPECT_GT(cycles_until(d, [&] { return (status(d) & (bit10 | bit13)) == (bit10 | bit13); }), 0)
      << "bit 10 with bit 13 once the shaft has stopped";
  EXPECT_EQ(d.view().velocity_micro_rpm(), 0);
}

TEST(homing_phase, the_drive_says_which_phase_of_its_method_runs) {
  virtual_drive d(standard_profile());
  write(d, 0x6098, 3);
  enable_in_mode(d, cia402::mode::homing);
  EXPECT_STREQ(cia402::motion::homing_phase_name(d.view().homing_phase()), "not started");
  write(d, 0x6040, 0x1F);
  std::vector<std::string> phases;
  for (int i = 0; i < 10000; ++i) {
    d.step();
    const std::string name = cia402::motion::homing_phase_name(d.view().homing_phase());
    if (phases.empty() || phases.back() != name) phases.push_back(name);
  }
  EXPECT_EQ(phases, (std::vector<std::string>{"searching home switch", "searching index pulse", "stopping past home",
                                              "moving to zero", "homing attained"}));
}

}  // namespace
