// A mode switch and control bit 4 on the virtual drive (docs/semantics.md S18, S19; issue 42): bit 4
// (new set-point in pp, homing operation start in hm) acts on its 0->1 edge seen while the mode is
// active. Entering a mode with bit 4 already 1 starts nothing and shows bit 12 = 0; the next edge
// acts. A mode switch never moves the axle by itself, between any two modes the drive offers. And a
// homing run that starts standing on the index pulse it looks for goes on to the next.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/words.hpp"
#include "mode_support.hpp"

namespace {

using namespace mode_test;
namespace mode = cia402::mode;

constexpr std::uint16_t enable = 0x0F, bit4 = 0x10;

bool homed(virtual_drive& d) { return (status(d) & (bit10 | bit12)) == (bit10 | bit12); }

// Issue 42, as python-canopen's BaseNode402.homing() leaves it: homed with method 37 to 1,234, the
// control word still 0x001F, then pp with 0x607A = 0.
TEST(mode_switch, pp_entered_with_bit_4_high_does_not_move_shows_no_bit_12_and_the_next_edge_moves) {
  virtual_drive d(standard_profile());
  write(d, 0x6098, 37);
  write(d, 0x607C, 1234);
  enable_in_mode(d, mode::homing);
  write(d, 0x6040, enable | bit4);
  ASSERT_GT(cycles_until(d, [&] { return homed(d); }, 10), 0);
  ASSERT_EQ(read(d, 0x6064), 1234);
  write(d, 0x607A, 0);
  write(d, 0x6060, mode::profile_position);
  for (int i = 0; i < 500; ++i) {
    d.step();
    ASSERT_EQ(read(d, 0x6061), mode::profile_position);
    ASSERT_EQ(status(d) & bit12, 0) << "no set-point acknowledge, cycle " << i;
    ASSERT_EQ(read(d, 0x6064), 1234) << "cycle " << i;
    ASSERT_EQ(d.view().velocity_micro_rpm(), 0);
  }
  write(d, 0x6040, enable);
  d.step();
  write(d, 0x6040, enable | bit4);  // the next 0->1 edge acts
  ASSERT_GT(cycles_until(d, [&] { return (status(d) & bit12) != 0; }, 10), 0);
  write(d, 0x6040, enable);
  ASSERT_GT(cycles_until(d, [&] { return (status(d) & (bit10 | bit12)) == bit10 && read(d, 0x6064) == 0; }, 5000), 0);
}

// The same for homing: from a pp move with bit 4 still 1, homing starts only on a new edge (method
// 37 would change 0x6064 without a move, 34 would move).
TEST(mode_switch, homing_entered_with_bit_4_high_does_not_start_and_the_next_edge_starts_it) {
  for (const int method : {37, 34}) {
    SCOPED_TRACE(method);
    virtual_drive d(standard_profile());
    write(d, 0x607C, 2500);
    enable_in_mode(d, mode::profile_position);
    write(d, 0x607A, 30000);
    write(d, 0x6040, enable | bit4);
    ASSERT_GT(cycles_until(d, [&] { return (status(d) & bit10) != 0 && read(d, 0x6064) == 30000; }, 5000), 0);
    write(d, 0x6098, method);
    write(d, 0x6060, mode::homing);
    for (int i = 0; i < 300; ++i) {
      d.step();
      ASSERT_EQ(status(d) & (bit12 | bit13), 0) << "not started, cycle " << i;
      ASSERT_EQ(read(d, 0x6064), 30000);
      ASSERT_EQ(d.view().velocity_micro_rpm(), 0);
      ASSERT_EQ(d.view().homing_phase(), cia402::motion::homing_phase::not_started);
    }
    write(d, 0x6040, enable);
    d.step();
    write(d, 0x6040, enable | bit4);
    ASSERT_GT(cycles_until(d, [&] { return homed(d); }, 20000), 0);
    EXPECT_EQ(read(d, 0x6064), 2500);
  }
}

// Bit 4 held through a disable and an enable is no new edge either: a stale 0x607A stays where it is.
TEST(mode_switch, bit_4_held_through_disable_operation_and_enable_starts_nothing) {
  virtual_drive d(standard_profile());
  enable_in_mode(d, mode::profile_position);
  write(d, 0x6040, enable | bit4);  // a move to 0x607A = 0, where it stands
  for (int i = 0; i < 20; ++i) d.step();
  write(d, 0x607A, 40000);
  write(d, 0x6040, 0x07 | bit4);  // disable operation (T5)
  for (int i = 0; i < 60; ++i) d.step();
  ASSERT_EQ(d.view().current(), state::switched_on);
  write(d, 0x6040, enable | bit4);  // T4, bit 4 still 1
  for (int i = 0; i < 300; ++i) {
    d.step();
    ASSERT_EQ(read(d, 0x6064), 0) << "cycle " << i;
  }
  ASSERT_EQ(d.view().current(), state::operation_enabled);
  EXPECT_EQ(status(d) & bit12, 0);
}

// Issue 42: method 34 with 0x607C = 2,500, run twice. The plant's pulses lie every revolution from
// 0, under the shaft at power-up: the first run goes on to 10,000, the second to 20,000.
TEST(homing_index, method_34_run_twice_moves_a_revolution_each_time_and_ends_on_the_next_pulse) {
  virtual_drive d(standard_profile());
  write(d, 0x6098, 34);
  write(d, 0x607C, 2500);
  enable_in_mode(d, mode::homing);
  for (const std::int64_t pulse : {10000, 20000}) {
    SCOPED_TRACE(pulse);
    write(d, 0x6040, enable | bit4);
    d.step();  // this cycle's status word still shows the run before
    std::int64_t farthest = d.view().shaft_position();
    ASSERT_GT(cycles_until(d, [&] {
      farthest = std::max(farthest, d.view().shaft_position());
      return homed(d);
    }, 20000), 0);
    EXPECT_EQ(d.view().shaft_position(), pulse) << "on the next pulse, a revolution on";
    EXPECT_GT(farthest, pulse) << "it stopped past the pulse and came back";
    EXPECT_EQ(read(d, 0x6064), 2500);
    EXPECT_EQ(status(d) & bit13, 0);
    write(d, 0x6040, enable);
    d.step();
  }
}

// Every pair of the modes 0x6502 announces, bit 4 held at 0 and at 1, from standstill in
// OPERATION ENABLED: the switch moves nothing, in pp and homing bit 12 stays 0 and nothing starts,
// and there the next 0->1 edge of bit 4 moves the axle. Each mode's set-point is one it would move
// to if it started: pp a 0x607A 30,000 increments away, homing method 34; the others hold theirs at
// standstill (0x60FF and 0x6071 at 0; csp follows 0x607A from its first cycle, so a master sets
// it to the position before the switch, as docs/modes.md says).
TEST(mode_switch, no_switch_between_any_two_modes_moves_the_axle_with_bit_4_high_or_low) {
  const int modes[] = {mode::profile_position, mode::profile_velocity, mode::profile_torque, mode::homing,
                       mode::cyclic_synchronous_position, mode::cyclic_synchronous_velocity,
                       mode::cyclic_synchronous_torque};
  int pairs = 0;
  for (const int from : modes) {
    for (const int to : modes) {
      if (from == to) continue;
      for (const bool high : {false, true}) {
        SCOPED_TRACE("from " + std::to_string(from) + " to " + std::to_string(to) + ", bit 4 " + (high ? "1" : "0"));
        virtual_drive d(standard_profile());
        write(d, 0x6098, 37);  // in homing as the first mode, bit 4 homes where it stands
        ASSERT_NO_FATAL_FAILURE(enable_in_mode(d, static_cast<std::int8_t>(from)));
        write(d, 0x6040, enable | (high ? bit4 : 0));
        for (int i = 0; i < 50; ++i) d.step();
        ASSERT_EQ(d.view().velocity_micro_rpm(), 0);
        const std::int64_t shaft = d.view().shaft_position();
        const std::int64_t reads = read(d, 0x6064);
        write(d, 0x607A, to == mode::cyclic_synchronous_position ? reads : reads + 30000);
        write(d, 0x6098, 34);
        write(d, 0x6060, to);
        for (int i = 0; i < 300; ++i) {
          d.step();
          ASSERT_EQ(read(d, 0x6061), to);
          ASSERT_EQ(d.view().shaft_position(), shaft) << "cycle " << i;
          ASSERT_EQ(d.view().velocity_micro_rpm(), 0) << "cycle " << i;
          ASSERT_EQ(read(d, 0x6064), reads) << "cycle " << i;
          if (to == mode::profile_position || to == mode::homing) {
            ASSERT_EQ(status(d) & (bit12 | bit13), 0) << "cycle " << i;
          }
        }
        if (to == mode::profile_position || to == mode::homing) {
          write(d, 0x6040, enable);
          d.step();
          write(d, 0x6040, enable | bit4);
          EXPECT_GT(cycles_until(d, [&] { return d.view().shaft_position() != shaft; }, 100), 0)
              << "the next edge acts";
        }
        ++pairs;
      }
    }
  }
  EXPECT_EQ(pairs, 7 * 6 * 2);
}

}  // namespace
