// Helpers for the simulator tests: bring a virtual drive to OPERATION ENABLED with the profile's own
// command words, run it up to speed, step until something happens.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>

#include "cia402/master.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace sim_test {

using namespace cia402;
using namespace cia402::sim;

inline constexpr std::int64_t micro = 1000000;

inline std::uint16_t word_for(const profile& p, command c, std::uint16_t keep = 0) {
  std::uint16_t w = 0;
  EXPECT_TRUE(encode_command(p, c, keep, w)) << p.name << ": no word for " << command_name(c);
  return w;
}

/// Writes the control word and steps `cycles` times.
inline void command_for(virtual_drive& d, std::uint16_t word, int cycles) {
  EXPECT_EQ(d.write(0x6040, 0, word), sdo_abort::none);
  for (int i = 0; i < cycles; ++i) d.step();
}

/// Steps until `done` holds (checked after each step); returns the cycles taken, or -1.
inline long step_until(virtual_drive& d, const std::function<bool(const drive_outputs&)>& done,
                       long max_cycles = 100000) {
  for (long i = 1; i <= max_cycles; ++i) {
    if (done(d.step())) return i;
  }
  return -1;
}

/// Power-up, Shutdown, Switch on, Enable operation: OPERATION ENABLED, by the profile's own words.
inline void enable(virtual_drive& d) {
  const profile& p = d.view().table();
  command_for(d, word_for(p, command::shutdown), 5);
  command_for(d, word_for(p, command::switch_on), 3);
  command_for(d, word_for(p, command::enable_operation), 3);
  ASSERT_EQ(d.view().current(), state::operation_enabled) << p.name;
}

/// Enabled and turning at `rpm` (0x60FF written after T4, which clears set-points).
inline void run_at(virtual_drive& d, std::int32_t rpm) {
  enable(d);
  ASSERT_EQ(d.write(0x60FF, 0, rpm), sdo_abort::none);
  const long n = step_until(d, [&](const drive_outputs&) {
    return d.view().velocity_micro_rpm() == std::int64_t{rpm} * micro;
  });
  ASSERT_GT(n, 0) << d.view().table().name << ": never reached " << rpm << " rpm";
}

}  // namespace sim_test
