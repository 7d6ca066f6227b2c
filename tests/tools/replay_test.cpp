// `cia402 replay` on the standard profile: the interface and the behaviour semantics.md defines.
// Expected lines are written from docs/semantics.md (S1..S17) and the status-word table, not from
// output.
#include "cli/replay.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cia402/profile_file.hpp"
#include "../profile_file/helpers.hpp"
#include "replay_support.hpp"

namespace cia402 {
namespace {

using test::replay;
using test::settled;

constexpr const char* enable = "cw 0x06\ncw 0x0F\n";

// Replays whose lines say it all: the events, how many lines replay prints (0: not counted) and
// the settled lines expected at their places.
struct replay_case {
  const char* name;
  std::string events;
  std::size_t line_count;
  std::vector<std::pair<std::size_t, std::string>> expected;
};

const std::vector<replay_case>& settled_cases() {
  static const std::vector<replay_case> all = {
    {"shutdown_then_enable_operation_takes_t2_then_t3_and_t4_to_0x0237",
     enable, 3,
     {{1, settled("READY_TO_SWITCH_ON", test::rtso, "2")},
      {2, settled("OPERATION_ENABLED", test::oe, "3,4")}}},
    {"switch_on_then_enable_operation_takes_t3_then_t4",
     "cw 0x06\ncw 0x07\ncw 0x0F\n", 4,
     {{2, settled("SWITCHED_ON", test::so, "3")},
      {3, settled("OPERATION_ENABLED", test::oe, "4")}}},
    {"operation_enabled_quick_stop_code_2_ramps_and_ends_in_switch_on_disabled",
     std::string(enable) + "cw 0x0B\n", 4,
     {{3, settled("SWITCH_ON_DISABLED", test::sod, "11,12")}}},
    {"operation_enabled_quick_stop_code_6_stays_in_quick_stop_active",
     std::string("set 0x605A 6\n") + enable + "cw 0x0B\ncw 0x0B\n", 6,
     {{4, settled("QUICK_STOP_ACTIVE", test::qsa_standstill, "11")},
      {5, settled("QUICK_STOP_ACTIVE", test::qsa_standstill, "")}}},
    {"quick_stop_code_0_coasts_stays_without_t16_and_leaves_by_disable_voltage",
     std::string("set 0x605A 0\n") + enable + "cw 0x0B\ncw 0x0F\ncw 0x00\n", 7,
     {{4, settled("QUICK_STOP_ACTIVE", test::qsa, "11")},
      {5, settled("QUICK_STOP_ACTIVE", test::qsa, "")},
      {6, settled("SWITCH_ON_DISABLED", test::sod, "12")}}},
    // S6: in QUICK STOP ACTIVE only Disable voltage (T12) and Enable operation (T16) act.
    {"quick_stop_code_6_shutdown_in_quick_stop_active_stays",
     std::string("set 0x605A 6\n") + enable + "cw 0x0B\ncw 0x06\n", 6,
     {{5, settled("QUICK_STOP_ACTIVE", test::qsa_standstill, "")}}},
    {"fault_in_operation_enabled_takes_t13_then_t14_to_fault",
     std::string(enable) + "fault\n", 4,
     {{3, settled("FAULT", test::fault, "13,14")}}},
    {"fault_in_switch_on_disabled_takes_t13_then_t14",
     "fault 0x4310\n", 0,
     {{1, settled("FAULT", test::fault, "13,14")}}},
    {"fault_reset_edge_after_clear_takes_t15",
     std::string(enable) + "fault\nclear\ncw 0x80\n", 6,
     {{4, settled("FAULT", test::fault, "")},
      {5, settled("SWITCH_ON_DISABLED", test::sod, "15")}}},
    // S2: the edge is used up; clearing the cause afterwards does not reset without a new edge.
    {"fault_reset_edge_while_the_cause_persists_is_used_up",
     "fault\ncw 0x80\nclear\ncw 0x00\ncw 0x80\n", 6,
     {{2, settled("FAULT", test::fault, "")},
      {3, settled("FAULT", test::fault, "")},
      {4, settled("FAULT", test::fault, "")},
      {5, settled("SWITCH_ON_DISABLED", test::sod, "15")}}},
    // S2: the edge is taken against the previous step's control word, whatever the state was.
    {"bit_7_held_through_the_fault_gives_no_edge_after_clear",
     "cw 0x80\nfault\nclear\n", 4,
     {{3, settled("FAULT", test::fault, "")}}},
    {"bit_7_outside_fault_is_ignored_and_bits_0_to_3_decode_as_usual",
     "cw 0x86\n", 0,
     {{1, settled("READY_TO_SWITCH_ON", test::rtso, "2")}}},
    // Two causes; the newest is reported. `clear` removes both, so the reset then works.
    {"clear_resets_only_when_every_fault_cause_is_gone",
     "fault 0x2310\nfault 0x4310\ncw 0x80\ncw 0\nclear\ncw 0x80\n", 7,
     {{2, settled("FAULT", test::fault, "")},  // S4: recorded, no transition
      {3, settled("FAULT", test::fault, "")},
      {6, settled("SWITCH_ON_DISABLED", test::sod, "15")}}},
    {"halt_in_operation_enabled_stays_and_sets_bit_10_at_standstill",
     std::string(enable) + "cw 0x010F\ncw 0x0F\n", 5,
     {{3, settled("OPERATION_ENABLED", "0x0637", "")},
      {4, settled("OPERATION_ENABLED", test::oe, "")}}},
    // S13: T3 needs the DC link; without it only bit 4 changes.
    {"voltage_off_blocks_t3_and_voltage_on_lets_it_through",
     "cw 0x06\nvoltage off\ncw 0x0F\nvoltage on\n", 5,
     {{2, settled("READY_TO_SWITCH_ON", "0x0221", "")},
      {3, settled("READY_TO_SWITCH_ON", "0x0221", "")},
      {4, settled("OPERATION_ENABLED", test::oe, "3,4")}}},
    {"voltage_off_while_torque_is_on_is_a_fault",
     std::string(enable) + "voltage off\n", 0,
     {{3, settled("FAULT", "0x0208", "13,14")}}},
    {"voltage_off_in_switch_on_disabled_only_clears_bit_4",
     "voltage off\n", 0,
     {{1, settled("SWITCH_ON_DISABLED", "0x0240", "")}}},
    // S14: STO acts as a local Disable voltage; SWITCH ON DISABLED is not left while it is active,
    // and after it goes only a new Shutdown brings the drive back.
    {"sto_in_ready_to_switch_on_takes_t7_and_no_restart_follows_its_release",
     "cw 0x06\nsto on\ncw 0x0F\nsto off\ncw 0x06\ncw 0x0F\n", 7,
     {{2, settled("SWITCH_ON_DISABLED", "0x02D0", "7")},
      {3, settled("SWITCH_ON_DISABLED", "0x02D0", "")},
      {4, settled("SWITCH_ON_DISABLED", test::sod, "")},
      {5, settled("READY_TO_SWITCH_ON", test::rtso, "2")},
      {6, settled("OPERATION_ENABLED", test::oe, "3,4")}}},
    // S16: 0x605A is read when the quick stop starts. 6 -> 1 while the drive holds in QUICK STOP
    // ACTIVE changes nothing now; the next quick stop ends by itself.
    {"set_of_0x605a_in_a_holding_quick_stop_waits_for_the_next_quick_stop",
     std::string("set 0x605A 6\n") + enable + "cw 0x0B\nset 0x605A 1\ncw 0x0F\ncw 0x0B\n", 8,
     {{5, settled("QUICK_STOP_ACTIVE", test::qsa_standstill, "")},
      {6, settled("OPERATION_ENABLED", test::oe, "16")},
      {7, settled("SWITCH_ON_DISABLED", test::sod, "11,12")}}},
    {"set_accepted_prints_the_settled_state_and_takes_effect",
     "set 0x605A 5\n", 0,
     {{1, settled("SWITCH_ON_DISABLED", test::sod, "")}}},
    {"crlf_line_ends_are_accepted",
     "cw 0x06\r\n", 0,
     {{1, settled("READY_TO_SWITCH_ON", test::rtso, "2")}}},
  };
  return all;
}

class replay_settles : public ::testing::TestWithParam<replay_case> {};

TEST_P(replay_settles, prints_the_settled_lines_semantics_md_defines) {
  const replay_case& c = GetParam();
  const auto r = replay("cia402", c.events);
  if (c.line_count != 0) ASSERT_EQ(r.lines.size(), c.line_count);
  for (const auto& [at, line] : c.expected) EXPECT_EQ(r.lines.at(at), line) << "line " << at;
}

INSTANTIATE_TEST_SUITE_P(replay, replay_settles, ::testing::ValuesIn(settled_cases()),
                         [](const ::testing::TestParamInfo<replay_case>& info) {
                           return std::string(info.param.name);
                         });

TEST(replay, power_up_prints_switch_on_disabled_after_t0_and_t1_before_any_event) {
  const auto r = replay("cia402", "");
  EXPECT_EQ(r.exit_code, 0);
  ASSERT_EQ(r.lines.size(), 1u);
  EXPECT_EQ(r.lines[0], test::power_up);
}

TEST(replay, operation_enabled_quick_stop_codes_1_to_4_all_end_with_t12) {
  for (const char* code : {"1", "2", "3", "4"}) {
    const auto r =
        replay("cia402", std::string("set 0x605A ") + code + "\n" + enable + "cw 0x0B\n");
    ASSERT_EQ(r.lines.size(), 5u) << code;
    EXPECT_EQ(r.lines[4], settled("SWITCH_ON_DISABLED", test::sod, "11,12")) << code;
  }
}

TEST(replay, quick_stop_codes_5_to_8_stay_and_enable_operation_returns_by_t16) {
  for (const char* code : {"5", "6", "7", "8"}) {
    const auto r =
        replay("cia402", std::string("set 0x605A ") + code + "\n" + enable + "cw 0x0B\ncw 0x0F\n");
    ASSERT_EQ(r.lines.size(), 6u) << code;
    EXPECT_EQ(r.lines[4], settled("QUICK_STOP_ACTIVE", test::qsa_standstill, "11")) << code;
    EXPECT_EQ(r.lines[5], settled("OPERATION_ENABLED", test::oe, "16")) << code;
  }
}

TEST(replay, operation_enabled_disable_operation_shutdown_and_disable_voltage_take_t5_t8_t9) {
  EXPECT_EQ(replay("cia402", std::string(enable) + "cw 0x07\n").lines.at(3),
            settled("SWITCHED_ON", test::so, "5"));
  EXPECT_EQ(replay("cia402", std::string(enable) + "cw 0x06\n").lines.at(3),
            settled("READY_TO_SWITCH_ON", test::rtso, "8"));
  EXPECT_EQ(replay("cia402", std::string(enable) + "cw 0x00\n").lines.at(3),
            settled("SWITCH_ON_DISABLED", test::sod, "9"));
}

TEST(replay, shutdown_and_disable_operation_codes_0_and_1_both_complete_on_the_ideal_plant) {
  for (const char* code : {"0", "1"}) {
    const auto r = replay("cia402", std::string("set 0x605B ") + code + "\nset 0x605C " + code +
                                        "\n" + enable + "cw 0x07\ncw 0x0F\ncw 0x06\n");
    ASSERT_EQ(r.lines.size(), 8u) << code;
    EXPECT_EQ(r.lines[5], settled("SWITCHED_ON", test::so, "5")) << code;
    EXPECT_EQ(r.lines[7], settled("READY_TO_SWITCH_ON", test::rtso, "8")) << code;
  }
}

TEST(replay, switched_on_quick_stop_takes_t10_and_ready_to_switch_on_quick_stop_takes_t7) {
  EXPECT_EQ(replay("cia402", "cw 0x06\ncw 0x07\ncw 0x02\n").lines.at(3),
            settled("SWITCH_ON_DISABLED", test::sod, "10"));
  EXPECT_EQ(replay("cia402", "cw 0x06\ncw 0x02\n").lines.at(2),
            settled("SWITCH_ON_DISABLED", test::sod, "7"));
}

TEST(replay, sto_while_torque_is_on_is_a_fault) {
  const auto r = replay("cia402", std::string(enable) + "sto on\n");
  ASSERT_EQ(r.lines.size(), 4u);
  EXPECT_TRUE(line_names(r, 3, {"\"state\":\"FAULT\"", "\"transitions\":[13,14]"}));
}

TEST(replay, set_unsupported_value_is_refused_with_the_abort_code_and_changes_nothing) {
  const auto r = replay("cia402", std::string(enable) + "set 0x605A 9\ncw 0x0B\n");
  ASSERT_EQ(r.lines.size(), 5u);
  EXPECT_EQ(r.lines[3],
            "{\"error\":\"set 0x605A 9 refused: SDO abort 0x06090030 (invalid value for "
            "parameter)\",\"line\":3}");
  // Still the default 2: the quick stop ends by itself.
  EXPECT_EQ(r.lines[4], settled("SWITCH_ON_DISABLED", test::sod, "11,12"));
}

TEST(replay, set_of_an_object_the_drive_lacks_is_refused_with_0x06020000) {
  const auto r = replay("cia402", "set 0x6060 1\n");
  ASSERT_EQ(r.lines.size(), 2u);
  EXPECT_TRUE(line_names(r, 1, {"0x06020000", "\"line\":1}"}));
}

TEST(replay, blank_lines_and_comments_are_skipped_but_counted) {
  const auto r = replay("cia402", "# a comment\n\n   \ncw 0x06   # shutdown\n\tbad\n");
  ASSERT_EQ(r.lines.size(), 3u);
  EXPECT_EQ(r.lines[1], settled("READY_TO_SWITCH_ON", test::rtso, "2"));
  EXPECT_EQ(r.lines[2],
            "{\"error\":\"unknown event 'bad' (cw, fault, clear, set, voltage, sto, moving, "
            "standstill, local, remote, link)\",\"line\":5}");
}

TEST(replay, decimal_and_hex_values_mean_the_same) {
  EXPECT_EQ(replay("cia402", "cw 6\ncw 15\n").lines, replay("cia402", enable).lines);
}

struct bad_line_case {
  const char* line;
  const char* reason_part;
};

class replay_bad_line : public ::testing::TestWithParam<bad_line_case> {};

TEST_P(replay_bad_line, prints_an_error_with_its_line_number_changes_nothing_and_goes_on) {
  // Line 2 is bad; line 3 must behave as if line 2 had not been there.
  const std::string input = std::string("cw 0x06\n") + GetParam().line + "\ncw 0x0F\n";
  const auto r = replay("cia402", input);
  EXPECT_EQ(r.exit_code, 0);
  ASSERT_EQ(r.lines.size(), 4u);
  EXPECT_EQ(r.lines[2].rfind("{\"error\":\"", 0), 0u) << r.lines[2];
  EXPECT_TRUE(line_names(r, 2, {GetParam().reason_part, "\",\"line\":2}"}));
  EXPECT_EQ(r.lines[3], settled("OPERATION_ENABLED", test::oe, "3,4"));
}

INSTANTIATE_TEST_SUITE_P(
    every_kind, replay_bad_line,
    ::testing::Values(
        bad_line_case{"cw", "takes one value"}, bad_line_case{"cw 0x06 0x0F", "takes one value"},
        bad_line_case{"cw 0x10000", "does not fit 16 bits"},
        bad_line_case{"cw -1", "does not fit 16 bits"},
        bad_line_case{"cw 12abc", "is not a number"}, bad_line_case{"cw 0x", "is not a number"},
        bad_line_case{"fault 0", "is not an error code"},
        bad_line_case{"fault 0x10000", "is not an error code"},
        bad_line_case{"fault 0x1000 3", "has no error classes"},
        bad_line_case{"clear all", "takes no argument"},
        bad_line_case{"set 0x605A", "takes an index and a value"},
        bad_line_case{"set x 1", "is not a 16-bit object index"},
        bad_line_case{"set 0x605A two", "is not a number"},
        bad_line_case{"set 0x605A 9", "0x06090030"}, bad_line_case{"voltage", "takes on or off"},
        bad_line_case{"voltage maybe", "takes on or off"},
        bad_line_case{"sto 1", "takes on or off"}, bad_line_case{"CW 0x06", "unknown event 'CW'"},
        bad_line_case{"jump \"3\"", "unknown event 'jump'"}));

TEST(replay, error_text_with_quotes_is_escaped_as_json) {
  const auto r = replay("cia402", "\"quoted\\\n");
  ASSERT_EQ(r.lines.size(), 2u);
  EXPECT_EQ(r.lines[1],
            "{\"error\":\"unknown event '\\\"quoted\\\\' (cw, fault, clear, set, "
            "voltage, sto, moving, standstill, local, remote, link)\",\"line\":1}");
}

TEST(replay, bad_line_leaves_control_word_and_faults_untouched) {
  cli::replay_session s(standard_profile());
  s.power_up();
  s.feed("cw 0x06", 1);
  s.feed("fault 0x2310", 2);
  s.feed("cw 0x1FFFF", 3);
  s.feed("fault 0", 4);
  s.feed("voltage sideways", 5);
  EXPECT_EQ(s.inputs().control_word, 0x06);
  EXPECT_EQ(s.inputs().fault_code, 0x2310);
  EXPECT_TRUE(s.inputs().dc_link);
  EXPECT_EQ(s.drive_axis().current, state::fault);
}

TEST(replay, newest_present_fault_cause_is_the_one_the_drive_sees) {
  cli::replay_session s(standard_profile());
  s.power_up();
  s.feed("fault 0x2310", 1);
  s.feed("fault 0x4310", 2);
  EXPECT_EQ(s.inputs().fault_code, 0x4310);
  s.feed("fault 0x2310", 3);  // raised again: the newest now
  EXPECT_EQ(s.inputs().fault_code, 0x2310);
  EXPECT_EQ(s.drive_axis().error_code, 0x2310);
  s.feed("clear", 4);
  EXPECT_EQ(s.inputs().fault_code, 0);
}

TEST(replay, set_option_before_power_up_applies_from_the_start) {
  const auto r = replay("cia402", std::string(enable) + "cw 0x0B\n", {"0x605A=6"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.lines.at(0), test::power_up);
  EXPECT_EQ(test::first_fields(r.lines.at(3)), settled("QUICK_STOP_ACTIVE", test::qsa_standstill, "11"));
}

TEST(replay, several_set_options_apply_in_order) {
  const auto r = replay("cia402", std::string(enable) + "cw 0x0B\n", {"0x605A=6", "0x605A=1"});
  EXPECT_EQ(r.lines.at(3), settled("SWITCH_ON_DISABLED", test::sod, "11,12"));
}

TEST(replay, refused_set_option_exits_non_zero_with_the_abort_code_and_prints_nothing) {
  const auto r = replay("cia402", "cw 0x06\n", {"0x605A=9"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("0x06090030"), std::string::npos) << r.err;
}

TEST(replay, malformed_set_option_exits_non_zero_with_a_message) {
  for (const char* bad : {"0x605A", "0x605A=", "x=1", "0x605A=six", "0x1605A=1"}) {
    const auto r = replay("cia402", "", {bad});
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_TRUE(r.out.empty()) << bad;
    EXPECT_NE(r.err.find("--set"), std::string::npos) << bad << ": " << r.err;
  }
}

TEST(replay, unknown_profile_exits_non_zero_and_lists_the_built_ins) {
  const auto r = replay("cia403", "");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("ax2000-profibus"), std::string::npos) << r.err;
}

TEST(replay, profile_file_example_quick_stop_holds_by_its_default_code_6) {
  const auto r =
      test::run_tool({"replay", "--profile-file", CIA402_EXAMPLE_PROFILES_DIR "/custom-drive.toml"},
                     std::string(enable) + "cw 0x0B\n");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(test::first_fields(r.lines.at(3)), settled("QUICK_STOP_ACTIVE", test::qsa_standstill, "11"));
}

TEST(replay, bad_profile_file_exits_non_zero_with_file_line_and_reason) {
  const auto r = test::run_tool({"replay", "--profile-file", "/nonexistent.toml"}, "");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("/nonexistent.toml"), std::string::npos) << r.err;
}

TEST(replay, profile_and_profile_file_together_are_refused) {
  const auto r = test::run_tool({"replay", "--profile", "cia402", "--profile-file",
                                 CIA402_EXAMPLE_PROFILES_DIR "/custom-drive.toml"},
                                "");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(r.out.empty() || r.out.find("{\"state\"") == std::string::npos);
}

TEST(replay, settling_is_bounded_when_a_profile_never_comes_to_rest) {
  // Two automatic rows that undo each other: the drive never settles, replay must still end.
  const custom_profile restless =
      test::load_ok(test::toml({"base = \"cia402\"\nname = \"restless\"\n", test::t0_row, test::t1_row,
                                R"([[rows]]
number = 2
from = ["switch_on_disabled"]
to = "ready_to_switch_on"
any = ["automatic"]
[[rows]]
number = 7
from = ["ready_to_switch_on"]
to = "switch_on_disabled"
any = ["automatic"]
)"}));
  ASSERT_FALSE(::testing::Test::HasFailure()) << "the restless profile was refused";
  std::istringstream in("cw 0x06\n");
  std::ostringstream out;
  std::ostringstream err;
  EXPECT_EQ(cli::run_replay(restless.get(), {}, in, out, err), 0);
  std::istringstream lines(out.str());
  std::string first;
  std::getline(lines, first);
  // One transition a step, every step of the bound, and the line says it did not settle.
  const std::string list = first.substr(first.find('[') + 1, first.find(']') - first.find('[') - 1);
  EXPECT_EQ(std::count(list.begin(), list.end(), ',') + 1, cli::max_settle_steps) << first;
  EXPECT_NE(first.find(",\"settled\":false}"), std::string::npos) << first;
  std::string second;
  EXPECT_TRUE(std::getline(lines, second));
}

TEST(replay_cli, no_subcommand_is_a_usage_error) { EXPECT_NE(test::run_tool({}).exit_code, 0); }

TEST(replay_cli, help_exits_zero_and_names_every_subcommand) {
  const auto r = test::run_tool({"--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const char* sub : {"replay", "decode", "profiles", "demo"}) {
    EXPECT_NE(r.out.find(sub), std::string::npos) << sub;
  }
}

}  // namespace
}  // namespace cia402

namespace cia402 {

// Every line replay prints is valid JSON, whatever bytes it is fed: bytes that are not UTF-8 are
// echoed as U+FFFD in the error, never raw.
TEST(replay, every_line_is_valid_json_whatever_the_input_bytes) {
  const std::string inputs[] = {
      std::string("\xcf\n"),        std::string("cw \xff\xfe\n"),
      std::string("\xd0\xb9 on\n"), std::string("fault \xc3\x28\n"),
      std::string("set 0x605A \xe2\x82\n"), std::string("bogus\x01\x1f\x7f\n"),
      std::string("cw 6\0x\n", 7),
  };
  for (const std::string& input : inputs) {
    const auto r = test::run_tool({"replay", "--profile", "cia402"}, input);
    EXPECT_EQ(r.exit_code, 0);
    const auto lines = test::whole_lines(r);
    ASSERT_EQ(lines.size(), 2u) << r.out;
    for (const std::string& line : lines) {
      const auto parsed = nlohmann::json::parse(line, nullptr, false);
      EXPECT_FALSE(parsed.is_discarded()) << "not JSON: " << line;
    }
    EXPECT_NE(lines[1].find("\"error\""), std::string::npos) << lines[1];
  }
}

}  // namespace cia402
