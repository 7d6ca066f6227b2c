// The ordinary cycles of the standard profile (profile::ordinary_entry, and the tables compiled from
// it, profile::ordinary), written from seed 002's table: which transitions an ordinary cycle takes at
// once, which it leaves to the full step, and that the step taking them does what the full step does. The model check proves the equality on
// every reachable pair; these pin the table's reading of the rows, which it cannot see.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <initializer_list>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "test_support.hpp"

namespace cia402 {
namespace {

std::uint8_t entry(const profile& p, state s, command c) {
  return p.ordinary_entry(static_cast<int>(s), static_cast<unsigned>(c));
}

// The transition number of the row an entry fires, or no_transition for a quiet entry.
int fired_transition(const profile& p, state s, command c) {
  const unsigned row = entry(p, s, c) & ordinary::row;
  return row == 0 ? no_transition : p.rows[row - 1].number;
}

// Steps two axes through `words`, one by step() on `p`, the other by the full step on `full`: the
// outputs and the axes are the same after every word. The axis step() left.
axis expect_step_is_full_step(const profile& p, const profile& full,
                              std::initializer_list<std::uint16_t> words) {
  axis a = make_axis(p);
  axis b = a;
  drive_inputs in;
  for (const std::uint16_t cw : words) {
    in.control_word = cw;
    const drive_outputs x = step(p, a, in);
    const drive_outputs y = detail::full_step(full, b, in);
    EXPECT_TRUE(test::same_outputs(x, y)) << "control word 0x" << std::hex << cw;
    EXPECT_EQ(std::memcmp(&a, &b, sizeof(axis)), 0) << "control word 0x" << std::hex << cw;
  }
  return a;
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
  const axis a = expect_step_is_full_step(p, p, {0x00, 0x00, 0x06, 0x07, 0x0F, 0x80, 0x06, 0x0F, 0x02});
  EXPECT_EQ(a.current, state::switch_on_disabled);  // the last word, Quick stop in SWITCHED ON: T10
}

// The compiled entry of a key: the state, a control word (its command and bit 7) and the axis's
// flags fault_reset_bit and torque_on.
struct compiled_entry {
  std::uint32_t keep, set;
  std::uint64_t image;
};
compiled_entry compiled(const profile& p, state s, std::uint16_t cw, bool reset_before, bool torque_before) {
  const unsigned axis_key = static_cast<unsigned>(s) | (reset_before ? 1u << 8 : 0u) | (torque_before ? 1u << 9 : 0u);
  const std::size_t at = ordinary_tables::offset_of(axis_key) + p.ordinary->row_offset[cw & 0xFFu];
  return {p.ordinary->axis_words[at / 4], p.ordinary->axis_words[at / 4 + 1], p.ordinary->images[at / 8]};
}
bool to_full_step(const compiled_entry& e) {
  return ((e.keep >> detail::byte_shift<4>(2)) & ordinary_action::full) != 0;
}

TEST(ordinary_tables, every_built_in_profile_has_them_compiled_with_it) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    ASSERT_NE(p.ordinary, nullptr) << p.name;
    ordinary_tables again{};
    p.compile_ordinary(again);
    EXPECT_EQ(std::memcmp(&again, p.ordinary, sizeof again), 0) << p.name << ": compiled anew at run time";
  }
}

TEST(ordinary_tables, a_stop_with_torque_on_starts_in_the_table_and_a_reset_edge_where_a_row_reads_it_goes_to_the_full_step) {
  const profile& p = standard_profile();
  // T5 (Switch on in OPERATION ENABLED) ramps first where torque was on (S7), else fires at once.
  const compiled_entry starts = compiled(p, state::operation_enabled, 0x07, false, true);
  const unsigned actions = (starts.keep >> detail::byte_shift<4>(2)) & 0xFFu;
  EXPECT_NE(actions & ordinary_action::stop_starts, 0u);
  EXPECT_NE(actions & ordinary_action::stop_code_605c, 0u) << "T5's stop reads 0x605C";
  const unsigned pending = (starts.set >> detail::byte_shift<4>(2)) & 0xFFu;
  ASSERT_LT(pending, p.row_count);
  EXPECT_EQ(p.rows[pending].number, 5);
  const compiled_entry t5 = compiled(p, state::operation_enabled, 0x07, false, false);
  ASSERT_FALSE(to_full_step(t5));
  EXPECT_EQ((t5.set >> detail::byte_shift<4>(1)) & 0xFFu, static_cast<unsigned>(state::switched_on));
  EXPECT_EQ((t5.image >> detail::byte_shift<8>(4)) & 0xFFu, 5u) << "the image's transition";
  // FAULT: bit 7 rising is T15's fault reset; bit 7 held (its flag set before) is quiet.
  EXPECT_TRUE(to_full_step(compiled(p, state::fault, 0x80, false, false)));
  const compiled_entry held = compiled(p, state::fault, 0x80, true, false);
  ASSERT_FALSE(to_full_step(held));
  EXPECT_EQ((held.set >> detail::byte_shift<4>(0)) & axis_flag::fault_reset_bit, axis_flag::fault_reset_bit)
      << "bit 7 kept for the next cycle's edge";
  // QUICK STOP ACTIVE stops by 0x605A in every cycle: its cycles take the rare path (stop words).
  EXPECT_TRUE(to_full_step(compiled(p, state::quick_stop_active, 0x0F, false, true)));
}

// T5 under torque by the table: with 0x605C = 1 the stop starts (the pending row is T5's, the state
// stays until standstill), with 0 the state changes at once; each as the full step does.
TEST(ordinary_tables, the_stop_of_t5_starts_by_0x605c_as_the_full_step_starts_it) {
  const profile& p = standard_profile();
  for (const std::int8_t code : {std::int8_t{1}, std::int8_t{0}}) {
    axis a = make_axis(p);
    drive_inputs in;
    for (const std::uint16_t cw : {0x00, 0x00, 0x06, 0x07, 0x0F}) {
      in.control_word = cw;
      step(p, a, in);
    }
    ASSERT_EQ(a.current, state::operation_enabled);
    ASSERT_EQ(write_option(p, a, 0x605C, code), sdo_abort::none);
    in.control_word = 0x07;
    in.standstill = false;
    axis by_full = a;
    drive_outputs quiet{};
    axis by_quiet = a;
    EXPECT_EQ(detail::quiet_step(p, by_quiet, in, quiet), code == 1) << "0x605C = " << int{code};
    const drive_outputs x = step(p, a, in);
    const drive_outputs y = detail::full_step(p, by_full, in);
    EXPECT_TRUE(test::same_outputs(x, y));
    EXPECT_EQ(std::memcmp(&a, &by_full, sizeof(axis)), 0);
    EXPECT_EQ(a.current, code == 1 ? state::operation_enabled : state::switched_on);
    EXPECT_EQ(stop_running(a), code == 1);
    EXPECT_EQ(x.torque, code == 1) << "the ramp runs with torque on";
  }
}

// The cycles of a running stop by the tables, each as the full step has it: T11 and QUICK STOP
// ACTIVE by the default 0x605A (cia402's 2 ends the state at standstill, T12; lexium32's 6 holds it
// and shows bit 10), and T5's ramp while the shaft turns and once it stands. With another 0x605A
// than the default the quick stop's start is the full step's.
TEST(ordinary_tables, a_running_stop_and_quick_stop_active_are_answered_by_the_tables) {
  struct cycle {
    std::uint16_t cw;
    bool standstill;
    bool answered;  // by detail::quiet_step, without the full step
  };
  const auto run = [](const profile& p, std::int8_t quick_stop_code, std::initializer_list<cycle> cycles) {
    axis a = make_axis(p);
    drive_inputs in;
    for (const std::uint16_t cw : {0x00, 0x00, 0x06, 0x07, 0x0F}) {
      in.control_word = cw;
      step(p, a, in);
    }
    ASSERT_EQ(write_option(p, a, 0x605A, quick_stop_code), sdo_abort::none);
    for (const cycle& c : cycles) {
      in.control_word = c.cw;
      in.standstill = c.standstill;
      axis by_quiet = a, by_full = a;
      drive_outputs quiet{};
      EXPECT_EQ(detail::quiet_step(p, by_quiet, in, quiet), c.answered)
          << p.name << " 0x" << std::hex << c.cw << " in " << state_name(a.current);
      const drive_outputs x = step(p, a, in);
      const drive_outputs y = detail::full_step(p, by_full, in);
      EXPECT_TRUE(test::same_outputs(x, y)) << p.name << " 0x" << std::hex << c.cw;
      EXPECT_EQ(std::memcmp(&a, &by_full, sizeof(axis)), 0) << p.name << " 0x" << std::hex << c.cw;
    }
    EXPECT_EQ(a.current, state::switched_on) << p.name;
  };
  const profile& standard = standard_profile();
  const profile& lexium = *find_builtin_profile("lexium32");
  // T11, the ramp, T12 at standstill (0x605A = 2), T2, T3, T4; then T5's ramp and its end.
  run(standard, 2, {{0x0B, false, true}, {0x0B, false, true}, {0x0B, true, true}, {0x06, true, true},
                    {0x07, true, true}, {0x0F, true, true}, {0x07, false, true}, {0x07, false, true},
                    {0x07, true, true}});
  // T11, the ramp, the state held at standstill (0x605A = 6), T16 by Enable operation, T5.
  run(lexium, 6, {{0x0B, false, true}, {0x0B, true, true}, {0x0B, true, true}, {0x0F, true, true},
                  {0x07, false, true}, {0x07, true, true}});
  // 0x605A = 6 where the default is 2: the quick stop is the full step's from its start.
  run(standard, 6, {{0x0B, false, false}, {0x0B, true, false}, {0x0F, true, false}, {0x07, true, true},
                    {0x07, true, true}});
}

TEST(ordinary_tables, a_profile_finalized_without_tables_steps_by_the_full_step_alone) {
  profile p = standard_profile();
  p.finalize();
  EXPECT_EQ(p.ordinary, nullptr);
  expect_step_is_full_step(p, standard_profile(), {0x00, 0x00, 0x06, 0x07, 0x0F, 0x07, 0x0F, 0x0B, 0x00});
}

TEST(ordinary_tables, a_copied_custom_profile_points_at_its_own_tables) {
  custom_profile c(standard_profile());
  ASSERT_NE(c.get().ordinary, nullptr);
  const custom_profile copy = c;
  EXPECT_NE(copy.get().ordinary, c.get().ordinary);
  EXPECT_EQ(std::memcmp(copy.get().ordinary, c.get().ordinary, sizeof(ordinary_tables)), 0);
  custom_profile assigned;
  assigned = c;
  EXPECT_NE(assigned.get().ordinary, c.get().ordinary);
  EXPECT_EQ(std::memcmp(assigned.get().ordinary, standard_profile().ordinary, sizeof(ordinary_tables)), 0);
}

}  // namespace
}  // namespace cia402
