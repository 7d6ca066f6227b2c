// The master drives the real drive-side machine in a closed loop and must reach every target in
// exactly the cycles its plan says, or say the target is unreachable.
#include <gtest/gtest.h>

#include <deque>

#include "cia402/master.hpp"

namespace {

using cia402::master_outcome;
using cia402::state;

struct loop_result {
  master_outcome outcome = master_outcome::idle;
  int cycles = 0;  // drive steps before the master saw the target
  state final_state = state::start;
};

std::uint16_t status_at_rest(const cia402::profile& p, state s) {
  return static_cast<std::uint16_t>(p.status_pattern(s) | cia402::status_bit::voltage_enabled |
                                    cia402::status_bit::remote);
}

// Runs master and drive, the status word reaching the master `delay` cycles late.
loop_result run_loop(const cia402::profile& p, cia402::axis drive_axis,
                     const cia402::master_policy& policy, int delay, int max_cycles) {
  cia402::master m;
  m.set_target(policy, 0, 0);
  std::deque<std::uint16_t> in_flight(static_cast<std::size_t>(delay) + 1,
                                      status_at_rest(p, drive_axis.current));
  loop_result r;
  for (int cycle = 0; cycle <= max_cycles; ++cycle) {
    const std::uint16_t cw = m.step(in_flight.front(), static_cast<std::uint64_t>(cycle));
    in_flight.pop_front();
    r.outcome = m.outcome();
    if (r.outcome != master_outcome::in_progress) break;
    cia402::drive_inputs in;
    in.control_word = cw;
    const cia402::drive_outputs out = cia402::step(p, drive_axis, in);
    in_flight.push_back(out.status_word);
    r.cycles = cycle + 1;
  }
  r.final_state = drive_axis.current;
  return r;
}

constexpr state fsa_states[] = {
    state::not_ready_to_switch_on, state::switch_on_disabled, state::ready_to_switch_on,
    state::switched_on,            state::operation_enabled,  state::quick_stop_active,
    state::fault_reaction_active,  state::fault,
};

void check_every_pair(const cia402::profile& p, const cia402::axis& options) {
  for (const state target : fsa_states) {
    const cia402::master_policy policy = cia402::master_policy::make(p, options, target);
    for (const state from : fsa_states) {
      const cia402::axis start = cia402::axis_at_rest(p, options, from, false);
      const cia402::command_path plan = cia402::plan_path(p, start, target);
      const loop_result r = run_loop(p, start, policy, 0, 40);
      const std::string where = std::string(p.name) + " " + cia402::state_name(from) + " -> " +
                                cia402::state_name(target);
      if (!plan.reachable) {
        EXPECT_EQ(r.outcome, master_outcome::unreachable) << where;
        EXPECT_EQ(r.cycles, 0) << where;
        continue;
      }
      EXPECT_EQ(r.outcome, master_outcome::reached) << where;
      EXPECT_EQ(r.cycles, plan.length) << where;
      EXPECT_EQ(policy.first[static_cast<int>(from)][0].cycles, plan.length) << where;
      // Replaying the plan's words on a fresh drive takes exactly its transitions.
      cia402::axis replay = start;
      for (int k = 0; k < plan.length; ++k) {
        cia402::drive_inputs in;
        in.control_word = plan.steps[static_cast<std::size_t>(k)].control_word;
        const cia402::drive_outputs out = cia402::step(p, replay, in);
        EXPECT_EQ(out.transition, plan.steps[static_cast<std::size_t>(k)].transition) << where;
        EXPECT_EQ(out.current, plan.steps[static_cast<std::size_t>(k)].after) << where;
      }
      EXPECT_EQ(replay.current, target) << where;
    }
  }
}

TEST(closed_loop, every_profile_reaches_every_reachable_target_in_the_planned_cycles) {
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile& p = cia402::builtin_profile(i);
    check_every_pair(p, cia402::make_axis(p));
  }
}

TEST(closed_loop, every_quick_stop_and_stop_option_code_keeps_the_plan_exact) {
  const cia402::profile& p = cia402::standard_profile();
  for (int qs = 0; qs <= 8; ++qs) {
    for (int stop = 0; stop <= 1; ++stop) {
      cia402::axis options = cia402::make_axis(p);
      ASSERT_EQ(cia402::write_option(p, options, 0x605A, qs), cia402::sdo_abort::none);
      ASSERT_EQ(cia402::write_option(p, options, 0x605B, stop), cia402::sdo_abort::none);
      ASSERT_EQ(cia402::write_option(p, options, 0x605C, stop), cia402::sdo_abort::none);
      SCOPED_TRACE("605A=" + std::to_string(qs) + " 605B/C=" + std::to_string(stop));
      check_every_pair(p, options);
    }
  }
}

TEST(closed_loop, quick_stop_codes_1_to_4_know_quick_stop_active_ends_by_itself) {
  const cia402::profile& p = cia402::standard_profile();
  cia402::axis options = cia402::make_axis(p);
  ASSERT_EQ(cia402::write_option(p, options, 0x605A, 2), cia402::sdo_abort::none);
  const cia402::axis qsa = cia402::axis_at_rest(p, options, state::quick_stop_active, false);
  const cia402::command_path back = cia402::plan_path(p, qsa, state::operation_enabled);
  ASSERT_TRUE(back.reachable);
  EXPECT_EQ(back.steps[0].transition, 12);  // no T16: down to SWITCH ON DISABLED, then up again
  EXPECT_EQ(back.length, 4);

  ASSERT_EQ(cia402::write_option(p, options, 0x605A, 6), cia402::sdo_abort::none);
  const cia402::axis held = cia402::axis_at_rest(p, options, state::quick_stop_active, false);
  const cia402::command_path resume = cia402::plan_path(p, held, state::operation_enabled);
  ASSERT_TRUE(resume.reachable);
  EXPECT_EQ(resume.length, 1);
  EXPECT_EQ(resume.steps[0].transition, 16);
  EXPECT_EQ(resume.steps[0].control_word, 0x0F);
}

TEST(closed_loop, enable_operation_in_ready_to_switch_on_is_held_through_t3_and_t4) {
  const cia402::profile& p = cia402::standard_profile();
  const cia402::axis rtso =
      cia402::axis_at_rest(p, cia402::make_axis(p), state::ready_to_switch_on, false);
  const cia402::command_path path = cia402::plan_path(p, rtso, state::operation_enabled);
  ASSERT_EQ(path.length, 2);
  EXPECT_EQ(path.steps[0].control_word, 0x0F);
  EXPECT_EQ(path.steps[0].transition, 3);
  EXPECT_EQ(path.steps[1].control_word, 0x0F);
  EXPECT_EQ(path.steps[1].transition, 4);
}

TEST(closed_loop, fault_reset_clears_bit_7_for_a_cycle_when_the_drive_last_saw_it_set) {
  const cia402::profile& p = cia402::standard_profile();
  const cia402::axis seen_set = cia402::axis_at_rest(p, cia402::make_axis(p), state::fault, true);
  const cia402::command_path path = cia402::plan_path(p, seen_set, state::switch_on_disabled);
  ASSERT_EQ(path.length, 2);
  EXPECT_EQ(path.steps[0].control_word & 0x80, 0);
  EXPECT_EQ(path.steps[0].transition, cia402::no_transition);
  EXPECT_EQ(path.steps[1].control_word & 0x80, 0x80);
  EXPECT_EQ(path.steps[1].transition, 15);
}

TEST(closed_loop, late_status_words_still_reach_the_target_without_a_fault) {
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile& p = cia402::builtin_profile(i);
    const cia402::axis options = cia402::make_axis(p);
    for (const state target : {state::operation_enabled, state::switch_on_disabled,
                               state::ready_to_switch_on, state::switched_on}) {
      const cia402::master_policy policy = cia402::master_policy::make(p, options, target);
      for (const state from : {state::switch_on_disabled, state::fault, state::operation_enabled,
                               state::switched_on}) {
        for (int delay = 1; delay <= 3; ++delay) {
          const cia402::axis start = cia402::axis_at_rest(p, options, from, false);
          const cia402::command_path plan = cia402::plan_path(p, start, target);
          ASSERT_TRUE(plan.reachable);
          const loop_result r = run_loop(p, start, policy, delay, 200);
          const std::string where = std::string(p.name) + " " + cia402::state_name(from) +
                                    " -> " + cia402::state_name(target) +
                                    " delay " + std::to_string(delay);
          EXPECT_EQ(r.outcome, master_outcome::reached) << where;
          EXPECT_EQ(r.final_state, target) << where;
          // Each command waits at most `delay` extra cycles for its effect to show.
          EXPECT_LE(r.cycles, (plan.length + 1) * (delay + 1)) << where;
        }
      }
    }
  }
}

}  // namespace

namespace {

TEST(closed_loop, a_path_sets_bit_7_only_for_the_fault_reset_itself) {
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile& p = cia402::builtin_profile(i);
    const cia402::axis options = cia402::make_axis(p);
    for (const state from : fsa_states) {
      for (const state target : fsa_states) {
        const cia402::command_path path =
            cia402::plan_path(p, cia402::axis_at_rest(p, options, from, false), target);
        for (int k = 0; k < path.length; ++k) {
          const cia402::path_step& s = path.steps[static_cast<std::size_t>(k)];
          if (s.control_word & 0x80) {
            EXPECT_EQ(s.transition, 15) << p.name << " " << cia402::state_name(from) << " -> "
                                        << cia402::state_name(target) << " step " << k;
          }
        }
      }
    }
  }
}

}  // namespace
