// How a run starts (docs/semantics.md S18, S19): control bit 4 acts on its 0->1 edge only, so a
// profile or a homing run taken over with bit 4 already 1 starts nothing until the next edge; and an
// index pulse is latched on its edge as the shaft moves across it, so a homing run started standing
// on the pulse it looks for does not take that one. The expected homes are worked out here (33, 34)
// or are the ones homing_test.cpp checks against CiA 402-2's figures (1..14, from elsewhere).
#include <gtest/gtest.h>

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "cia402/motion/homing.hpp"
#include "cia402/motion/trajectory.hpp"
#include "homing_support.hpp"

namespace cia402::motion {
namespace {

using namespace test;  // homing_support.hpp

// --- bit 4's edge ---------------------------------------------------------------------------------

TEST(pp_bit_4, a_profile_taken_over_with_bit_4_high_offers_nothing_until_its_next_edge) {
  // Issue 42: homed to 1,234, then pp with 0x607A = 0 and bit 4 still 1 from homing.
  profile_position pp;
  shaft s;
  s.position = 1234;
  pp.reset(s, true);
  const pp_parameters par;
  pp_command cmd;
  cmd.new_setpoint = true;
  cmd.target = 0;
  for (int c = 0; c < 200; ++c) {
    const pp_status st = pp.step(cmd, par, cycle_us);
    ASSERT_FALSE(st.setpoint_acknowledge) << "bit 12 at cycle " << c;
    ASSERT_EQ(pp.state().position, 1234);
    ASSERT_EQ(pp.state().velocity, 0);
  }
  EXPECT_FALSE(pp.has_target());
  cmd.new_setpoint = false;
  pp.step(cmd, par, cycle_us);
  cmd.new_setpoint = true;  // the next 0->1 edge acts
  EXPECT_TRUE(pp.step(cmd, par, cycle_us).setpoint_acknowledge);
  ASSERT_TRUE(pp.has_target());
  EXPECT_EQ(pp.target(), 0);
  cmd.new_setpoint = false;
  pp_status st;
  for (int c = 0; c < 5000 && !st.target_reached; ++c) st = pp.step(cmd, par, cycle_us);
  EXPECT_TRUE(st.target_reached);
  EXPECT_EQ(pp.state().position, 0);
}

TEST(homing_bit_4, a_run_reset_with_bit_4_high_starts_nothing_until_its_next_edge) {
  for (const int method : {34, 37, 3}) {
    SCOPED_TRACE(method);
    homing h;
    homing_parameters par;
    par.method = static_cast<std::int8_t>(method);
    par.home_offset = 2500;
    const homing_machine m;
    shaft s;
    s.position = 1234;
    std::int64_t offset = 0;
    h.reset(true);
    for (int c = 0; c < 200; ++c) {
      const homing_status st = h.step(true, par, m, s, offset, cycle_us);
      ASSERT_FALSE(st.attained || st.error);
      ASSERT_EQ(h.phase(), homing_phase::not_started);
      ASSERT_EQ(s.position, 1234);
      ASSERT_EQ(offset, 0) << "0x6064 unchanged";
    }
    h.step(false, par, m, s, offset, cycle_us);
    homing_status st;
    for (int c = 0; c < 20000 && !(st.attained && st.target_reached); ++c) st = h.step(true, par, m, s, offset, cycle_us);
    EXPECT_TRUE(st.attained && st.target_reached) << "the next edge starts the run";
    EXPECT_EQ(s.position + offset, 2500);
  }
}

TEST(homing_bit_4, stand_by_interrupts_a_run_bit_4_held_through_it_is_no_edge_a_new_one_waits) {
  homing h;
  homing_parameters par;
  par.method = 34;
  const homing_machine m;
  shaft s;
  s.position = 1234;
  std::int64_t offset = 0;
  h.step(false, par, m, s, offset, cycle_us);
  for (int c = 0; c < 50; ++c) h.step(true, par, m, s, offset, cycle_us);
  ASSERT_TRUE(h.running());
  h.stand_by(true);  // a stop: no motion this cycle, bit 4 still 1
  EXPECT_EQ(h.phase(), homing_phase::interrupted);
  h.step(true, par, m, s, offset, cycle_us);
  EXPECT_EQ(h.phase(), homing_phase::interrupted) << "no edge: no new run";
  h.step(false, par, m, s, offset, cycle_us);
  h.step(true, par, m, s, offset, cycle_us);
  EXPECT_TRUE(h.running()) << "a new edge starts it again";
  h.stand_by(false);  // stopped again; bit 4 falls and rises while nothing moves (a brake releasing)
  h.stand_by(true);
  EXPECT_EQ(h.phase(), homing_phase::interrupted);
  h.step(true, par, m, s, offset, cycle_us);
  EXPECT_TRUE(h.running()) << "that edge waited for the first cycle the mode moves";
}

// --- the index pulse under the shaft --------------------------------------------------------------

TEST(homing_index, method_34_run_twice_goes_on_one_revolution_to_the_next_pulse) {
  // Issue 42: 0x607C = 2,500; the second run starts standing on the pulse the first found.
  const homing_machine m;  // index pulses every revolution from 0
  const homing_run first = home(34, m, 1234, 2500);
  ASSERT_TRUE(first.status.attained && first.status.target_reached);
  EXPECT_EQ(first.s.position, 10000);
  EXPECT_EQ(first.s.position + first.offset, 2500);
  const homing_run second = home(34, m, first.s.position, 2500, first.offset);
  ASSERT_TRUE(second.status.attained && second.status.target_reached);
  EXPECT_EQ(second.s.position, 20000) << "one revolution on, not the pulse it stood on";
  EXPECT_EQ(second.s.position + second.offset, 2500) << "the new home reads as 0x607C";
  EXPECT_EQ(second.offset, first.offset - revolution);
  ASSERT_TRUE(second.latched);
  EXPECT_LT(second.latch_from, 20000);
  EXPECT_GE(second.latch_to, 20000) << "latched moving across it";
  // And 33 the mirror image: from the pulse at 0, the one at -10,000.
  const homing_run down = home(33, m, 0, 2500);
  ASSERT_TRUE(down.status.attained && down.status.target_reached);
  EXPECT_EQ(down.s.position, -10000);
}

TEST(homing_index, a_shaft_a_fraction_above_a_pulse_still_crosses_it_going_down) {
  const homing_machine m;
  shaft start;
  start.position = 10000;
  start.fraction = shaft::fraction_unit / 2;  // 10,000.5 increments
  const homing_run r = home(33, m, start, 0, 0, 20000);
  ASSERT_TRUE(r.status.attained && r.status.target_reached);
  EXPECT_EQ(r.s.position, 10000);
  EXPECT_EQ(r.s.fraction, 0);
}

// The machines are homing_test.cpp's (homing_support.hpp).
struct index_case {
  int method;
  const homing_machine* machine;
};

std::vector<index_case> every_index_method() {
  std::vector<index_case> cases{{1, &cam}, {2, &cam}, {3, &positive_home_switch}, {4, &positive_home_switch},
                                {5, &negative_home_switch}, {6, &negative_home_switch}};
  for (int method = 7; method <= 14; ++method) cases.push_back({method, &cam});
  cases.push_back({33, &cam});
  cases.push_back({34, &cam});
  return cases;
}

void PrintTo(const index_case& c, std::ostream* os) { *os << "method " << c.method; }

class every_index_method_test : public ::testing::TestWithParam<index_case> {};

// From standing exactly on the pulse home is at, on its neighbours and on the first pulse: the run
// ends on an index pulse it latched moving across it, never on one it stood on without moving. 1..14
// search their pulse after an edge, so they find the home they find from elsewhere (from 0, which
// homing_test.cpp checks against the figure); 33 and 34 the next pulse beyond the start.
TEST_P(every_index_method_test, a_start_standing_on_a_pulse_takes_only_a_pulse_it_moves_across) {
  const index_case c = GetParam();
  const homing_machine& m = *c.machine;
  const homing_run reference = home(c.method, m, 0, 777);
  ASSERT_TRUE(reference.status.attained && reference.status.target_reached);
  const std::int64_t pulse_home = reference.s.position;
  ASSERT_EQ(floor_div(pulse_home - m.index_at, revolution) * revolution, pulse_home - m.index_at);
  for (const std::int64_t start : {pulse_home, pulse_home - revolution, pulse_home + revolution, m.index_at}) {
    SCOPED_TRACE("method " + std::to_string(c.method) + " standing on the pulse at " + std::to_string(start));
    const std::int64_t expected = c.method == 33   ? start - revolution
                                  : c.method == 34 ? start + revolution
                                                   : pulse_home;
    const homing_run r = home(c.method, m, start, 777);
    ASSERT_FALSE(r.status.error);
    ASSERT_TRUE(r.status.attained && r.status.target_reached);
    EXPECT_EQ(r.s.position, expected);
    EXPECT_EQ(r.s.position + r.offset, 777);
    // The cycle that ended the search moved the shaft across home (or onto it), at speed.
    ASSERT_TRUE(r.latched);
    const std::int64_t way = r.latch_to > r.latch_from ? 1 : r.latch_to < r.latch_from ? -1 : 0;
    EXPECT_NE(way, 0) << "found home without moving";
    EXPECT_NE(r.latch_velocity, 0);
    EXPECT_GT((expected - r.latch_from) * way, 0) << "home lay ahead at the start of that cycle";
    EXPECT_GE((r.latch_to - expected) * way, 0) << "and was reached in it";
  }
}

INSTANTIATE_TEST_SUITE_P(homing_index, every_index_method_test, ::testing::ValuesIn(every_index_method()),
                         [](const ::testing::TestParamInfo<index_case>& i) {
                           return "method_" + std::to_string(i.param.method);
                         });

}  // namespace
}  // namespace cia402::motion
