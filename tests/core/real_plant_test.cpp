// The defects a turning motor shows and an ideal plant hides (docs/semantics.md S4, S14..S16), each
// stepped cycle by cycle with the motor still moving (standstill = false) where it matters.
#include "test_support.hpp"

namespace cia402 {
namespace {

using S = state;
using test::bench;

// Enables the drive and starts a ramped fault reaction with the motor turning.
void ramping_fault_reaction(bench& b, std::uint16_t code, std::uint8_t error_class) {
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.standstill = false;
  b.in.fault_code = code;
  b.in.fault_class = error_class;
  b.step();
  ASSERT_EQ(b.out.current, S::fault_reaction_active) << test::describe(b.out);
  b.step();
  ASSERT_EQ(b.out.current, S::fault_reaction_active) << "the reaction ramps while the motor turns";
  ASSERT_TRUE(b.out.torque);
  ASSERT_TRUE(b.out.brake_released);
}

void expect_coast_now(bench& b, std::uint16_t code) {
  b.step();
  EXPECT_FALSE(b.out.torque) << "S4: torque off in the same step; " << test::describe(b.out);
  EXPECT_FALSE(b.out.brake_released) << "S4: the brake closes at once";
  EXPECT_EQ(b.out.current, S::fault) << "T14 follows the coast";
  EXPECT_EQ(b.out.error_code, code);
  for (int i = 0; i < 3; ++i) b.step();
  EXPECT_EQ(b.out.error_code, code) << "the outside cause still present does not write over it";
  EXPECT_FALSE(b.out.torque);
}

TEST(real_plant, lexium32_class_3_during_a_class_2_reaction_coasts_at_once) {
  bench b(test::builtin("lexium32"));
  ramping_fault_reaction(b, 0x5530, 2);
  b.in.fault_code = 0x7000;  // seed 001 T14: "Error of error classes 3 or 4"
  b.in.fault_class = 3;
  expect_coast_now(b, 0x7000);
}

// On every profile whose fault reaction ramps, `cause` during that ramp makes the drive coast at
// once with `code`. The PROFIBUS drives' reaction coasts anyway ("switched off immediately",
// 0x605E fixed at 0): they are left out.
void expect_coast_during_the_ramp(void (*cause)(bench&), std::uint16_t code) {
  for (const profile* p : test::all_builtins()) {
    SCOPED_TRACE(p->name);
    if (p->spec(option::fault_reaction).default_value == 0) continue;
    bench b(*p);
    ramping_fault_reaction(b, 0x5530, 2);
    cause(b);
    expect_coast_now(b, code);
  }
}

TEST(real_plant, dc_link_lost_during_a_ramped_fault_reaction_coasts_at_once_on_every_profile) {
  expect_coast_during_the_ramp([](bench& b) { b.in.dc_link = false; }, error_code::dc_link_undervoltage);
}

TEST(real_plant, sto_during_a_ramped_fault_reaction_coasts_at_once_on_every_profile) {
  expect_coast_during_the_ramp([](bench& b) { b.in.sto = true; }, error_code::safe_torque_off);
}

// S15: with the fieldbus in control a local enable is ignored, so a Shutdown held beside it never
// fights it; without the fieldbus the local request commands and the control word is ignored.
TEST(real_plant, lexium32_local_enable_beside_the_fieldbus_never_oscillates) {
  bench b(test::builtin("lexium32"));
  ASSERT_TRUE(test::reach(b, S::ready_to_switch_on));
  b.in.control_word = 0x0006;  // Shutdown
  b.in.local_enable = true;
  for (int i = 0; i < 20; ++i) b.step();
  EXPECT_TRUE(b.taken.size() == 3) << "only T0, T1, T2; no T3/T4/T8 cycle";
  EXPECT_EQ(b.a.current, S::ready_to_switch_on);
  b.in.remote = false;  // the local place takes control: T3, T4, then rest
  for (int i = 0; i < 20; ++i) b.step();
  EXPECT_EQ(b.a.current, S::operation_enabled);
  EXPECT_EQ(b.taken.size(), 5u);
  EXPECT_FALSE(b.out.status_word & status_bit::remote);
  b.in.local_disable = true;  // a local disable acts whatever place has control
  b.in.remote = true;
  b.in.control_word = 0x000F;
  b.settle();
  EXPECT_EQ(b.a.current, S::switch_on_disabled);
  for (int i = 0; i < 20; ++i) b.step();
  EXPECT_EQ(b.a.current, S::switch_on_disabled) << "the disable request holds the drive";
}

// Seed 001 T5: "Movement is canceled with Halt": the halt ramp of 0x605D, and the set-points go.
TEST(real_plant, lexium32_t5_stops_by_the_halt_ramp_and_cancels_the_movement) {
  bench b(test::builtin("lexium32"));
  ASSERT_EQ(b.write(0x605D, 3), sdo_abort::none);  // torque ramp (current limit)
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.standstill = false;
  b.in.control_word = 0x0007;  // Disable operation
  b.step();
  EXPECT_EQ(b.out.ramp, stop_ramp::current_limit) << test::describe(b.out);
  EXPECT_EQ(b.out.current, S::operation_enabled) << "S7: the source state until the stop ends";
  b.in.standstill = true;
  b.step();
  EXPECT_EQ(int(b.out.transition), 5);
  EXPECT_TRUE(b.out.clear_setpoints);
}

// T11 then T16 must not resume the cancelled movement.
TEST(real_plant, lexium32_quick_stop_clears_the_set_points) {
  bench b(test::builtin("lexium32"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.control_word = 0x000B;
  b.step();
  EXPECT_EQ(int(b.out.transition), 11);
  EXPECT_TRUE(b.out.clear_setpoints);
}

// S16: 0x605A is read when the quick stop starts.
TEST(real_plant, a_0x605a_write_during_the_quick_stop_waits_for_the_next_one) {
  bench b(test::builtin("cia402"));
  ASSERT_EQ(b.write(0x605A, 6), sdo_abort::none);
  ASSERT_TRUE(test::reach(b, S::quick_stop_active));
  b.in.standstill = false;
  b.step();
  EXPECT_EQ(b.out.ramp, stop_ramp::quick_stop);
  ASSERT_EQ(b.write(0x605A, 1), sdo_abort::none);
  b.step();
  EXPECT_EQ(b.out.ramp, stop_ramp::quick_stop) << "still the quick stop of code 6";
  b.in.standstill = true;
  for (int i = 0; i < 4; ++i) b.step();
  EXPECT_EQ(b.a.current, S::quick_stop_active) << "code 6 holds: no T12";
  std::int32_t value = 0;
  ASSERT_EQ(b.p.spec(option::quick_stop).exists(), true);
  ASSERT_EQ(read_option(b.p, b.a, 0x605A, value), sdo_abort::none);
  EXPECT_EQ(value, 1) << "the object reads what was written";
  b.in.control_word = 0x000F;  // T16, then a new quick stop runs by code 1
  b.step();
  b.in.control_word = 0x000B;
  b.settle();
  EXPECT_EQ(b.a.current, S::switch_on_disabled);
}

}  // namespace
}  // namespace cia402
