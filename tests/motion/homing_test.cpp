// Homing on a machine whose switches and index pulses are places on the shaft: every method of
// 0x60E3 ends at the home CiA 402-2's figure for it names (the edge it measures from, the side of it
// the home lies on), from every kind of starting place, and a second run from that home ends where
// the first did (33 and 34: on the next pulse, since the one under the standing shaft is not
// latched, docs/semantics.md S19). The expected homes are worked out here from the figures, never
// by the code under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstdint>
#include <string>
#include <vector>

#include "cia402/motion/homing.hpp"
#include "homing_support.hpp"

namespace cia402::motion {
namespace {

using namespace test;  // homing_support.hpp

constexpr std::int64_t home_offset = 777;

// The first index pulse at or above / at or below a position, and strictly above / below it.
std::int64_t pulse_at_or_above(const homing_machine& m, std::int64_t at) {
  return m.index_at + (floor_div(at - m.index_at - 1, revolution) + 1) * revolution;
}
std::int64_t pulse_at_or_below(const homing_machine& m, std::int64_t at) {
  return m.index_at + floor_div(at - m.index_at, revolution) * revolution;
}
std::int64_t pulse_above(const homing_machine& m, std::int64_t at) { return pulse_at_or_above(m, at + 1); }
std::int64_t pulse_below(const homing_machine& m, std::int64_t at) { return pulse_at_or_below(m, at - 1); }

// CiA 402-2's figure for a method: which edge home is measured from and on which side of it home
// lies (+1 right, -1 left). The edge is the first position in the switch's new state as the drive
// crosses it on its way to that side.
struct figure {
  std::int64_t edge;
  int side;
};
figure figure_of(int method, const homing_machine& m) {
  const int base = method > 16 ? method - 16 : method;
  const std::int64_t lower = m.home_switch_low, upper = m.home_switch_high;
  switch (base) {
    case 1: return {m.negative_limit, +1};  // right of the negative limit switch
    case 2: return {m.positive_limit, -1};  // left of the positive limit switch
    case 3: case 7: case 14: return {lower - 1, -1};  // left of the lower edge
    case 4: case 8: case 13: return {lower, +1};      // right of the lower edge
    case 6: case 9: case 12: return {upper, -1};      // left of the upper edge
    case 5: case 10: case 11: return {upper + 1, +1};  // right of the upper edge
    default: ADD_FAILURE() << "no figure for method " << method; return {0, 0};
  }
}

std::int64_t expected_home(int method, const homing_machine& m, std::int64_t start) {
  if (method == 35 || method == 37) return start;
  // 33 / 34 from a shaft standing at `start`: a pulse under it is not latched (no edge), the next is.
  if (method == 33) return pulse_below(m, start);
  if (method == 34) return pulse_above(m, start);
  const figure f = figure_of(method, m);
  if (method >= 17) return f.edge;  // no index pulse: the edge itself
  return f.side > 0 ? pulse_at_or_above(m, f.edge) : pulse_at_or_below(m, f.edge);
}

struct homing_case {
  int method;
  const homing_machine* machine;
  std::vector<std::int64_t> starts;
};

std::vector<homing_case> every_method() {
  std::vector<homing_case> cases;
  for (int offset : {0, 16}) {
    cases.push_back({1 + offset, &cam, {0, 120000, -250000}});         // -250,000: on the limit switch
    cases.push_back({2 + offset, &cam, {0, 120000, 350000}});
    for (int method : {3, 4}) cases.push_back({method + offset, &positive_home_switch, {0, 49999, 50000, 120000}});
    for (int method : {5, 6}) cases.push_back({method + offset, &negative_home_switch, {0, 50000, 50001, 120000}});
    for (int method = 7; method <= 14; ++method) {
      cases.push_back({method + offset, &cam, {0, 49999, 50000, 65000, 80000, 80001, 150000}});
    }
  }
  for (int method : {33, 34, 35, 37}) cases.push_back({method, &cam, {0, 3000, 12345, -7777}});
  return cases;
}

TEST(homing, every_method_of_0x60E3_homes_where_its_figure_says_and_again_there_from_its_home) {
  std::vector<int> covered;
  for (const homing_case& c : every_method()) {
    covered.push_back(c.method);
    for (const std::int64_t start : c.starts) {
      SCOPED_TRACE("method " + std::to_string(c.method) + " from " + std::to_string(start));
      const std::int64_t home_at = expected_home(c.method, *c.machine, start);
      const homing_run first = home(c.method, *c.machine, start, home_offset);
      ASSERT_FALSE(first.status.error);
      ASSERT_TRUE(first.status.attained && first.status.target_reached) << "not done in " << first.cycles;
      EXPECT_EQ(first.s.position, home_at) << "the shaft stands at home";
      EXPECT_EQ(first.s.velocity, 0);
      EXPECT_EQ(first.s.position + first.offset, home_offset) << "home reads as 0x607C";
      // Again, from home: the switches and pulses have not moved, so neither does home (33 and 34
      // go on to the next pulse: the one under the standing shaft is not latched).
      const homing_run second = home(c.method, *c.machine, first.s.position, home_offset, first.offset);
      ASSERT_FALSE(second.status.error);
      ASSERT_TRUE(second.status.attained && second.status.target_reached);
      const std::int64_t again_at = expected_home(c.method, *c.machine, first.s.position);
      EXPECT_EQ(second.s.position, again_at);
      EXPECT_EQ(second.s.position + second.offset, home_offset);
      if (c.method != 33 && c.method != 34) {
        EXPECT_EQ(second.s.position, first.s.position);
        EXPECT_EQ(second.offset, first.offset);
      }
    }
  }
  // Every method the drive announces, no more.
  std::vector<int> supported;
  for (int m = -128; m <= 127; ++m) {
    if (homing::supports(m)) supported.push_back(m);
  }
  std::sort(covered.begin(), covered.end());
  EXPECT_EQ(covered, supported);
}

TEST(homing, a_default_method_3_run_ends_within_two_seconds) {
  // The plant's defaults: a home switch from 5 revolutions up, index pulses from 0, 0x6099 and
  // 0x609A as homing_parameters has them.
  homing_machine m;
  const homing_run r = home(3, m, 0, home_offset);
  ASSERT_TRUE(r.status.attained && r.status.target_reached);
  EXPECT_EQ(r.s.position, 40000);
  EXPECT_LT(r.cycles, 2000);
}

TEST(homing, a_limit_switch_where_the_method_expects_none_is_a_homing_error) {
  // 3 expects its home switch to reach to the positive end: right of a cam it runs into the
  // positive limit switch. 5 expects one from the negative end. 33 finds no pulse before the
  // limit switch it starts beyond.
  struct bad_case {
    int method;
    const homing_machine* machine;
    std::int64_t start;
  };
  homing_machine no_pulse_room = cam;
  no_pulse_room.negative_limit = -5000;  // the pulse below 0 lies at -7,000, beyond it
  for (const bad_case& c : {bad_case{3, &cam, 150000}, bad_case{19, &cam, 150000}, bad_case{4, &cam, 150000},
                            bad_case{5, &positive_home_switch, 0}, bad_case{6, &positive_home_switch, 0},
                            bad_case{33, &no_pulse_room, 0}}) {
    SCOPED_TRACE(c.method);
    const homing_run r = home(c.method, *c.machine, c.start, home_offset);
    ASSERT_TRUE(r.status.error);
    EXPECT_FALSE(r.status.attained);
    EXPECT_EQ(r.offset, 0) << "nothing redefined";
  }
}

TEST(homing, a_switch_the_machine_lacks_is_searched_for_1000_revolutions_then_a_homing_error) {
  homing_machine bare;  // no limit switches, no home switch
  bare.home_switch_low = homing_machine::none_above;
  bare.home_switch_high = homing_machine::none_below;
  homing_machine endless = bare;  // a home switch from 50,000 to the positive end, nothing else
  endless.home_switch_low = 50000;
  endless.home_switch_high = homing_machine::none_above;
  struct lacking {
    int method;
    const homing_machine* machine;
  };
  for (const lacking c : {lacking{1, &bare}, lacking{2, &bare}, lacking{17, &bare}, lacking{18, &bare},
                          lacking{3, &bare}, lacking{19, &bare}, lacking{14, &bare}, lacking{30, &bare},
                          lacking{10, &endless}, lacking{26, &endless}, lacking{11, &endless}, lacking{5, &endless}}) {
    SCOPED_TRACE(c.method);
    const homing_run r = home(c.method, *c.machine, 0, home_offset, 0, 2000000);
    ASSERT_TRUE(r.status.error);
    EXPECT_LE(std::llabs(r.s.position), (homing::max_search_revolutions + 10) * revolution);
    EXPECT_EQ(r.offset, 0);
  }
}

TEST(homing, after_an_error_the_shaft_stops_and_bit_10_says_so) {
  homing h;
  homing_parameters par;
  par.method = 3;
  shaft s;
  s.position = 150000;
  std::int64_t offset = 0;
  homing_status st;
  h.step(false, par, cam, s, offset, cycle_us);
  long cycles = 0;
  do {
    st = h.step(true, par, cam, s, offset, cycle_us);
  } while (!st.error && ++cycles < 100000);
  ASSERT_TRUE(st.error);
  EXPECT_FALSE(st.target_reached) << "still moving: 1/0/0";
  while (s.velocity != 0 && ++cycles < 100000) st = h.step(true, par, cam, s, offset, cycle_us);
  st = h.step(true, par, cam, s, offset, cycle_us);
  EXPECT_TRUE(st.error && st.target_reached) << "at rest: 1/0/1";
  EXPECT_EQ(h.phase(), homing_phase::error);
}

TEST(homing, the_phases_of_method_3_in_order_with_their_names) {
  homing h;
  homing_parameters par;
  par.method = 3;
  homing_machine m;
  shaft s;
  std::int64_t offset = 0;
  EXPECT_EQ(h.phase(), homing_phase::not_started);
  h.step(false, par, m, s, offset, cycle_us);
  std::vector<homing_phase> seen{h.phase()};
  for (int i = 0; i < 10000 && h.phase() != homing_phase::attained; ++i) {
    h.step(true, par, m, s, offset, cycle_us);
    if (h.phase() != seen.back()) seen.push_back(h.phase());
  }
  const std::vector<homing_phase> expected = {homing_phase::not_started, homing_phase::searching_home_switch,
                                              homing_phase::searching_index_pulse, homing_phase::stopping_past_home,
                                              homing_phase::moving_to_zero, homing_phase::attained};
  EXPECT_EQ(seen, expected);
  std::vector<std::string> names;
  for (const homing_phase p : seen) names.emplace_back(homing_phase_name(p));
  EXPECT_EQ(names, (std::vector<std::string>{"not started", "searching home switch", "searching index pulse",
                                             "stopping past home", "moving to zero", "homing attained"}));
  // Bit 4 falls during a run: interrupted.
  h.reset();
  h.step(true, par, m, s, offset, cycle_us);
  h.step(false, par, m, s, offset, cycle_us);
  EXPECT_EQ(h.phase(), homing_phase::interrupted);
  EXPECT_STREQ(homing_phase_name(homing_phase::searching_limit_switch), "searching limit switch");
}

TEST(homing, the_speeds_are_cut_to_the_speed_limit_and_say_so) {
  homing h;
  homing_parameters par;
  par.method = 34;
  homing_machine m;
  m.index_at = 5000;
  shaft s;
  std::int64_t offset = 0;
  h.step(false, par, m, s, offset, cycle_us, 60);
  homing_status st;
  std::int64_t fastest = 0;
  for (int i = 0; i < 20000 && !(st.attained && st.target_reached); ++i) {
    st = h.step(true, par, m, s, offset, cycle_us, 60);
    fastest = std::max(fastest, s.velocity);
    if (h.running() && s.velocity > 0) {
      EXPECT_TRUE(st.limited);
    }
  }
  EXPECT_EQ(fastest, 60'000'000) << "0x6099 sub 2 (100 rpm) cut to 60 rpm";
  EXPECT_EQ(s.position, 5000);
}

TEST(homing_machine, an_index_pulse_is_seen_in_the_cycle_the_shaft_reaches_it_or_while_it_stands_on_it) {
  homing_machine m;
  m.index_at = 3000;
  EXPECT_TRUE(m.index_pulse_between(2990, 3010, 10000));
  EXPECT_TRUE(m.index_pulse_between(3010, 2990, 10000)) << "either direction";
  EXPECT_TRUE(m.index_pulse_between(3000, 3000, 10000)) << "standing on it";
  EXPECT_TRUE(m.index_pulse_between(-7000, -7000, 10000));
  EXPECT_FALSE(m.index_pulse_between(3001, 12999, 10000));
  EXPECT_FALSE(m.index_pulse_between(-6999, 2999, 10000));
  EXPECT_TRUE(m.index_pulse_between(-6999, 3000, 10000));
  EXPECT_FALSE(m.index_pulse_between(3000, 3100, 10000)) << "counted in the cycle that reached it";
  EXPECT_FALSE(m.index_pulse_between(3000, 2900, 10000));
  EXPECT_TRUE(m.index_pulse_between(3100, 3000, 10000));
}

}  // namespace
}  // namespace cia402::motion
