// `cia402 replay` on every built-in profile: what all share (power-up, enable, fault and reset) and
// what each seed says differently about quick stop. Control words are written from the seeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <string>

#include "cia402/profile.hpp"
#include "replay_support.hpp"

namespace cia402 {
namespace {

using test::replay;
using test::settled;

// A profile's name as a test's name: gtest takes no '-'.
std::string test_name(std::string profile) {
  std::replace(profile.begin(), profile.end(), '-', '_');
  return profile;
}

// The words each profile is enabled with: seed 004_e07fd68605b3a8c6.txt needs bit 4 (fast stop,
// active low) set as well, the others bits 0..3 alone.
struct profile_words {
  const char* name;
  const char* enable;  ///< Enable operation
};

class every_profile : public ::testing::TestWithParam<profile_words> {};

TEST_P(every_profile, power_up_takes_t0_and_t1_to_switch_on_disabled) {
  const auto r = replay(GetParam().name, "");
  EXPECT_EQ(r.exit_code, 0);
  ASSERT_EQ(r.lines.size(), 1u);
  EXPECT_EQ(r.lines[0], test::power_up);
}

TEST_P(every_profile, shutdown_then_enable_operation_takes_t2_then_t3_and_t4) {
  const auto r = replay(GetParam().name, std::string("cw 0x06\ncw ") + GetParam().enable + "\n");
  ASSERT_EQ(r.lines.size(), 3u);
  EXPECT_EQ(r.lines[1], settled("READY_TO_SWITCH_ON", test::rtso, "2"));
  EXPECT_EQ(r.lines[2], settled("OPERATION_ENABLED", test::oe, "3,4"));
}

TEST_P(every_profile, fault_in_operation_enabled_takes_t13_t14_and_reset_after_clear_takes_t15) {
  const std::string enable = std::string("cw 0x06\ncw ") + GetParam().enable + "\n";
  const auto r =
      replay(GetParam().name, enable + "fault\ncw 0x00\ncw 0x80\nclear\ncw 0x00\ncw 0x80\n");
  ASSERT_EQ(r.lines.size(), 9u);
  EXPECT_EQ(r.lines[3], settled("FAULT", test::fault, "13,14"));
  EXPECT_EQ(r.lines[5], settled("FAULT", test::fault, ""));  // cause still present (S2)
  EXPECT_EQ(r.lines[8], settled("SWITCH_ON_DISABLED", test::sod, "15"));
}

TEST_P(every_profile, operation_enabled_disable_voltage_takes_t9) {
  const auto r =
      replay(GetParam().name, std::string("cw 0x06\ncw ") + GetParam().enable + "\ncw 0x00\n");
  EXPECT_EQ(r.lines.at(3), settled("SWITCH_ON_DISABLED", test::sod, "9"));
}

TEST_P(every_profile, unsupported_set_is_refused_and_the_replay_goes_on) {
  const auto r = replay(GetParam().name, "set 0x605A 15\ncw 0x06\n");
  ASSERT_EQ(r.lines.size(), 3u);
  EXPECT_EQ(r.lines[1].rfind("{\"error\":\"set 0x605A 15 refused: SDO abort 0x0", 0), 0u)
      << r.lines[1];
  EXPECT_EQ(r.lines[2], settled("READY_TO_SWITCH_ON", test::rtso, "2"));
}

INSTANTIATE_TEST_SUITE_P(builtin, every_profile,
                         ::testing::Values(profile_words{"cia402", "0x0F"},
                                           profile_words{"no-quick-stop", "0x0F"},
                                           profile_words{"lexium32", "0x0F"},
                                           profile_words{"s300-profibus", "0x0F"},
                                           profile_words{"ax2000-profibus", "0x1F"}),
                         [](const auto& info) { return test_name(info.param.name); });

TEST(replay_profiles, every_builtin_is_listed_in_the_every_profile_suite) {
  // The suite above names the profiles by hand; a new built-in must be added there.
  const char* covered[] = {"cia402", "no-quick-stop", "lexium32", "s300-profibus",
                           "ax2000-profibus"};
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const std::string name = builtin_profile(i).name;
    EXPECT_NE(std::find(std::begin(covered), std::end(covered), name), std::end(covered)) << name;
  }
}

// --- the profiles whose quick stop holds in QUICK STOP ACTIVE -----------------------------------
// Each seed's words: the quick stop (fast stop) taken from OPERATION ENABLED by T11, Enable
// operation back by T16, and the word that leaves the quick stop for SWITCH ON DISABLED.
struct holding_quick_stop {
  const char* name;
  const char* enable;      ///< Enable operation
  const char* quick_stop;  ///< Quick stop (fast stop) from OPERATION ENABLED
  const char* leave;       ///< the word that ends the quick stop in SWITCH ON DISABLED
  const char* leave_transition;
};

class quick_stop_holds : public ::testing::TestWithParam<holding_quick_stop> {};

TEST_P(quick_stop_holds, in_quick_stop_active_by_t11_and_enable_operation_takes_t16) {
  const holding_quick_stop& p = GetParam();
  const auto r = replay(p.name, std::string("cw 0x06\ncw ") + p.enable + "\ncw " + p.quick_stop +
                                    "\ncw " + p.enable + "\n");
  EXPECT_EQ(r.lines.at(3), settled("QUICK_STOP_ACTIVE", test::qsa_standstill, "11"));
  EXPECT_EQ(r.lines.at(4), settled("OPERATION_ENABLED", test::oe, "16"));
}

TEST_P(quick_stop_holds, its_leaving_word_in_quick_stop_active_ends_in_switch_on_disabled_at_once) {
  const holding_quick_stop& p = GetParam();
  const auto r = replay(p.name, std::string("cw 0x06\ncw ") + p.enable + "\ncw " + p.quick_stop +
                                    "\ncw " + p.leave + "\n");
  EXPECT_EQ(r.lines.at(4), settled("SWITCH_ON_DISABLED", test::sod, p.leave_transition));
}

INSTANTIATE_TEST_SUITE_P(
    builtin, quick_stop_holds,
    ::testing::Values(
        // seed 001_f9323c8e43dc977c.txt: Disable voltage takes T12.
        holding_quick_stop{"lexium32", "0x0F", "0x0B", "0x00", "12"},
        // seed 003_83442f2f4b0b2bb9.txt: fast stop on bit 2 cleared, T16 on bit 2 set; bit 1
        // cleared in fast stop takes T12.
        holding_quick_stop{"s300-profibus", "0x0F", "0x0B", "0x09", "12"},
        // seed 004_e07fd68605b3a8c6.txt: fast stop on bit 4 cleared, T16 on bit 4 set; bit 2
        // cleared in fast stop takes T17.
        holding_quick_stop{"ax2000-profibus", "0x1F", "0x0F", "0x0B", "17"}),
    [](const auto& info) { return test_name(info.param.name); });

// --- no-quick-stop, seed 000_44b471b7401b86be.txt: "'Quick Stop' is not supported" -------------

TEST(replay_no_quick_stop, quick_stop_in_operation_enabled_never_reaches_quick_stop_active) {
  const auto r = replay("no-quick-stop", "cw 0x06\ncw 0x0F\ncw 0x0B\n");
  EXPECT_EQ(r.lines.at(3), settled("SWITCH_ON_DISABLED", test::sod, "9"));
}

TEST(replay_no_quick_stop, quick_stop_in_switched_on_takes_t10_as_the_seed_prints) {
  EXPECT_EQ(replay("no-quick-stop", "cw 0x06\ncw 0x07\ncw 0x02\n").lines.at(3),
            settled("SWITCH_ON_DISABLED", test::sod, "10"));
}

TEST(replay_no_quick_stop, quick_stop_option_object_does_not_exist) {
  const auto r = replay("no-quick-stop", "set 0x605A 2\n");
  EXPECT_NE(r.lines.at(1).find("0x06020000"), std::string::npos) << r.lines.at(1);
}

// --- lexium32, seed 001_f9323c8e43dc977c.txt ---------------------------------------------------

TEST(replay_lexium32, class_3_fault_goes_straight_through_to_fault) {
  EXPECT_EQ(replay("lexium32", "cw 0x06\ncw 0x0F\nfault 0x2310 3\n").lines.at(3),
            settled("FAULT", test::fault, "13,14"));
}

TEST(replay_lexium32, class_0_error_does_not_interrupt_operation) {
  const auto r = replay("lexium32", "cw 0x06\ncw 0x0F\nfault 0x2310 0\n");
  EXPECT_NE(r.lines.at(3).find("\"state\":\"OPERATION_ENABLED\""), std::string::npos)
      << r.lines.at(3);
  EXPECT_NE(r.lines.at(3).find("\"transitions\":[]"), std::string::npos) << r.lines.at(3);
}

TEST(replay_lexium32, class_4_fault_is_not_reset_by_fault_reset_even_after_clear) {
  // Lexium 32 error class 4: power cycle only (cia402-reference.md §6.3).
  const auto r = replay("lexium32", "fault 0x2310 4\nclear\ncw 0x80\n");
  EXPECT_EQ(r.lines.at(3), settled("FAULT", test::fault, ""));
}

// Seed 001 T11: "Error of error class 1" -> QUICK STOP ACTIVE; T16 by Enable Operation is "possible
// only if operating state was triggered via the fieldbus" (footnote 3). Disabled: the built-in's
// T16 row fires on the Enable operation level while the class-1 cause persists, so T11 and T16
// alternate every cycle (reported to the lead; src/core/profiles/lexium32.cpp, first T16 row).
TEST(replay_lexium32, class_1_error_in_operation_enabled_quick_stops_and_holds) {
  const auto r = replay("lexium32", "cw 0x06\ncw 0x0F\nfault 0x2310 1\nclear\ncw 0x8F\n");
  ASSERT_EQ(r.lines.size(), 6u);
  EXPECT_TRUE(line_names(r, 3, {"\"state\":\"QUICK_STOP_ACTIVE\"", "\"transitions\":[11]"}));
  // Cause gone, Enable operation still commanded: no T16 for a quick stop a fault started.
  EXPECT_TRUE(line_names(r, 4, {"\"transitions\":[]"}));
  // Seed 001 T16: "a Fault Reset causes a direct transition to ... 6 Operation Enabled".
  EXPECT_EQ(r.lines[5], settled("OPERATION_ENABLED", test::oe, "16"));
}

// --- s300-profibus, seed 003_83442f2f4b0b2bb9.txt: fast stop on bit 2 -------------------------

TEST(replay_s300, option_objects_do_not_exist_on_profibus) {
  EXPECT_NE(replay("s300-profibus", "set 0x605A 6\n").lines.at(1).find("0x06020000"),
            std::string::npos);
}

// --- ax2000-profibus, seed 004_e07fd68605b3a8c6.txt: fast stop on bit 4, T17 on bit 2 ----------

TEST(replay_ax2000, bit_2_cleared_in_operation_enabled_takes_t17_to_switch_on_disabled) {
  EXPECT_EQ(replay("ax2000-profibus", "cw 0x06\ncw 0x1F\ncw 0x1B\n").lines.at(3),
            settled("SWITCH_ON_DISABLED", test::sod, "17"));
}

}  // namespace
}  // namespace cia402
