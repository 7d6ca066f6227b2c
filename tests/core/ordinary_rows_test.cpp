// The ordinary-cycle table (profile::ordinary_rows) of the standard profile, written from seed 002's
// table: which transitions an ordinary cycle takes at once, which it leaves to the full step, and
// that the step taking them does what the full step does. The model check proves the equality on
// every reachable pair; these pin the table's reading of the rows, which it cannot see.
#include <gtest/gtest.h>

#include <array>
#include <cstring>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "test_support.hpp"

namespace cia402 {
namespace {

std::uint8_t entry(const profile& p, state s, command c) {
  return p.ordinary_rows[profile::ordinary_index(static_cast<int>(s), static_cast<unsigned>(c))];
}

// The transition number of the row an entry fires, or no_transition for a quiet entry.
int fired_transition(const profile& p, state s, command c) {
  const unsigned row = entry(p, s, c) & ordinary::row;
  return row == 0 ? no_transition : p.rows[row - 1].number;
}

TEST(ordinary_rows, the_standard_profile_fires_the_immediate_transitions_from_its_table) {
  const profile& p = standard_profile();
  EXPECT_EQ(fired_transition(p, state::start, command::enable_operation), 0);
  EXPECT_EQ(fired_transition(p, state::not_ready_to_switch_on, command::disable_voltage), 1);
  EXPECT_EQ(fired_transition(p, state::switch_on_disabled, command::shutdown), 2);
  EXPECT_EQ(fired_transition(p, state::ready_to_switch_on, command::switch_on), 3);
  EXPECT_EQ(fired_transition(p, state::ready_to_switch_on, command::enable_operation), 3);  // S3
  EXPECT_EQ(fired_transition(p, state::switched_on, command::enable_operation), 4);
  EXPECT_EQ(fired_transition(p, state::switched_on, command::shutdown), 6);
  EXPECT_EQ(fired_transition(p, state::ready_to_switch_on, command::disable_voltage), 7);
  EXPECT_EQ(fired_transition(p, state::operation_enabled, command::disable_voltage), 9);
  EXPECT_EQ(fired_transition(p, state::switched_on, command::quick_stop), 10);
  EXPECT_EQ(fired_transition(p, state::operation_enabled, command::enable_operation), no_transition);
  EXPECT_EQ(fired_transition(p, state::switch_on_disabled, command::enable_operation), no_transition);
}

TEST(ordinary_rows, stops_and_stopping_states_are_left_to_the_full_step) {
  const profile& p = standard_profile();
  // T5 and T8 run a stop first where torque is on (S7).
  EXPECT_EQ(fired_transition(p, state::operation_enabled, command::switch_on), 5);
  EXPECT_NE(entry(p, state::operation_enabled, command::switch_on) & ordinary::stops, 0);
  EXPECT_EQ(fired_transition(p, state::operation_enabled, command::shutdown), 8);
  EXPECT_NE(entry(p, state::operation_enabled, command::shutdown) & ordinary::stops, 0);
  EXPECT_EQ(entry(p, state::operation_enabled, command::disable_voltage) & ordinary::stops, 0);
  // T11 goes to QUICK STOP ACTIVE, which stops by 0x605A; that state and FAULT REACTION ACTIVE
  // are the full step's in every cycle.
  EXPECT_EQ(entry(p, state::operation_enabled, command::quick_stop), ordinary::full);
  for (int c = 0; c < command_count; ++c) {
    EXPECT_EQ(entry(p, state::quick_stop_active, static_cast<command>(c)), ordinary::full);
    EXPECT_EQ(entry(p, state::fault_reaction_active, static_cast<command>(c)), ordinary::full);
    // FAULT is left only by T15's fault reset: quiet but for an edge.
    EXPECT_EQ(entry(p, state::fault, static_cast<command>(c)), ordinary::reset_reads);
  }
}

TEST(ordinary_rows, a_profile_with_a_changed_row_gets_a_changed_table_at_finalize) {
  // A user profile where Shutdown from SWITCH ON DISABLED is no longer T2: the table follows.
  custom_profile c(standard_profile());
  std::array<transition_row, max_rows> rows{};
  std::size_t n = 0;
  for (std::size_t i = 0; i < c.get().row_count; ++i) {
    if (c.get().row(i).number != 2) rows[n++] = c.get().row(i);
  }
  ASSERT_TRUE(c.set_rows(rows.data(), n));
  c.finalize();
  EXPECT_EQ(fired_transition(c.get(), state::switch_on_disabled, command::shutdown), no_transition);
  EXPECT_EQ(fired_transition(c.get(), state::ready_to_switch_on, command::switch_on), 3);
}

TEST(ordinary_rows, an_ordinary_transition_through_the_profile_equals_the_full_step) {
  const profile& p = standard_profile();
  axis a = make_axis(p);
  axis b = a;
  drive_inputs in;
  for (const std::uint16_t cw : {0x00, 0x00, 0x06, 0x07, 0x0F, 0x80, 0x06, 0x0F, 0x02}) {
    in.control_word = cw;
    const drive_outputs x = step(p, a, in);
    const drive_outputs y = detail::full_step(p, b, in);
    EXPECT_TRUE(test::same_outputs(x, y)) << "control word 0x" << std::hex << cw;
    EXPECT_EQ(std::memcmp(&a, &b, sizeof(axis)), 0) << "control word 0x" << std::hex << cw;
  }
  EXPECT_EQ(a.current, state::switch_on_disabled);  // the last word, Quick stop in SWITCHED ON: T10
}

}  // namespace
}  // namespace cia402
