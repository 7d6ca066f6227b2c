// S17: a planned path to any target but OPERATION ENABLED never enters OPERATION ENABLED, and a
// drive that needs Fault Reset to leave a state (seed 001_f9323c8e43dc977c.txt T16, footnote 3: a
// quick stop a class-1 error caused) gets it from the master, which cannot see how the state was
// entered.
#include <gtest/gtest.h>

#include <string>

#include "cia402/master.hpp"
#include "fsa_states.hpp"

namespace {

using cia402::state;

using cia402::test::fsa_states;

// Every option value of 0x605A the profile supports (the one that decides T16 and T12).
std::vector<int> quick_stop_codes(const cia402::profile& p) {
  std::vector<int> codes;
  const cia402::option_spec& s = p.spec(cia402::option::quick_stop);
  for (int v = 0; v < 16; ++v) {
    if (s.allows(v)) codes.push_back(v);
  }
  if (codes.empty()) codes.push_back(s.default_value);
  return codes;
}

TEST(planner_s17, no_path_to_another_target_enters_operation_enabled) {
  int checked = 0;
  int through_before = 0;  // the case the issue names: QSA -> SO with 605A = 6
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile& p = cia402::builtin_profile(i);
    for (const int qs : quick_stop_codes(p)) {
      cia402::axis options = cia402::make_axis(p);
      options.options[static_cast<int>(cia402::option::quick_stop)] = static_cast<std::int8_t>(qs);
      for (const state from : fsa_states) {
        for (const state target : fsa_states) {
          if (target == state::operation_enabled || from == target) continue;
          for (const bool bit : {false, true}) {
            const cia402::command_path path =
                cia402::plan_path_from_status(p, options, from, bit, target);
            if (!path.reachable) continue;
            ++checked;
            // Starting in OPERATION ENABLED, a ramped stop keeps it for a cycle; once out of
            // it (or never in), the path must not come back.
            bool out_of_it = from != state::operation_enabled;
            for (std::size_t k = 0; k < path.length; ++k) {
              const bool in_it = path.steps[k].after == state::operation_enabled;
              out_of_it |= !in_it;
              EXPECT_FALSE(in_it && out_of_it)
                  << p.name << " 605A=" << qs << " " << cia402::state_name(from) << " -> "
                  << cia402::state_name(target) << " cycle " << k + 1;
            }
            if (std::string(p.name) == "cia402" && qs == 6 && from == state::quick_stop_active &&
                target == state::switched_on && !bit) {
              ++through_before;
              // T12 by Disable voltage, T2, T3: one cycle more than through T16 and T5.
              ASSERT_EQ(path.length, 3u);
              EXPECT_EQ(path.steps[0].transition, 12);
              EXPECT_EQ(path.steps[1].transition, 2);
              EXPECT_EQ(path.steps[2].transition, 3);
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(through_before, 1);
  EXPECT_GT(checked, 100);
}

// The lexium drive in a class-1 quick stop whose cause is gone: Enable operation alone does not
// leave it; the master's command does, and it also leaves a quick stop the fieldbus asked for.
TEST(planner_s17, master_leaves_a_class_1_quick_stop_with_fault_reset) {
  const cia402::profile& p = *cia402::find_builtin_profile("lexium32");
  for (const bool by_fault : {true, false}) {
    SCOPED_TRACE(by_fault ? "entered by a class-1 error" : "entered by Quick stop");
    cia402::axis a = cia402::make_axis(p);
    cia402::drive_inputs in;
    for (const std::uint16_t cw : {0x0000, 0x0000, 0x0006, 0x000F, 0x000F}) {
      in.control_word = cw;
      cia402::step(p, a, in);
    }
    ASSERT_EQ(a.current, state::operation_enabled);
    if (by_fault) {
      in.fault_code = 0x4100;
      in.fault_class = 1;
    } else {
      in.control_word = 0x000B;
    }
    cia402::step(p, a, in);
    ASSERT_EQ(a.current, state::quick_stop_active);
    in.fault_code = 0;  // the cause is gone

    const cia402::master_policy policy =
        cia402::master_policy::make(p, a, state::operation_enabled);
    cia402::master m;
    m.set_target(policy, 0, 50);
    std::uint16_t status = cia402::step(p, a, in).status_word;
    int cycles = 0;
    for (; cycles < 20 && m.outcome() != cia402::master_outcome::reached; ++cycles) {
      in.control_word = m.step(status, static_cast<std::uint64_t>(cycles));
      status = cia402::step(p, a, in).status_word;
    }
    EXPECT_EQ(m.outcome(), cia402::master_outcome::reached)
        << cia402::master_outcome_name(m.outcome());
    EXPECT_EQ(a.current, state::operation_enabled);
    EXPECT_LE(cycles, 3);
  }
}

}  // namespace
