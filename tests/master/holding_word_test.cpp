// The word a master holds at its target keeps the drive there and asks nothing more of it: once a
// caller asked for any state but OPERATION ENABLED, no word it sends is Enable operation, before or
// after the target is reached (a drive in QUICK STOP ACTIVE with 0x605A = 5..8 would take T16 back
// to OPERATION ENABLED on it).
#include <gtest/gtest.h>

#include "cia402/master.hpp"
#include "fsa_states.hpp"

namespace {

using cia402::command;
using cia402::master_outcome;
using cia402::state;

using cia402::test::fsa_states;

// Runs the master from `from` towards `target` and on for 40 cycles at the target: no word sent to a
// target other than OPERATION ENABLED is Enable operation, and a drive that can stand at the target
// (its holding word keeps it there at rest) is still there at the end.
void check_from(const cia402::profile& p, const cia402::axis& options, state from, state target) {
  // States the drive leaves by itself are no target a master holds.
  if (target == state::not_ready_to_switch_on || target == state::fault_reaction_active) return;
  const cia402::master_policy policy = cia402::master_policy::make(p, options, target);
  const std::uint16_t owned = cia402::owned_control_bits(p);
  cia402::axis drive = cia402::axis_at_rest(p, options, from, false);
  const cia402::command_path plan = cia402::plan_path(p, drive, target);
  if (!plan.reachable) return;
  cia402::master m;
  m.set_target(policy, 0, 0);
  std::uint16_t sw = static_cast<std::uint16_t>(p.status_pattern(from) | cia402::status_bit::voltage_enabled |
                                                cia402::status_bit::remote);
  const std::string where = std::string(p.name) + " " + cia402::state_name(from) + " -> " + cia402::state_name(target) +
                            " (0x605A = " + std::to_string(options.options[static_cast<int>(cia402::option::quick_stop)]) + ")";
  int at_target = 0;
  for (int cycle = 0; cycle < 80 && at_target < 40; ++cycle) {
    const std::uint16_t cw = m.step(sw, static_cast<std::uint64_t>(cycle));
    if (target != state::operation_enabled) {
      ASSERT_NE(p.decode(static_cast<std::uint16_t>(cw & owned)), command::enable_operation)
          << where << ": cycle " << cycle << " sent " << cw;
    }
    cia402::drive_inputs in;
    in.control_word = cw;
    sw = cia402::step(p, drive, in).status_word;
    if (m.outcome() == master_outcome::reached) ++at_target;
  }
  // Held: a drive that can stand at the target is still there (QUICK STOP ACTIVE with 0x605A = 1..4
  // ends by itself, and the master then finds it unreachable from where the drive went).
  cia402::axis probe = cia402::axis_at_rest(p, options, target, false);
  cia402::drive_inputs hold_in;
  hold_in.control_word = policy.first[static_cast<int>(target)][0].control_word;
  cia402::step(p, probe, hold_in);
  cia402::step(p, probe, hold_in);
  if (probe.current != target) return;
  EXPECT_EQ(m.outcome(), master_outcome::reached) << where;
  EXPECT_EQ(drive.current, target) << where;
}

TEST(holding_word, no_word_to_a_target_but_operation_enabled_is_enable_operation_on_any_profile) {
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile& p = cia402::builtin_profile(i);
    for (const state target : fsa_states) {
      for (const state from : fsa_states) check_from(p, cia402::make_axis(p), from, target);
    }
  }
}

TEST(holding_word, every_quick_stop_code_keeps_quick_stop_active_and_switch_on_disabled_without_enable) {
  const cia402::profile& p = cia402::standard_profile();
  for (int qs = 0; qs <= 8; ++qs) {
    cia402::axis options = cia402::make_axis(p);
    ASSERT_EQ(cia402::write_option(p, options, 0x605A, qs), cia402::sdo_abort::none);
    for (const state target : fsa_states) {
      for (const state from : fsa_states) check_from(p, options, from, target);
    }
  }
}

TEST(holding_word, each_standard_target_holds_with_the_command_that_asks_least) {
  const cia402::profile& p = cia402::standard_profile();
  cia402::axis options = cia402::make_axis(p);
  ASSERT_EQ(cia402::write_option(p, options, 0x605A, 6), cia402::sdo_abort::none);
  const auto hold = [&](state s) { return cia402::master_policy::make(p, options, s).first[static_cast<int>(s)][0].control_word; };
  EXPECT_EQ(hold(state::switch_on_disabled), 0x0000);  // Disable voltage, not the 0x000F a path from START ends on
  EXPECT_EQ(hold(state::ready_to_switch_on), 0x0006);
  EXPECT_EQ(hold(state::switched_on), 0x0007);
  EXPECT_EQ(hold(state::operation_enabled), 0x000F);
  EXPECT_EQ(hold(state::quick_stop_active), 0x0002);
  EXPECT_EQ(hold(state::fault), 0x0000);
}

}  // namespace
