// The master side never touches the heap either (include/cia402/master.hpp: "No heap"; STYLE.md,
// ETL: "a test that fails if the core calls operator new"). As in
// tests/core/no_allocation_test.cpp, every global operator new and delete is replaced by the
// counting versions of tests/support/counting_allocator.hpp, and the counts are read around stretches of master calls only, since gtest
// itself allocates. This file is its own executable so the replacement touches nothing else.
#include <gtest/gtest.h>

#include "cia402/drive.hpp"
#include "cia402/master.hpp"
#include "fsa_states.hpp"
#include "cia402/profile.hpp"

#include "counting_allocator.hpp"

namespace cia402 {
namespace {

using test::heap_calls_during;

using test::fsa_states;

TEST(master_no_allocation, counter_sees_a_heap_allocation) {
  // So the zero counts below can mean something.
  EXPECT_EQ(test::heap_calls_of_two_known_allocations(), 4);
}

TEST(master_no_allocation, plan_path_from_every_state_to_every_target_never_allocates) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    const axis options = make_axis(p);
    int reachable = 0;
    const long calls = heap_calls_during([&] {
      for (const state from : fsa_states) {
        for (const bool reset_bit : {false, true}) {
          const axis start = axis_at_rest(p, options, from, reset_bit);
          for (const state target : fsa_states) {
            const command_path path = plan_path(p, start, target);
            reachable += path.reachable ? 1 : 0;
          }
        }
      }
    });
    EXPECT_EQ(calls, 0) << p.name;
    EXPECT_GT(reachable, 0) << p.name << ": the searches ran";
  }
}

TEST(master_no_allocation, master_policy_make_for_every_target_never_allocates) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    const axis options = make_axis(p);
    std::uint32_t sink = 0;
    const long calls = heap_calls_during([&] {
      for (const state target : fsa_states) {
        const master_policy policy = master_policy::make(p, options, target);
        sink += policy.first[static_cast<int>(state::switch_on_disabled)][0].cycles;
      }
    });
    EXPECT_EQ(calls, 0) << p.name;
    EXPECT_NE(sink, 0u) << p.name << ": the policies were computed";
  }
}

// A master and a drive in a closed loop, through every target, faults, late and frozen status
// words, a word that shows no state, remote off, timeouts and cleared targets, so the master step
// takes each of its branches. Only the loop is counted; the policies are made before it.
TEST(master_no_allocation, master_step_in_a_closed_loop_never_allocates) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    const axis options = make_axis(p);
    master_policy policies[sizeof(fsa_states) / sizeof(fsa_states[0])];
    for (std::size_t t = 0; t < sizeof(fsa_states) / sizeof(fsa_states[0]); ++t) {
      policies[t] = master_policy::make(p, options, fsa_states[t]);
    }
    std::uint32_t sink = 0;
    int reached = 0;
    const long calls = heap_calls_during([&] {
      axis a = make_axis(p);
      master m;
      std::uint16_t status = 0;
      std::uint64_t now = 0;
      for (int round = 0; round < 40; ++round) {
        const master_policy& policy = policies[static_cast<std::size_t>(round) % 8];
        m.set_target(policy, now, round % 3 == 0 ? 5 : 0);
        m.application_bits = static_cast<std::uint16_t>(round % 2 ? 0x0100 : 0x0000);
        for (int cycle = 0; cycle < 30; ++cycle, ++now) {
          const std::uint16_t cw = m.step(status, now, 0x2310);
          drive_inputs in;
          in.control_word = cw;
          in.fault_code = (round % 5 == 4 && cycle == 3) ? 0x2310 : 0;
          in.remote = !(round % 7 == 6 && cycle > 10);
          const drive_outputs out = step(p, a, in);
          // Odd rounds see the status word only every other cycle; some rounds freeze it long
          // enough for a timeout, or show once a word that decodes to no state.
          const bool frozen = round % 6 == 3 && cycle >= 1 && cycle < 15;
          if (!frozen && (round % 2 == 0 || cycle % 2 == 0)) status = out.status_word;
          if (round % 10 == 9 && cycle == 5) status = 0x0201;
          if (m.outcome() == master_outcome::reached) ++reached;
          sink += cw + static_cast<std::uint32_t>(m.outcome());
        }
        if (round % 4 == 3) m.clear_target();
        sink += m.step(status, now);
      }
    });
    EXPECT_EQ(calls, 0) << p.name;
    EXPECT_GT(reached, 0) << p.name << ": the loop reached targets";
    EXPECT_NE(sink, 0u);
  }
}

}  // namespace
}  // namespace cia402
