// The transition numbers the page infers for a remote drive from the states it observes. Expected
// numbers are the standard's (cia402-reference.md §1.3, seed 002_522d2c0bb8f5a5f8.txt) and seed
// 004_e07fd68605b3a8c6.txt's T17, not taken from the code.
#include <gtest/gtest.h>

#include <vector>

#include "cia402/master.hpp"
#include "cia402/page/transition_inference.hpp"
#include "cia402/profile.hpp"

namespace {

using cia402::command;
using cia402::state;
using cia402::page::infer_transitions;
using cia402::page::observer_facts;

// Standard control words (cia402-reference.md §2.2), written out rather than encoded by the code.
constexpr std::uint16_t shutdown_word = 0x06;
constexpr std::uint16_t switch_on_word = 0x07;
constexpr std::uint16_t enable_operation_word = 0x0F;
constexpr std::uint16_t disable_voltage_word = 0x00;
constexpr std::uint16_t quick_stop_word = 0x02;

std::vector<int> numbers(const cia402::profile& p, state from, state to, std::uint16_t word,
                         bool reset_edge = false) {
  std::vector<int> out;
  for (const auto& t : infer_transitions(p, from, to, observer_facts(p, word, reset_edge))) {
    out.push_back(t.number);
  }
  return out;
}

const cia402::profile& standard() { return cia402::standard_profile(); }

TEST(transition_inference, single_rows_of_the_standard_are_found_from_their_ends) {
  EXPECT_EQ(numbers(standard(), state::switch_on_disabled, state::ready_to_switch_on, shutdown_word),
            std::vector<int>{2});
  EXPECT_EQ(numbers(standard(), state::ready_to_switch_on, state::switched_on, switch_on_word),
            std::vector<int>{3});
  EXPECT_EQ(numbers(standard(), state::switched_on, state::operation_enabled, enable_operation_word),
            std::vector<int>{4});
  EXPECT_EQ(numbers(standard(), state::operation_enabled, state::switch_on_disabled,
                    disable_voltage_word),
            std::vector<int>{9});
  EXPECT_EQ(numbers(standard(), state::fault, state::switch_on_disabled, enable_operation_word, true),
            std::vector<int>{15});
  EXPECT_EQ(numbers(standard(), state::operation_enabled, state::fault_reaction_active,
                    enable_operation_word),
            std::vector<int>{13});
  EXPECT_EQ(numbers(standard(), state::fault_reaction_active, state::fault, enable_operation_word),
            std::vector<int>{14});
}

TEST(transition_inference, a_missed_state_in_between_gives_the_shortest_chain) {
  // S3: Enable operation in READY TO SWITCH ON runs T3 then T4 in consecutive cycles; an observer
  // sampling status words may see only the two ends.
  EXPECT_EQ(numbers(standard(), state::ready_to_switch_on, state::operation_enabled,
                    enable_operation_word),
            (std::vector<int>{3, 4}));
  EXPECT_EQ(numbers(standard(), state::operation_enabled, state::fault, enable_operation_word),
            (std::vector<int>{13, 14}));
  const auto chain = infer_transitions(standard(), state::ready_to_switch_on,
                                       state::operation_enabled,
                                       observer_facts(standard(), enable_operation_word, false));
  ASSERT_EQ(chain.size(), 2u);
  EXPECT_EQ(chain[0].from, state::ready_to_switch_on);
  EXPECT_EQ(chain[0].to, state::switched_on);
  EXPECT_EQ(chain[1].from, state::switched_on);
  EXPECT_EQ(chain[1].to, state::operation_enabled);
}

TEST(transition_inference, same_state_or_no_chain_of_three_rows_gives_nothing) {
  EXPECT_TRUE(numbers(standard(), state::switched_on, state::switched_on, switch_on_word).empty());
  // SWITCH ON DISABLED to QUICK STOP ACTIVE needs T2, T3, T4, T11: four rows.
  EXPECT_TRUE(numbers(standard(), state::switch_on_disabled, state::quick_stop_active,
                      quick_stop_word)
                  .empty());
}

TEST(transition_inference, quick_stop_in_switched_on_is_t10_and_quick_stop_end_is_t12) {
  EXPECT_EQ(numbers(standard(), state::switched_on, state::switch_on_disabled, quick_stop_word),
            std::vector<int>{10});
  EXPECT_EQ(numbers(standard(), state::quick_stop_active, state::switch_on_disabled,
                    quick_stop_word),
            std::vector<int>{12});
}

TEST(transition_inference, two_rows_with_the_same_ends_are_told_apart_by_the_last_command) {
  // Seed 004_e07fd68605b3a8c6.txt: OPERATION ENABLED -> SWITCH ON DISABLED is T9 (disable voltage)
  // or T17 (bit 2 cleared: fast stop, switch-on inhibited).
  const cia402::profile* ax = cia402::find_builtin_profile("ax2000-profibus");
  ASSERT_NE(ax, nullptr);
  std::uint16_t dv = 0;
  std::uint16_t inhibit = 0;
  ASSERT_TRUE(cia402::encode_command(*ax, command::disable_voltage, 0, dv));
  ASSERT_TRUE(cia402::encode_command(*ax, command::stop_and_inhibit, 0, inhibit));
  EXPECT_EQ(numbers(*ax, state::operation_enabled, state::switch_on_disabled, dv),
            std::vector<int>{9});
  EXPECT_EQ(numbers(*ax, state::operation_enabled, state::switch_on_disabled, inhibit),
            std::vector<int>{17});
}

}  // namespace
