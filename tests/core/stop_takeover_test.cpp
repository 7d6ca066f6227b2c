// Behaviour no other core test pins: a stop that takes over a running T5 stop, T5 into a SWITCHED
// ON that holds torque, the ways out of a Lexium quick stop, the codes STO and undervoltage record,
// status bits passed through from the motion side, and a lost connection beside a Lexium warning.
// Every expectation is written from the seed a test cites, docs/semantics.md (S1..S17) or the project's
// documented choices in docs/semantics.md; the profiles' rows are never read.
#include <cstdint>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace cia402 {
namespace {

using test::bench;
using test::words_for;
using S = state;

// Status bits 0..3, 5, 6 of the states (cia402-reference.md §1.1, S11) and the masks they are
// read under.
constexpr std::uint16_t state_mask = 0x006F;
constexpr std::uint16_t operation_enabled_bits = 0x0027;
constexpr std::uint16_t switched_on_bits = 0x0023;
constexpr std::uint16_t switch_on_disabled_bits = 0x0040;

const std::uint16_t any_fault = 0x5530;

// The transitions taken since `from` (an index into bench::taken).
std::vector<std::uint8_t> taken_since(const bench& b, std::size_t from) {
  return std::vector<std::uint8_t>(b.taken.begin() + static_cast<std::ptrdiff_t>(from),
                                   b.taken.end());
}

// ---------------------------------------------------------------------------------------------
// A stop that takes over a running T5 stop.

// 004_e07fd68605b3a8c6.txt T5: "Bit 3 is canceled ... Motor is braked, using the relevant ramp";
// T17: "Bit 2 is canceled: Switch-on inhibited, output stage disabled", and STW bit 2 is "fast
// stop, switch-on inhibited": the emergency ramp, then the axis is disabled (cia402-reference.md
// §6.1). S7: the state changes when the stop completes, and the status word shows the source state
// until then; S12: a ramped stop closes the brake at standstill, then removes torque.
TEST(stop_takeover, ax2000_bit_2_cleared_during_t5_ramp_stops_on_quick_stop_ramp_then_takes_t17) {
  bench b(test::builtin("ax2000-profibus"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.standstill = false;
  b.in.brake_engaged = false;
  b.in.control_word = 0x17;  // bit 3 canceled: T5 on its ramp
  b.step();
  ASSERT_EQ(b.out.current, S::operation_enabled) << test::describe(b.out);
  ASSERT_EQ(b.out.ramp, stop_ramp::slow_down);
  const std::size_t before = b.taken.size();

  b.in.control_word = 0x13;  // bit 2 canceled as well: T17
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE("still turning, step " + std::to_string(i));
    b.step();
    EXPECT_EQ(b.out.transition, no_transition) << test::describe(b.out);
    EXPECT_EQ(b.out.current, S::operation_enabled);
    EXPECT_EQ(b.out.status_word & state_mask, operation_enabled_bits);
    EXPECT_EQ(b.out.ramp, stop_ramp::quick_stop) << "the emergency ramp, not T5's";
    EXPECT_TRUE(b.out.torque);
    EXPECT_TRUE(b.out.brake_released);
  }
  b.in.standstill = true;  // stopped: the brake closes while torque holds the axis
  b.step();
  EXPECT_EQ(b.out.current, S::operation_enabled) << test::describe(b.out);
  EXPECT_TRUE(b.out.torque);
  EXPECT_FALSE(b.out.brake_released);
  b.in.brake_engaged = true;  // engaged: now the output stage goes
  b.step();
  EXPECT_EQ(int(b.out.transition), 17) << test::describe(b.out);
  EXPECT_EQ(b.out.current, S::switch_on_disabled);
  EXPECT_FALSE(b.out.torque);
  EXPECT_FALSE(b.out.brake_released);
  EXPECT_EQ(taken_since(b, before), (std::vector<std::uint8_t>{17})) << "T5 never completed";
}

// 001_f9323c8e43dc977c.txt T9 (lines 30..36): a "Request for disabling the power stage" cancels the
// movement "with Halt or power stage is immediately disabled. Can be set via parameter
// DSM_ShutDownOption" (0x605B in this profile). T5 (lines 18..20) halts first. Here the local
// request comes while T5's ramp runs and the master already sends Enable operation again.
void start_t5_then_local_disable(bench& b) {
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.standstill = false;
  b.in.brake_engaged = false;
  b.in.control_word = 0x0007;  // Disable operation: T5
  b.step();
  ASSERT_EQ(b.out.current, S::operation_enabled) << "T5 halts first; " << test::describe(b.out);
  ASSERT_TRUE(b.out.torque);
  b.in.control_word = 0x000F;  // Enable operation
  b.in.local_disable = true;
}

TEST(stop_takeover, lexium32_local_disable_during_t5_ramp_with_0x605b_1_ramps_then_takes_t9) {
  bench b(test::builtin("lexium32"));
  ASSERT_EQ(b.write(0x605B, 1), sdo_abort::none);
  start_t5_then_local_disable(b);
  const std::size_t before = b.taken.size();
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE("still turning, step " + std::to_string(i));
    b.step();
    EXPECT_EQ(b.out.transition, no_transition) << test::describe(b.out);
    EXPECT_EQ(b.out.current, S::operation_enabled);
    EXPECT_EQ(b.out.ramp, stop_ramp::slow_down) << "DSM_ShutDownOption 1: Halt";
    EXPECT_TRUE(b.out.torque);
    EXPECT_TRUE(b.out.brake_released);
  }
  b.in.standstill = true;
  b.step();
  EXPECT_EQ(b.out.current, S::operation_enabled) << test::describe(b.out);
  EXPECT_TRUE(b.out.torque);
  EXPECT_FALSE(b.out.brake_released) << "the brake closes at standstill, before torque goes";
  b.in.brake_engaged = true;
  b.step();
  EXPECT_EQ(int(b.out.transition), 9) << test::describe(b.out);
  EXPECT_EQ(b.out.current, S::switch_on_disabled);
  EXPECT_FALSE(b.out.torque);
  EXPECT_FALSE(b.out.brake_released);
  EXPECT_EQ(taken_since(b, before), (std::vector<std::uint8_t>{9}))
      << "T9 took over T5; it did not wait for T5 and then take T10";
}

TEST(stop_takeover, lexium32_local_disable_during_t5_ramp_with_0x605b_0_coasts_at_once) {
  bench b(test::builtin("lexium32"));
  ASSERT_EQ(b.write(0x605B, 0), sdo_abort::none);
  start_t5_then_local_disable(b);
  b.step();  // the motor still turns, the brake is not engaged
  EXPECT_EQ(int(b.out.transition), 9)
      << "power stage immediately disabled; " << test::describe(b.out);
  EXPECT_EQ(b.out.current, S::switch_on_disabled);
  EXPECT_FALSE(b.out.torque);
  EXPECT_FALSE(b.out.brake_released) << "a coast closes the brake at once (S12)";
  EXPECT_NE(b.out.ramp, stop_ramp::slow_down);
}

// 003_83442f2f4b0b2bb9.txt T3: "Output stage is switched on (enabled). Drive has torque."; T5:
// "Drive is braked, using the relevant ramp" into "Ready for operation ... Output stage is switched
// on". 004_e07fd68605b3a8c6.txt says the same ("Motor has torque", "Motor is braked"). T5 keeps
// torque, so S12's "brake released only while torque is on" never asks the brake to close, and
// docs/semantics.md choice 20: T5 is taken at standstill without waiting for the brake.
TEST(stop_takeover, profibus_t5_into_switched_on_keeps_brake_released_and_ends_at_standstill) {
  for (const char* name : {"s300-profibus", "ax2000-profibus"}) {
    SCOPED_TRACE(name);
    bench b(test::builtin(name));
    ASSERT_TRUE(test::reach(b, S::operation_enabled));
    const std::size_t before = b.taken.size();
    b.in.standstill = false;
    b.in.brake_engaged = false;  // and it stays so: the brake is never asked to close
    b.in.control_word = words_for(b.p).switch_on;
    for (int i = 0; i < 3; ++i) {
      SCOPED_TRACE("still turning, step " + std::to_string(i));
      b.step();
      EXPECT_EQ(b.out.transition, no_transition) << test::describe(b.out);
      EXPECT_EQ(b.out.current, S::operation_enabled);
      EXPECT_EQ(b.out.ramp, stop_ramp::slow_down);
      EXPECT_TRUE(b.out.torque);
      EXPECT_TRUE(b.out.brake_released);
    }
    b.in.standstill = true;
    std::uint8_t got = no_transition;
    for (int i = 0; i < 2 && got == no_transition; ++i) {
      b.step();
      got = b.out.transition;
      EXPECT_TRUE(b.out.torque) << test::describe(b.out);
      EXPECT_TRUE(b.out.brake_released) << test::describe(b.out);
    }
    EXPECT_EQ(int(got), 5) << "T5 completes at standstill although the brake never engaged";
    EXPECT_EQ(b.out.current, S::switched_on);
    for (int i = 0; i < 3; ++i) {
      SCOPED_TRACE("after the ramp, step " + std::to_string(i));
      b.step();
      EXPECT_EQ(b.out.current, S::switched_on) << test::describe(b.out);
      EXPECT_EQ(b.out.status_word & state_mask, switched_on_bits);
      EXPECT_EQ(b.out.ramp, stop_ramp::none);
      EXPECT_TRUE(b.out.torque);
      EXPECT_TRUE(b.out.brake_released);
    }
    EXPECT_EQ(taken_since(b, before), (std::vector<std::uint8_t>{5}));
  }
}

// ---------------------------------------------------------------------------------------------
// Leaving a Lexium quick stop (001_f9323c8e43dc977c.txt T11, T16 and footnote (3)).

// T11 (lines 39..40): "Error of error class 1" quick-stops. T16 (lines 50..54): "In the event of a
// Quick Stop triggered by a detected error of class 1, a Fault Reset causes a direct transition to
// ... Operation Enabled"; Enable Operation is "Possible only if operating state was triggered via
// the fieldbus" (footnote (3), line 57). T15's "cause of error must have been corrected" (line 49)
// is read for the class-1 reset too (docs/profiles/lexium32.md).
TEST(quick_stop_exit,
     lexium32_class_1_quick_stop_ignores_enable_operation_and_leaves_by_fault_reset) {
  bench b(test::builtin("lexium32"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  const std::size_t before = b.taken.size();
  b.in.fault_code = any_fault;
  b.in.fault_class = 1;
  b.step();
  ASSERT_EQ(int(b.out.transition), 11) << test::describe(b.out);
  ASSERT_EQ(b.out.current, S::quick_stop_active);

  // The master keeps sending Enable operation while the cause is present.
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE("cause present, step " + std::to_string(i));
    b.step();
    EXPECT_EQ(b.out.transition, no_transition) << test::describe(b.out);
    EXPECT_EQ(b.out.current, S::quick_stop_active);
  }
  // The cause is corrected; Enable operation still does not leave: the quick stop came from a
  // fault.
  b.in.fault_code = 0;
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE("cause gone, step " + std::to_string(i));
    b.step();
    EXPECT_EQ(b.out.transition, no_transition) << test::describe(b.out);
    EXPECT_EQ(b.out.current, S::quick_stop_active);
  }
  b.in.control_word = 0x008F;  // Fault Reset edge (bit 7 0 -> 1), Enable operation kept
  b.step();
  EXPECT_EQ(int(b.out.transition), 16) << test::describe(b.out);
  EXPECT_EQ(b.out.current, S::operation_enabled);
  EXPECT_TRUE(b.out.torque);
  EXPECT_EQ(taken_since(b, before), (std::vector<std::uint8_t>{11, 16}));
}

// T16 (lines 50..54) with footnote (3): after a Quick Stop the fieldbus commanded, Enable Operation
// leaves QUICK STOP ACTIVE.
TEST(quick_stop_exit, lexium32_fieldbus_quick_stop_is_left_by_enable_operation) {
  bench b(test::builtin("lexium32"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.control_word = 0x0002;  // Quick stop
  b.step();
  ASSERT_EQ(int(b.out.transition), 11) << test::describe(b.out);
  b.step();
  ASSERT_EQ(b.out.current, S::quick_stop_active) << "0x605A 6/7 hold the quick stop";
  b.in.control_word = 0x000F;  // Enable operation
  b.step();
  EXPECT_EQ(int(b.out.transition), 16) << test::describe(b.out);
  EXPECT_EQ(b.out.current, S::operation_enabled);
}

// ---------------------------------------------------------------------------------------------
// Error codes the drive raises itself (S13, S14; docs/semantics.md choices 5 and 16).

// In every built-in, from OPERATION ENABLED with torque on and no error: `cause` takes T13 in the
// next step with the torque off, 0x603F = `code` and 0x1001 = `reg`, and FAULT keeps both.
void expect_fault_recorded(void (*cause)(bench&), std::uint16_t code, std::uint8_t reg) {
  for (const profile* p : test::all_builtins()) {
    SCOPED_TRACE(p->name);
    bench b(*p);
    ASSERT_TRUE(test::reach(b, S::operation_enabled));
    ASSERT_TRUE(b.out.torque);
    ASSERT_EQ(b.out.error_code, 0);
    cause(b);
    b.step();
    EXPECT_EQ(int(b.out.transition), 13) << test::describe(b.out);
    EXPECT_FALSE(b.out.torque);
    EXPECT_EQ(b.out.error_code, code);
    EXPECT_EQ(b.out.error_register, reg);
    b.settle();
    EXPECT_EQ(b.a.current, S::fault);
    EXPECT_EQ(b.out.error_code, code) << "0x603F keeps the code in FAULT";
    EXPECT_EQ(b.out.error_register, reg);
  }
}

// S14: STO while torque is on is a fault (T13) with a documented code: 0xFF01, in the manufacturer
// range. 0x1001 (CiA 301, cia402-reference.md §5): bit 0 generic + bit 7 manufacturer = 0x81.
TEST(fault_codes, sto_while_torque_is_on_records_0xff01_and_error_register_0x81) {
  expect_fault_recorded([](bench& b) { b.in.sto = true; }, 0xFF01, 0x81);
}

// S13: losing the DC link while torque is on is a fault (T13, 0x3220). 0x1001: bit 0 generic + bit
// 2 voltage = 0x05.
TEST(fault_codes, dc_link_lost_while_torque_is_on_records_0x3220_and_error_register_0x05) {
  expect_fault_recorded([](bench& b) { b.in.dc_link = false; }, 0x3220, 0x05);
}

// S14 elsewhere: STO where torque is off raises the warning bit 7; no fault, no code. S11 gives the
// whole status word of SWITCH ON DISABLED on the ideal plant: 0x40 | bit 4 (DC link) | bit 9
// (remote) = 0x0250; with STO bit 7 joins it. T2 waits for STO to go (S14).
TEST(fault_codes, cia402_sto_in_switch_on_disabled_sets_only_bit_7_and_holds_the_state) {
  bench b(test::builtin("cia402"));
  ASSERT_TRUE(test::reach(b, S::switch_on_disabled));
  b.step();
  ASSERT_EQ(b.out.status_word, 0x0250) << test::describe(b.out);
  b.in.sto = true;
  for (int i = 0; i < 3; ++i) {
    b.step();
    EXPECT_EQ(b.out.transition, no_transition) << test::describe(b.out);
    EXPECT_EQ(b.out.status_word, 0x02D0);
    EXPECT_EQ(b.out.error_code, 0);
    EXPECT_EQ(b.out.error_register, 0);
  }
  // S14: SWITCH ON DISABLED is not left while STO is active, whatever the master sends.
  for (std::uint16_t word : {std::uint16_t{0x0006}, std::uint16_t{0x0007}, std::uint16_t{0x000F}}) {
    SCOPED_TRACE(test::hex(word));
    b.in.control_word = word;
    for (int i = 0; i < 3; ++i) {
      b.step();
      EXPECT_EQ(b.out.transition, no_transition) << "T2 blocked by STO; " << test::describe(b.out);
      EXPECT_EQ(b.out.current, S::switch_on_disabled);
      EXPECT_TRUE(b.out.status_word & status_bit::warning);
      EXPECT_FALSE(b.out.torque);
      EXPECT_EQ(b.out.error_code, 0);
    }
  }
  b.in.sto = false;  // released with Enable operation held: no restart
  b.step();
  EXPECT_EQ(b.out.transition, no_transition) << test::describe(b.out);
  EXPECT_EQ(b.out.current, S::switch_on_disabled);
  EXPECT_FALSE(b.out.status_word & status_bit::warning);
  b.in.control_word = 0x0006;  // only a Shutdown brings the drive back
  b.step();
  EXPECT_EQ(int(b.out.transition), 2) << test::describe(b.out);
}

// ---------------------------------------------------------------------------------------------
// Status bits from the motion side (S11; docs/semantics.md choices 14 and 15).

// S11: bit 11 = internal limit active; bits 8 and 12..15 (manufacturer / operation-mode specific,
// cia402-reference.md §1.2) pass through unchanged, whatever the state, and no other bit of
// `status_bits` reaches the status word. Checked where the drive `b` stands; it must stay
// there.
void check_pass_through(bench& b) {
  const state s = b.a.current;
  const std::uint16_t passed[] = {0x0000, 0x0100, 0x1000, 0x2000, 0x4000, 0x8000, 0xA100, 0xF100};
  for (std::uint16_t bits : passed) {
    for (bool limit : {false, true}) {
      SCOPED_TRACE(test::hex(bits) + (limit ? " with internal limit" : ""));
      b.in.status_bits = static_cast<std::uint16_t>(bits | (limit ? status_bit::internal_limit_active : 0));
      b.step();
      ASSERT_EQ(b.out.current, s) << test::describe(b.out);
      const std::uint16_t want = static_cast<std::uint16_t>(bits | (limit ? 0x0800 : 0));
      EXPECT_EQ(b.out.status_word & 0xF900, want) << test::describe(b.out);
    }
  }
  // Bits 0..6 and 9 are the drive's own: set in status_bits, they change nothing.
  b.in.status_bits = 0xF100;
  b.step();
  const std::uint16_t clean = b.out.status_word;
  b.in.status_bits = static_cast<std::uint16_t>(0xF100 | 0x027F);
  b.step();
  EXPECT_EQ(b.out.status_word, clean) << test::describe(b.out);
}

TEST(status_word, bits_8_11_and_12_to_15_pass_through_from_the_motion_side_in_resting_states) {
  for (const profile* p : test::all_builtins()) {
    for (state s : {S::switch_on_disabled, S::ready_to_switch_on, S::switched_on,
                    S::operation_enabled, S::fault}) {
      SCOPED_TRACE(std::string(p->name) + " in " + state_name(s));
      bench b(*p);
      ASSERT_TRUE(test::reach(b, s));
      check_pass_through(b);
    }
  }
}

// The same while a stop runs: a T5 ramp, a holding quick stop (0x605A = 6 where the profile has
// 0x605A; the PROFIBUS fast stop holds by itself), a fault reaction on its ramp (S9, 0x605E = 2).
TEST(status_word, bits_8_11_and_12_to_15_pass_through_while_a_stop_runs) {
  for (const profile* p : test::all_builtins()) {
    SCOPED_TRACE(p->name);
    {
      SCOPED_TRACE("T5 ramp");
      bench b(*p);
      ASSERT_TRUE(test::reach(b, S::operation_enabled));
      b.in.standstill = false;
      b.in.control_word = words_for(*p).switch_on;
      check_pass_through(b);
    }
    if (std::string(p->name) != "no-quick-stop") {  // 000: "'Quick Stop' is not supported"
      SCOPED_TRACE("QUICK STOP ACTIVE");
      bench b(*p);
      const sdo_abort written = b.write(0x605A, 6);
      ASSERT_TRUE(written == sdo_abort::none || written == sdo_abort::object_does_not_exist);
      ASSERT_TRUE(test::reach(b, S::quick_stop_active));
      check_pass_through(b);
    }
  }
  SCOPED_TRACE("cia402 FAULT REACTION ACTIVE");
  bench b(test::builtin("cia402"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.standstill = false;
  b.in.fault_code = any_fault;
  b.step();
  ASSERT_EQ(b.out.current, S::fault_reaction_active) << test::describe(b.out);
  check_pass_through(b);
}

// docs/semantics.md choice 14 (S11: bit 10 is "target reached / standstill after halt or quick stop
// 5..8"): while a T5 or T8 stop runs, bit 10 stays clear, even with halt (bit 8) set and the motion
// side reporting its target reached. The last two checks make sure both routes to bit 10 are live.
TEST(status_word, bit_10_stays_clear_while_a_t5_or_t8_stop_runs_also_with_halt) {
  struct stop_case {
    const char* profile;
    std::uint16_t word;
  };
  // T5 ramps in every seed (000 "decelerated", 001 "canceled with Halt", 002 0x605C default 1,
  // 003/004 "braked, using the relevant ramp"); T8 ramps in 000, 001 and 002 (0x605B default 1),
  // not in 003/004. Bit 8 is halt where the profile has 0x605D (002, and 000 and 001 by their
  // pages).
  const stop_case cases[] = {
      {"cia402", 0x0007},          {"cia402", 0x0107},          {"cia402", 0x0006},
      {"cia402", 0x0106},          {"no-quick-stop", 0x0007},   {"no-quick-stop", 0x0107},
      {"no-quick-stop", 0x0006},   {"no-quick-stop", 0x0106},   {"lexium32", 0x0007},
      {"lexium32", 0x0107},        {"lexium32", 0x0006},        {"lexium32", 0x0106},
      {"s300-profibus", 0x0007},   {"ax2000-profibus", 0x0017},
  };
  for (const stop_case& c : cases) {
    SCOPED_TRACE(std::string(c.profile) + " control word " + test::hex(c.word));
    bench b(test::builtin(c.profile));
    ASSERT_TRUE(test::reach(b, S::operation_enabled));
    b.in.status_bits = status_bit::target_reached;
    b.in.standstill = false;
    b.in.brake_engaged = false;
    b.in.control_word = c.word;
    for (int i = 0; i < 2; ++i) {
      b.step();
      ASSERT_EQ(b.out.current, S::operation_enabled)
          << "the stop still runs; " << test::describe(b.out);
      EXPECT_FALSE(b.out.status_word & status_bit::target_reached) << test::describe(b.out);
    }
    b.in.standstill = true;  // at standstill; where torque goes, the brake has not engaged yet
    b.step();
    if (b.out.transition == no_transition) {
      EXPECT_FALSE(b.out.status_word & status_bit::target_reached) << test::describe(b.out);
    }
  }

  // Without a running stop the same inputs do set bit 10: target reached in OPERATION ENABLED, and
  // halt at standstill (S8).
  bench b(test::builtin("cia402"));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  b.in.status_bits = status_bit::target_reached;
  b.step();
  EXPECT_TRUE(b.out.status_word & status_bit::target_reached) << test::describe(b.out);
  b.in.status_bits = 0;
  b.in.control_word = 0x010F;  // halt
  b.step();
  EXPECT_TRUE(b.out.status_word & status_bit::target_reached) << test::describe(b.out);
}

// ---------------------------------------------------------------------------------------------
// A lost connection beside a Lexium warning (S10 with 001_f9323c8e43dc977c.txt's error classes).

// S10: with 0x6007 = 1 a lost connection is a fault: T13, 0x8130 (0x1001 = 0x11: generic +
// communication). An error of class 0 (a warning) or class 1 (a quick stop, T11) present at the
// same time must not hide it. The fault's cause is the lost connection, so a Fault Reset is refused
// while it lasts (S2, seed 001 T15: "cause of error must have been corrected").
TEST(lost_connection,
     lexium32_0x6007_1_faults_beside_class_0_or_1_error_and_refuses_reset_until_back) {
  for (state s : {S::operation_enabled, S::switch_on_disabled}) {
    for (std::uint8_t cls : {std::uint8_t{0}, std::uint8_t{1}}) {
      SCOPED_TRACE(std::string(state_name(s)) + ", class " + std::to_string(cls));
      bench b(test::builtin("lexium32"));
      ASSERT_EQ(b.write(0x6007, 1), sdo_abort::none);
      ASSERT_TRUE(test::reach(b, s));
      b.in.fault_code = 0x2310;
      b.in.fault_class = cls;
      b.in.connection_lost = true;
      b.step();
      EXPECT_EQ(int(b.out.transition), 13) << test::describe(b.out);
      EXPECT_EQ(b.out.current, S::fault_reaction_active);
      EXPECT_EQ(b.out.error_code, 0x8130);
      EXPECT_EQ(b.out.error_register, 0x11);
      b.settle();
      ASSERT_EQ(b.a.current, S::fault) << test::describe(b.out);

      // The class 0/1 error is corrected; the connection stays lost.
      b.in.fault_code = 0;
      for (int attempt = 0; attempt < 2; ++attempt) {
        b.in.control_word = 0x0000;
        b.step();
        b.in.control_word = 0x0080;  // Fault Reset edge
        b.step();
        EXPECT_EQ(b.out.transition, no_transition) << test::describe(b.out);
        EXPECT_EQ(b.out.current, S::fault);
        EXPECT_EQ(b.out.error_code, 0x8130);
      }
      // The connection is back: the next edge resets.
      b.in.connection_lost = false;
      b.in.control_word = 0x0000;
      b.step();
      b.in.control_word = 0x0080;
      b.step();
      EXPECT_EQ(int(b.out.transition), 15) << test::describe(b.out);
      EXPECT_EQ(b.out.current, S::switch_on_disabled);
      EXPECT_EQ(b.out.error_code, 0);
      EXPECT_EQ(b.out.status_word & state_mask, switch_on_disabled_bits);
    }
  }
}

}  // namespace
}  // namespace cia402
