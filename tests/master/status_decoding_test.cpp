// Status-word decoding and command encoding against the tables of cia402-reference.md §1.1 and
// §2.2, written out here rather than read from the code under test.
#include <gtest/gtest.h>

#include <random>

#include "cia402/master.hpp"

namespace {

using cia402::command;
using cia402::state;

struct status_row {
  state s;
  std::uint16_t mask;
  std::uint16_t value;
};

// cia402-reference.md §1.1: bit 5 is don't care in NRTSO, SOD, FRA and FAULT (mask 0x4F).
constexpr status_row standard_status[] = {
    {state::not_ready_to_switch_on, 0x4F, 0x00}, {state::switch_on_disabled, 0x4F, 0x40},
    {state::ready_to_switch_on, 0x6F, 0x21},     {state::switched_on, 0x6F, 0x23},
    {state::operation_enabled, 0x6F, 0x27},      {state::quick_stop_active, 0x6F, 0x07},
    {state::fault_reaction_active, 0x4F, 0x0F},  {state::fault, 0x4F, 0x08},
};

TEST(status_decoding, every_status_word_decodes_as_the_reference_table_says_on_every_profile) {
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile& p = cia402::builtin_profile(i);
    for (unsigned word = 0; word <= 0xFFFF; ++word) {
      const status_row* expected = nullptr;
      for (const status_row& r : standard_status) {
        if ((word & r.mask) == r.value) expected = &r;
      }
      state got = state::start;
      const bool ok = cia402::decode_status(p, static_cast<std::uint16_t>(word), got);
      ASSERT_EQ(ok, expected != nullptr) << p.name << " word 0x" << std::hex << word;
      if (expected) {
        ASSERT_EQ(got, expected->s) << p.name << " word 0x" << std::hex << word;
      }
    }
  }
}

TEST(status_decoding, bit_5_is_dont_care_in_four_states_only) {
  const cia402::profile& p = cia402::standard_profile();
  EXPECT_EQ(cia402::status_mask(p, state::not_ready_to_switch_on), 0x4F);
  EXPECT_EQ(cia402::status_mask(p, state::switch_on_disabled), 0x4F);
  EXPECT_EQ(cia402::status_mask(p, state::fault_reaction_active), 0x4F);
  EXPECT_EQ(cia402::status_mask(p, state::fault), 0x4F);
  EXPECT_EQ(cia402::status_mask(p, state::ready_to_switch_on), 0x6F);
  EXPECT_EQ(cia402::status_mask(p, state::operation_enabled), 0x6F);
  EXPECT_EQ(cia402::status_mask(p, state::quick_stop_active), 0x6F);
}

TEST(command_encoding, standard_commands_are_the_reference_words) {
  // cia402-reference.md §2.2 (the values PYCO writes).
  const cia402::profile& p = cia402::standard_profile();
  const std::pair<command, std::uint16_t> expected[] = {
      {command::shutdown, 0x06},        {command::switch_on, 0x07},
      {command::enable_operation, 0x0F}, {command::disable_voltage, 0x00},
      {command::quick_stop, 0x02},
  };
  for (const auto& [c, word] : expected) {
    std::uint16_t got = 0xFFFF;
    ASSERT_TRUE(cia402::encode_command(p, c, 0, got)) << cia402::command_name(c);
    EXPECT_EQ(got, word) << cia402::command_name(c);
  }
  std::uint16_t unused = 0;
  EXPECT_FALSE(cia402::encode_command(p, command::stop_and_inhibit, 0, unused));
}

TEST(command_encoding, ax2000_fast_stop_clears_bit_4_and_enable_sets_it) {
  const cia402::profile& p = *cia402::find_builtin_profile("ax2000-profibus");
  std::uint16_t w = 0;
  ASSERT_TRUE(cia402::encode_command(p, command::enable_operation, 0, w));
  EXPECT_EQ(w, 0x1F);
  ASSERT_TRUE(cia402::encode_command(p, command::quick_stop, 0, w));
  EXPECT_EQ(w, 0x0F);
  ASSERT_TRUE(cia402::encode_command(p, command::stop_and_inhibit, 0, w));
  EXPECT_EQ(w & 0x06, 0x02);  // bit 1 set, bit 2 cleared
}

TEST(command_encoding, bits_the_machine_does_not_own_are_kept_and_bit_7_is_cleared) {
  std::mt19937 rng(402);
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile& p = cia402::builtin_profile(i);
    const std::uint16_t owned = cia402::owned_control_bits(p);
    EXPECT_TRUE(owned & 0x80) << p.name;
    EXPECT_FALSE(owned & 0x100) << p.name << ": halt belongs to the application";
    for (int n = 0; n < 2000; ++n) {
      const auto keep = static_cast<std::uint16_t>(rng());
      for (int c = 0; c < cia402::command_count; ++c) {
        std::uint16_t w = 0;
        if (!cia402::encode_command(p, static_cast<command>(c), keep, w)) continue;
        ASSERT_EQ(w & ~owned, keep & ~owned) << p.name;
        ASSERT_EQ(w & 0x80, 0) << p.name;
        ASSERT_EQ(p.decode(w), static_cast<command>(c)) << p.name;
      }
    }
  }
}

}  // namespace
