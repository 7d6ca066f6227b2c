// `cia402 decode`: status words to states with the masks of cia402-reference.md §1.1, control
// words to the commands of S1 (and of seed 004's decoder), every bit named.
#include <gtest/gtest.h>

#include <cstdio>

#include <nlohmann/json.hpp>
#include <string>

#include "cia402/master.hpp"
#include "cia402/profile.hpp"
#include "cli/demo.hpp"
#include "cli/decode.hpp"
#include "replay_support.hpp"

namespace cia402 {
namespace {

struct status_case {
  std::uint16_t word;
  state expected;
};

class status_word_state : public ::testing::TestWithParam<status_case> {};

TEST_P(status_word_state, standard_pattern_decodes_to_its_state_on_every_builtin) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    // The CLI reports the state the core's decoder finds (cia402::decode_status): checked here
    // against the reference table, and through the tool's own output.
    state s{};
    ASSERT_TRUE(decode_status(builtin_profile(i), GetParam().word, s)) << builtin_profile(i).name;
    EXPECT_EQ(s, GetParam().expected) << builtin_profile(i).name;
    char word[8];
    std::snprintf(word, sizeof word, "0x%04X", GetParam().word);
    const auto r = test::run_tool({"decode", word, "--profile", builtin_profile(i).name});
    EXPECT_NE(r.out.find(std::string("state: ") + state_name(GetParam().expected) + "\n"),
              std::string::npos) << r.out;
  }
}

// Values from the reference table, with bit 5 both ways where it is don't-care, and with the bits
// that never take part (4, 7..15) set.
INSTANTIATE_TEST_SUITE_P(reference_table, status_word_state,
                         ::testing::Values(status_case{0x0000, state::not_ready_to_switch_on},
                                           status_case{0x0020, state::not_ready_to_switch_on},
                                           status_case{0x0040, state::switch_on_disabled},
                                           status_case{0x0060, state::switch_on_disabled},
                                           status_case{0x0250, state::switch_on_disabled},
                                           status_case{0x0021, state::ready_to_switch_on},
                                           status_case{0xFF31, state::ready_to_switch_on},
                                           status_case{0x0023, state::switched_on},
                                           status_case{0x0027, state::operation_enabled},
                                           status_case{0x0237, state::operation_enabled},
                                           status_case{0x0007, state::quick_stop_active},
                                           status_case{0x0617, state::quick_stop_active},
                                           status_case{0x000F, state::fault_reaction_active},
                                           status_case{0x002F, state::fault_reaction_active},
                                           status_case{0x0008, state::fault},
                                           status_case{0x0028, state::fault},
                                           status_case{0x0218, state::fault}));

TEST(decode_status, patterns_matching_no_state_decode_to_none) {
  // Bit 0 without bit 5 (0x01), bit 1 alone (0x02), SOD with bit 0 (0x41).
  for (std::uint16_t w : {0x0001, 0x0002, 0x0041, 0x0003, 0x0067}) {
    state s{};
    EXPECT_FALSE(decode_status(standard_profile(), w, s)) << w;
  }
}

TEST(decode_status, report_names_the_state_and_all_16_bits_with_their_values) {
  const auto r = test::run_tool({"decode", "0x0237"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("state: OPERATION_ENABLED"), std::string::npos) << r.out;
  int bit_lines = 0;
  for (const std::string& line : r.lines) {
    if (line.rfind("  bit ", 0) == 0) ++bit_lines;
  }
  EXPECT_EQ(bit_lines, 16);
  EXPECT_NE(r.out.find("bit  9  1  Remote"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bit  3  0  Fault"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bit  4  1  Voltage enabled"), std::string::npos) << r.out;
}

// The PROFIBUS profiles name their words and bits as their manuals do (DRIVECOM STW / ZSW): bit 8
// is jog there, and bits 1 and 2 act when cleared.
TEST(decode_control, profibus_profiles_use_the_stw_and_zsw_names) {
  for (const char* name : {"s300-profibus", "ax2000-profibus"}) {
    SCOPED_TRACE(name);
    const auto c = test::run_tool({"decode", "--controlword", "0x0106", "--profile", name});
    EXPECT_NE(c.out.find("control word STW (0x6040): 0x0106"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("bit  8  1  Jog"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("bit  1  1  Inhibit voltage (active low)"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("bit  2  1  Fast stop, switch-on inhibited (active low)"),
              std::string::npos) << c.out;
    EXPECT_EQ(c.out.find("Halt"), std::string::npos) << c.out;
    const auto z = test::run_tool({"decode", "0x0237", "--profile", name});
    EXPECT_NE(z.out.find("status word ZSW (0x6041): 0x0237"), std::string::npos) << z.out;
    EXPECT_NE(z.out.find("bit 10  0  In position"), std::string::npos) << z.out;
  }
  const auto std_word = test::run_tool({"decode", "--controlword", "0x0106"});
  EXPECT_NE(std_word.out.find("bit  8  1  Halt"), std::string::npos) << std_word.out;
}

TEST(decode_json, status_word_gives_the_state_and_16_named_bits) {
  const auto r = test::run_tool({"decode", "--json", "0x0237"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["state"], "OPERATION_ENABLED");
  EXPECT_EQ(j["word"], "0x0237");
  ASSERT_EQ(j["bits"].size(), 16u);
  EXPECT_EQ(j["bits"][2]["value"], 1);
  EXPECT_EQ(j["bits"][3]["value"], 0);
  const auto none = nlohmann::json::parse(test::run_tool({"decode", "--json", "0x0004"}).out);
  EXPECT_TRUE(none["state"].is_null()) << "bit 2 alone matches no state";
}

TEST(decode_json, control_word_on_a_profibus_profile_has_no_halt_and_uses_its_names) {
  const auto r = test::run_tool(
      {"decode", "--json", "--controlword", "--profile", "s300-profibus", "0x010F"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["command"], "ENABLE_OPERATION");
  EXPECT_EQ(j["halt"], false) << "bit 8 is not a halt on this profile";
  const auto text = test::run_tool({"decode", "--controlword", "--profile", "s300-profibus", "0x010F"});
  EXPECT_NE(text.out.find(j["bits"][8]["name"].get<std::string>()), std::string::npos)
      << "the same names as the report";
  EXPECT_EQ(j["bits"][0]["decoded"], true);
  EXPECT_EQ(j["bits"][8]["decoded"], false);
}

TEST(decode_status, decimal_word_is_accepted) {
  EXPECT_NE(test::run_tool({"decode", "567"}).out.find("OPERATION_ENABLED"), std::string::npos);
}

TEST(decode_status, word_matching_no_state_says_so) {
  EXPECT_NE(test::run_tool({"decode", "0x0001"}).out.find("state: none"), std::string::npos);
}

struct control_case {
  const char* profile;
  const char* word;
  const char* command;
};

class control_word_command : public ::testing::TestWithParam<control_case> {};

TEST_P(control_word_command, decodes_to_the_command_the_seed_gives) {
  const auto r =
      test::run_tool({"decode", GetParam().word, "--controlword", "--profile", GetParam().profile});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(std::string("command: ") + GetParam().command + "\n"), std::string::npos)
      << r.out;
}

// S1 (first match wins: bit 1, bit 2, bit 0, bit 3) and, for ax2000, seed 004's bit 2 and bit 4.
INSTANTIATE_TEST_SUITE_P(
    s1_and_seed_004, control_word_command,
    ::testing::Values(control_case{"cia402", "0x0006", "SHUTDOWN"},
                      control_case{"cia402", "0x000E", "SHUTDOWN"},
                      control_case{"cia402", "0x0007", "SWITCH_ON"},
                      control_case{"cia402", "0x000F", "ENABLE_OPERATION"},
                      control_case{"cia402", "0x000B", "QUICK_STOP"},
                      control_case{"cia402", "0x0002", "QUICK_STOP"},
                      control_case{"cia402", "0x0000", "DISABLE_VOLTAGE"},
                      control_case{"cia402", "0x000D", "DISABLE_VOLTAGE"},
                      control_case{"cia402", "0x008F", "ENABLE_OPERATION"},
                      control_case{"ax2000-profibus", "0x001F", "ENABLE_OPERATION"},
                      control_case{"ax2000-profibus", "0x000F", "QUICK_STOP"},
                      control_case{"ax2000-profibus", "0x001B", "STOP_AND_INHIBIT"},
                      control_case{"ax2000-profibus", "0x0007", "SWITCH_ON"},
                      control_case{"ax2000-profibus", "0x0006", "SHUTDOWN"},
                      control_case{"ax2000-profibus", "0x0019", "DISABLE_VOLTAGE"}));

TEST(decode_control, fault_reset_and_halt_bits_are_reported) {
  const auto r = test::run_tool({"decode", "0x018F", "--controlword"});
  EXPECT_NE(r.out.find("fault reset: 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("halt: 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bit  7  1  Fault reset"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bit  8  1  Halt"), std::string::npos) << r.out;
}

TEST(decode_control, halt_on_a_profile_without_0x605d_is_said_to_be_ignored) {
  const auto r =
      test::run_tool({"decode", "0x010F", "--controlword", "--profile", "s300-profibus"});
  EXPECT_NE(r.out.find("bit 8 is ignored"), std::string::npos) << r.out;
}

TEST(decode_control, bits_the_profile_decoder_reads_are_marked) {
  const auto standard = test::run_tool({"decode", "0x0F", "--controlword"});
  const auto ax2000 =
      test::run_tool({"decode", "0x0F", "--controlword", "--profile", "ax2000-profibus"});
  auto marked = [](const std::string& out, int bit) {
    const std::string head = std::string("  bit ") + (bit < 10 ? " " : "") + std::to_string(bit);
    const std::size_t at = out.find(head);
    const std::size_t end = out.find('\n', at);
    return out.substr(at, end - at).find("decoder") != std::string::npos;
  };
  EXPECT_TRUE(marked(standard.out, 3));
  EXPECT_FALSE(marked(standard.out, 4));
  EXPECT_TRUE(marked(ax2000.out, 4));
}

TEST(decode_cli, word_that_does_not_fit_16_bits_is_a_usage_error) {
  for (const char* bad : {"0x10000", "-1", "abc", "0x"}) {
    const auto r = test::run_tool({"decode", bad});
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_TRUE(r.out.empty()) << bad;
  }
}

TEST(decode_cli, missing_word_is_a_usage_error) {
  EXPECT_NE(test::run_tool({"decode"}).exit_code, 0);
}

}  // namespace
}  // namespace cia402
