// What the seeds say beyond where each row goes (profile_rows_test.cpp pins that): which transition
// numbers each seed prints and which states a profile can reach; how T8/T9 stop and brake on the
// CANopen drive of seed 000, the PROFIBUS drives' torque in SWITCHED ON, their fast stop and T17, and
// the Lexium 32's error classes (each test cites its seed's words).
#include <algorithm>
#include <cstdint>
#include <set>
#include <vector>

#include "test_support.hpp"

namespace cia402 {
namespace {

using test::bench;
using test::words_for;
using S = state;

void fault_class(bench& b, std::uint8_t cls) {
  b.in.fault_code = 0x5530;  // any fault: the class decides
  b.in.fault_class = cls;
}

// A Fault Reset edge: a step with control word 0x00, then one with bit 7 set (0x80).
void send_fault_reset(bench& b) {
  b.in.control_word = 0x00;
  b.step();
  b.in.control_word = 0x80;
  b.step();
}

// 000_44b471b7401b86be.txt T9: "Power output stage is immediately disabled and the motor coasts.
// If available, the motor holding brake is closed immediately."
TEST(profile_rows, no_quick_stop_t9_coasts_and_closes_the_brake_in_the_same_step) {
  bench b(test::builtin("no-quick-stop"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  EXPECT_TRUE(b.out.torque);
  EXPECT_TRUE(b.out.brake_released);
  b.in.standstill = false;  // still turning
  b.in.control_word = 0x02;  // Quick stop acts as Disable voltage here
  b.step();
  EXPECT_EQ(int(b.out.transition), 9);
  EXPECT_EQ(b.out.current, S::switch_on_disabled);
  EXPECT_FALSE(b.out.torque);
  EXPECT_FALSE(b.out.brake_released);
}

// 000_44b471b7401b86be.txt T5/T8: "decelerated to standstill with the deceleration ramp ... In the
// detected standstill, the motor holding brake is closed and the power output stage is disabled."
TEST(profile_rows, no_quick_stop_t8_ramps_to_standstill_then_closes_brake_then_disables) {
  bench b(test::builtin("no-quick-stop"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.standstill = false;
  b.in.brake_engaged = false;
  b.in.control_word = 0x06;
  for (int i = 0; i < 3; ++i) {
    b.step();
    EXPECT_EQ(b.out.current, S::operation_enabled) << "still decelerating";
    EXPECT_EQ(b.out.ramp, stop_ramp::slow_down);
    EXPECT_TRUE(b.out.torque);
    EXPECT_TRUE(b.out.brake_released);
  }
  b.in.standstill = true;  // detected standstill: the brake must close, torque still on
  b.step();
  EXPECT_EQ(b.out.current, S::operation_enabled);
  EXPECT_TRUE(b.out.torque);
  EXPECT_FALSE(b.out.brake_released);
  b.in.brake_engaged = true;  // brake closed: now the power stage goes
  b.step();
  EXPECT_EQ(int(b.out.transition), 8);
  EXPECT_EQ(b.out.current, S::ready_to_switch_on);
  EXPECT_FALSE(b.out.torque);
}

// The PROFIBUS drives of seeds 003 and 004, each on a bench of its own brought to `s`, then `check`.
template <typename Check>
void on_each_profibus_drive_in(S s, Check check) {
  for (const char* name : {"s300-profibus", "ax2000-profibus"}) {
    SCOPED_TRACE(name);
    bench b(test::builtin(name));
    ASSERT_TRUE(test::reach(b, s));
    check(b);
  }
}

// 003_83442f2f4b0b2bb9.txt T3: "Output stage is switched on (enabled). Drive has torque." T6:
// "Output stage is switched off (disabled). Drive has no torque." 004 likewise ("Motor has torque").
TEST(profile_rows, profibus_switched_on_has_torque_and_t6_removes_it) {
  on_each_profibus_drive_in(S::switched_on, [](bench& b) {
    EXPECT_EQ(int(b.out.transition), 3);
    EXPECT_TRUE(b.out.torque);
    b.in.control_word = words_for(b.p).shutdown;
    b.step();
    EXPECT_EQ(int(b.out.transition), 6);
    EXPECT_FALSE(b.out.torque);
  });
}

// 003 / 004 T11: "The output stage remains enabled. Setpoints are canceled."
TEST(profile_rows, profibus_fast_stop_keeps_the_output_stage_and_cancels_setpoints) {
  on_each_profibus_drive_in(S::operation_enabled, [](bench& b) {
    b.in.standstill = false;
    b.in.control_word = words_for(b.p).quick_stop;
    b.step();
    EXPECT_EQ(int(b.out.transition), 11);
    EXPECT_TRUE(b.out.torque);
    EXPECT_TRUE(b.out.clear_setpoints);
    EXPECT_EQ(b.out.ramp, stop_ramp::quick_stop) << "the emergency ramp";
  });
}

// 004_e07fd68605b3a8c6.txt T17: "Switch-on inhibited, output stage disabled".
TEST(profile_rows, ax2000_t17_ends_with_the_output_stage_disabled) {
  bench b(test::builtin("ax2000-profibus"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.control_word = 0x1B;
  ASSERT_EQ(int(b.step_until_transition(4)), 17);
  EXPECT_EQ(b.out.current, S::switch_on_disabled);
  EXPECT_FALSE(b.out.torque);
  EXPECT_FALSE(b.out.brake_released);
}

// 001_f9323c8e43dc977c.txt T14: "Error response terminated (error class 2)" but "Error of error
// classes 3 or 4" at once: class 3 reaches FAULT while the motor still turns; class 2 waits.
TEST(profile_rows, lexium32_class_3_reaches_fault_at_once_class_2_after_its_stop) {
  for (std::uint8_t cls : {std::uint8_t{2}, std::uint8_t{3}}) {
    SCOPED_TRACE(int(cls));
    bench b(test::builtin("lexium32"));
    ASSERT_TRUE(test::reach(b, S::operation_enabled));
    b.in.standstill = false;
    b.in.brake_engaged = false;
    fault_class(b, cls);
    b.step();
    EXPECT_EQ(int(b.out.transition), 13);
    b.step();
    if (cls == 3) {
      EXPECT_EQ(int(b.out.transition), 14);
      EXPECT_FALSE(b.out.torque);
    } else {
      EXPECT_EQ(b.out.current, S::fault_reaction_active) << "class 2 stops on a ramp first";
      EXPECT_TRUE(b.out.torque);
      b.in.standstill = true;
      b.in.brake_engaged = true;
      EXPECT_EQ(int(b.step_until_transition(3)), 14);
    }
  }
}

// From OPERATION ENABLED, a fault of class `cls` until the drive stands in FAULT, the cause
// corrected, then one Fault Reset edge.
void fault_corrected_then_reset(bench& b, std::uint8_t cls) {
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  fault_class(b, cls);
  b.settle();
  ASSERT_EQ(b.a.current, S::fault);
  b.in.fault_code = 0;  // the cause is corrected
  send_fault_reset(b);
}

// Lexium 32 eSM table (cia402-reference.md §6.3): class 4 is reset by a power cycle only.
TEST(profile_rows, lexium32_class_4_needs_a_power_cycle) {
  const profile& p = test::builtin("lexium32");
  bench b(p);
  ASSERT_NO_FATAL_FAILURE(fault_corrected_then_reset(b, 4));
  EXPECT_EQ(b.out.current, S::fault) << "Fault Reset does not clear a class-4 error";
  send_fault_reset(b);
  EXPECT_EQ(b.out.current, S::fault);
  // Power cycle: a new axis.
  bench fresh(p);
  fresh.in.control_word = 0x00;
  EXPECT_EQ(fresh.settle(), (std::vector<std::uint8_t>{0, 1}));
  EXPECT_EQ(fresh.a.current, S::switch_on_disabled);
}

// The same fault with class 2: Fault Reset clears it (T15), the comparison case for class 4.
TEST(profile_rows, lexium32_class_2_is_cleared_by_fault_reset) {
  bench b(test::builtin("lexium32"));
  ASSERT_NO_FATAL_FAILURE(fault_corrected_then_reset(b, 2));
  EXPECT_EQ(int(b.out.transition), 15);
  EXPECT_EQ(b.out.current, S::switch_on_disabled);
}

// Lexium 32 eSM: class 0 and class 1 are warnings, not faults (status bit 7).
TEST(profile_rows, lexium32_class_0_error_raises_the_warning_bit_only) {
  bench b(test::builtin("lexium32"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  fault_class(b, 0);
  b.step();
  EXPECT_EQ(b.out.current, S::operation_enabled);
  EXPECT_TRUE(b.out.status_word & status_bit::warning);
  EXPECT_TRUE(b.out.torque);
}

TEST(profile_rows, no_quick_stop_never_enters_quick_stop_active) {
  // 000_44b471b7401b86be.txt: "'Quick Stop' is not supported".
  EXPECT_FALSE(test::reachable_states(test::builtin("no-quick-stop")) & state_bit(S::quick_stop_active));
  for (const char* name : {"cia402", "lexium32", "s300-profibus", "ax2000-profibus"}) {
    EXPECT_TRUE(test::reachable_states(test::builtin(name)) & state_bit(S::quick_stop_active)) << name;
  }
}

// Row numbers are exactly the seed's: each row's number is one the seed prints as supported, and
// each such transition has at least one row (000 has no 11, 12, 16; 003 no 17; only 004 has 17).
TEST(profile_rows, every_profile_has_exactly_its_seeds_transition_numbers) {
  for (const profile* p : test::all_builtins()) {
    const std::vector<int> seed = test::seed_transitions(*p);
    std::set<int> in_rows;
    for (std::size_t i = 0; i < p->row_count; ++i) {
      const int n = p->row(i).number;
      in_rows.insert(n);
      EXPECT_NE(std::find(seed.begin(), seed.end(), n), seed.end())
          << p->name << " row " << i << " is T" << n << ", which seed " << p->seed
          << " does not print";
    }
    for (int n : seed) {
      EXPECT_TRUE(in_rows.count(n)) << p->name << " has no row for T" << n << " of seed " << p->seed;
    }
  }
}

TEST(profile_rows, seed_lists_match_the_seeds_read_by_hand) {
  // 000 lacks 11, 12, 16; 003 lacks 17; only 004 has 17.
  auto has = [](const char* name, int n) {
    const std::vector<int> t = test::seed_transitions(test::builtin(name));
    return std::find(t.begin(), t.end(), n) != t.end();
  };
  EXPECT_FALSE(has("no-quick-stop", 11));
  EXPECT_FALSE(has("no-quick-stop", 12));
  EXPECT_FALSE(has("no-quick-stop", 16));
  EXPECT_TRUE(has("no-quick-stop", 15));
  EXPECT_FALSE(has("s300-profibus", 17));
  EXPECT_TRUE(has("s300-profibus", 16));
  EXPECT_FALSE(has("cia402", 17));
  EXPECT_FALSE(has("lexium32", 17));
  EXPECT_TRUE(has("ax2000-profibus", 17));
  EXPECT_EQ(builtin_profile_count(), 5u);
}

}  // namespace
}  // namespace cia402
