// Every kind of bad profile file is refused with the line (and column) of the mistake and a reason.
// Line numbers are counted in the test texts themselves.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <variant>

#include "cia402/profile_file.hpp"
#include "helpers.hpp"

namespace cia402 {
namespace {

using test::load_error;

// Asserts the refusal's place and that its reason mentions `reason_part`.
void expect_refused(std::string_view text, int line, int column, std::string_view reason_part) {
  const profile_file_error e = load_error(text);
  if (line >= 0) EXPECT_EQ(e.line, line) << e.message();
  if (column > 0) EXPECT_EQ(e.column, column) << e.message();
  EXPECT_NE(e.reason.find(reason_part), std::string::npos) << e.message();
  EXPECT_EQ(e.source_name, "test.toml");
}

std::string rows(int n) {
  std::string text = "base = \"cia402\"\n";
  for (int i = 0; i < n; ++i) text += test::t0_row;
  return text;
}

// --- syntax (toml++) ---------------------------------------------------------------------------

TEST(profile_file_errors, toml_syntax_error_is_refused_at_its_line) {
  expect_refused("base = \"cia402\"\nname = \"x\"\nspeed_limit_rpm = = 3\n", 3, 0, "");
}

// toml++ 3.3.0 reaches undefined behaviour on some non-ASCII input (the two bytes 0xD0 0xB9 among
// them, found by fuzzing): the text is checked before the parser sees it.
TEST(profile_file_errors, non_ascii_outside_strings_and_invalid_utf8_never_reach_the_parser) {
  expect_refused("\xd0\xb9", 1, 1, "non-ASCII character outside a string or comment");
  expect_refused("base = \"cia402\"\nname = x\xd0\xb9\n", 2, 9, "non-ASCII");
  expect_refused("base = \"cia402\"\nname = \"\xcf\"\n", 2, 9, "not UTF-8");
  expect_refused("base = \"cia402\"\nname = \"\xed\xa0\x80\"\n", 2, 9, "not UTF-8");  // a surrogate
  expect_refused("base = \"cia402\"\nname = \"\xc0\xaf\"\n", 2, 9, "not UTF-8");      // overlong
  expect_refused(std::string("base = \"cia402\"\0\n", 17), 1, 16, "NUL");
  // In strings and comments UTF-8 is welcome.
  const auto ok = load_profile_toml(
      "# \xc3\x9c" "bergang, \xd0\xb9\nbase = \"cia402\"\nname = \"x\"\n"
      "title = \"Fr\xc3\xa4sspindel \\\"\xd0\xb9\\\" '''\"\n",
      "test.toml");
  ASSERT_TRUE(std::holds_alternative<custom_profile>(ok))
      << std::get<profile_file_error>(ok).message();
  EXPECT_EQ(std::string(std::get<custom_profile>(ok).get().title),
            "Fr\xc3\xa4sspindel \"\xd0\xb9\" '''");
}

TEST(profile_file_errors, only_a_regular_file_of_at_most_1_mib_is_read) {
  for (const char* path : {"/dev/zero", "/dev/null", "/tmp"}) {
    const auto r = load_profile_toml_file(path);
    ASSERT_TRUE(std::holds_alternative<profile_file_error>(r)) << path;
    EXPECT_EQ(std::get<profile_file_error>(r).reason, "not a regular file") << path;
  }
  const std::string big = ::testing::TempDir() + "cia402-big-profile.toml";
  {
    std::FILE* f = std::fopen(big.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    const std::string line(1023, '#');
    for (int i = 0; i < 1025; ++i) std::fprintf(f, "%s\n", line.c_str());
    std::fclose(f);
  }
  const auto r = load_profile_toml_file(big);
  ASSERT_TRUE(std::holds_alternative<profile_file_error>(r));
  EXPECT_NE(std::get<profile_file_error>(r).reason.find("larger than 1048576 bytes"),
            std::string::npos);
  std::remove(big.c_str());
}

TEST(profile_file_errors, unterminated_array_is_refused) {
  const profile_file_error e =
      load_error("base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = [\"start\",\n");
  EXPECT_GE(e.line, 4) << e.message();
}

TEST(profile_file_errors, key_given_twice_is_refused_at_the_second) {
  expect_refused("base = \"cia402\"\nname = \"a\"\nname = \"b\"\n", 3, 0, "name");
}

TEST(profile_file_errors, table_given_twice_is_refused_at_the_second_header) {
  expect_refused(
      "base = \"cia402\"\n[states.fault]\nstatus = 0x08\n[states.fault]\nstatus = 0x08\n", 4, 0,
      "fault");
}

// --- keys --------------------------------------------------------------------------------------

TEST(profile_file_errors, unknown_word_names_are_refused_with_the_known_ones) {
  expect_refused("base = \"cia402\"\nname = \"x\"\nword_names = \"profinet\"\n", 3, 14,
                 "unknown word_names 'profinet' (cia402, drivecom)");
}

TEST(profile_file_errors, word_names_pick_the_bit_names_and_a_base_passes_them_on) {
  const auto drivecom = load_profile_toml("base = \"cia402\"\nname = \"x\"\nword_names = \"drivecom\"\n", "t.toml");
  ASSERT_TRUE(std::holds_alternative<custom_profile>(drivecom));
  EXPECT_EQ(std::string(bit_names_of(std::get<custom_profile>(drivecom).get()).control[8]), "Jog");
  const auto inherited = load_profile_toml("base = \"s300-profibus\"\nname = \"y\"\n", "t.toml");
  ASSERT_TRUE(std::holds_alternative<custom_profile>(inherited));
  EXPECT_EQ(std::get<custom_profile>(inherited).get().words, word_names::drivecom);
}

TEST(profile_file_errors, unknown_top_level_key_is_refused_at_the_key) {
  expect_refused("base = \"cia402\"\n\nnmae = \"x\"\n", 3, 1, "unknown key 'nmae'");
}

TEST(profile_file_errors, unknown_row_key_is_refused_at_the_key) {
  expect_refused(rows(1) + "  anyy = [\"fault\"]\n", 7, 3, "unknown key 'anyy' in a row");
}

TEST(profile_file_errors, unknown_decoder_key_is_refused) {
  expect_refused(
      "base = \"cia402\"\n[[decoder]]\nmask = 2\nvalue = 0\ncommand = \"shutdown\"\n"
      "result = \"shutdown\"\n",
      6, 1, "unknown key 'result'");
}

TEST(profile_file_errors, unknown_state_key_is_refused) {
  expect_refused("base = \"cia402\"\n[states.fault]\nstatus = 0x08\nactivty = \"idle\"\n", 4, 1,
                 "unknown key 'activty'");
}

TEST(profile_file_errors, unknown_option_key_is_refused) {
  expect_refused("base = \"cia402\"\n[options.0x605A]\ndefualt = 2\n", 3, 1,
                 "unknown key 'defualt'");
}

TEST(profile_file_errors, state_given_twice_under_two_spellings_is_refused) {
  const profile_file_error e = load_error(
      "base = \"cia402\"\n[states.fault]\nstatus = 0x08\n[states.FAULT]\nstatus = 0x08\n");
  EXPECT_TRUE(e.line == 2 || e.line == 4) << e.message();
  EXPECT_NE(e.reason.find("twice"), std::string::npos) << e.message();
}

TEST(profile_file_errors, option_given_twice_under_two_spellings_is_refused) {
  const profile_file_error e = load_error(
      "base = \"cia402\"\n[options.0x605A]\ndefault = 2\n[options.0x605a]\ndefault = 2\n");
  EXPECT_TRUE(e.line == 2 || e.line == 4) << e.message();
  EXPECT_NE(e.reason.find("twice"), std::string::npos) << e.message();
}

TEST(profile_file_errors, unknown_option_object_is_refused_at_its_key) {
  expect_refused("base = \"cia402\"\n[options.0x6060]\ndefault = 1\n", 2, 10,
                 "unknown option object '0x6060'");
}

// --- types -------------------------------------------------------------------------------------

TEST(profile_file_errors, number_as_string_is_refused_as_wrong_type) {
  expect_refused("base = \"cia402\"\n[[rows]]\nnumber = \"0\"\n", 3, 10, "must be an integer");
}

TEST(profile_file_errors, from_as_single_string_is_refused_as_wrong_type) {
  expect_refused("base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = \"start\"\n", 4, 8,
                 "from must be an array");
}

TEST(profile_file_errors, flag_as_integer_is_refused_as_wrong_type) {
  expect_refused(rows(1) + "interrupts_stop = 1\n", 7, 19, "must be true or false");
}

TEST(profile_file_errors, status_as_string_is_refused_as_wrong_type) {
  expect_refused("base = \"cia402\"\n[states.fault]\nstatus = \"0x08\"\n", 3, 10,
                 "must be an integer");
}

TEST(profile_file_errors, name_as_integer_is_refused_as_wrong_type) {
  expect_refused("base = \"cia402\"\nname = 5\n", 2, 8, "name must be a string");
}

TEST(profile_file_errors, rows_as_table_is_refused_as_wrong_type) {
  expect_refused("base = \"cia402\"\n[rows]\nnumber = 0\n", 2, 0, "rows must be an array");
}

TEST(profile_file_errors, supported_value_as_float_is_refused_as_wrong_type) {
  expect_refused("base = \"cia402\"\n[options.0x605A]\nsupported = [1, 2.0]\n", 3, 17,
                 "must be an integer");
}

// --- names -------------------------------------------------------------------------------------

TEST(profile_file_errors, unknown_state_in_from_is_refused_at_the_name) {
  expect_refused("base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = [\"start\", \"operational\"]\n",
                 4, 18, "unknown state 'operational'");
}

TEST(profile_file_errors, unknown_state_in_to_is_refused_at_the_name) {
  expect_refused("base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = [\"start\"]\nto = \"ready\"\n", 5,
                 6, "unknown state 'ready'");
}

TEST(profile_file_errors, unknown_state_table_is_refused_at_its_key) {
  expect_refused("base = \"cia402\"\n[states.enabled]\nstatus = 0x27\n", 2, 9,
                 "unknown state 'enabled'");
}

TEST(profile_file_errors, unknown_fact_in_any_is_refused_at_the_name) {
  expect_refused(
      "base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = [\"start\"]\nto = \"fault\"\n"
      "any = [\"fualt\"]\n",
      6, 8, "unknown fact 'fualt'");
}

TEST(profile_file_errors, unknown_fact_in_none_is_refused_at_the_name) {
  expect_refused(rows(1) + "none = [\"sto\", \"stto\"]\n", 7, 16, "unknown fact 'stto' in none");
}

TEST(profile_file_errors, unknown_command_in_decoder_is_refused_at_the_name) {
  expect_refused("base = \"cia402\"\n[[decoder]]\nmask = 2\nvalue = 0\ncommand = \"enable\"\n", 5,
                 11, "unknown command 'enable'");
}

TEST(profile_file_errors, unknown_stop_is_refused_at_the_name) {
  expect_refused(rows(1) + "stop = \"ramp\"\n", 7, 8, "unknown stop 'ramp'");
}

TEST(profile_file_errors, unknown_activity_is_refused_at_the_name) {
  expect_refused("base = \"cia402\"\n[states.fault]\nactivity = \"braking\"\n", 3, 12,
                 "unknown activity 'braking'");
}

TEST(profile_file_errors, unknown_base_is_refused_and_lists_the_built_ins) {
  expect_refused("\nbase = \"cia403\"\n", 2, 8, "unknown base profile 'cia403'");
  EXPECT_NE(load_error("base = \"x\"\n").reason.find("ax2000-profibus"), std::string::npos);
}

// --- values and semantics ----------------------------------------------------------------------

TEST(profile_file_errors, decoder_mask_outside_bits_0_to_4_is_refused_at_the_mask) {
  expect_refused("base = \"cia402\"\n[[decoder]]\nmask = 0x20\nvalue = 0\ncommand = \"shutdown\"\n",
                 3, 8, "outside 0..4");
}

TEST(profile_file_errors, decoder_value_outside_its_mask_is_refused_at_the_value) {
  expect_refused(
      "base = \"cia402\"\n[[decoder]]\nmask = 0x02\nvalue = 0x04\n"
      "command = \"shutdown\"\n",
      4, 9, "outside its mask");
}

TEST(profile_file_errors, more_than_8_decoder_rules_are_refused_at_the_ninth) {
  std::string text = "base = \"cia402\"\n";
  for (int i = 0; i < 9; ++i) text += "[[decoder]]\nmask = 2\nvalue = 0\ncommand = \"shutdown\"\n";
  expect_refused(text, 2 + 8 * 4, 0, "more than 8 decoder rules");
}

TEST(profile_file_errors, empty_decoder_is_refused) {
  expect_refused("base = \"cia402\"\ndecoder = []\n", 2, 11, "no rules");
}

TEST(profile_file_errors, more_than_32_rows_are_refused_at_the_thirty_third) {
  expect_refused(rows(33), 2 + 32 * 5, 0, "more than 32 transition rows");
}

TEST(profile_file_errors, exactly_32_rows_are_accepted) {
  profile_load_result r = load_profile_toml(rows(32), "test.toml");
  ASSERT_TRUE(std::holds_alternative<custom_profile>(r))
      << std::get<profile_file_error>(r).message();
  EXPECT_EQ(std::get<custom_profile>(r).get().row_count, 32);
}

TEST(profile_file_errors, row_from_no_state_is_refused_at_from) {
  expect_refused("base = \"cia402\"\n[[rows]]\nnumber = 4\nfrom = []\n", 4, 8, "leaves no state");
}

TEST(profile_file_errors, row_listing_a_state_twice_in_from_is_refused) {
  expect_refused("base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = [\"start\", \"START\"]\n", 4, 18,
                 "listed twice");
}

TEST(profile_file_errors, row_to_start_is_refused_at_to) {
  expect_refused("base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = [\"fault\"]\nto = \"start\"\n", 5,
                 6, "cannot go to START");
}

TEST(profile_file_errors, row_without_trigger_is_refused_at_any) {
  expect_refused(
      "base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = [\"start\"]\nto = \"fault\"\nany = []\n", 6,
      7, "no trigger");
}

TEST(profile_file_errors, row_requiring_and_forbidding_a_fact_is_refused_at_none) {
  expect_refused(rows(1) + "all = [\"dc_link\"]\nnone = [\"dc_link\"]\n", 8, 8,
                 "requires and forbids");
}

TEST(profile_file_errors, fact_listed_twice_is_refused) {
  expect_refused(rows(1) + "all = [\"dc_link\", \"dc_link\"]\n", 7, 19, "listed twice");
}

TEST(profile_file_errors, transition_number_18_is_refused_at_the_number) {
  expect_refused("base = \"cia402\"\n[[rows]]\nnumber = 18\n", 3, 10, "outside 0..17");
}

TEST(profile_file_errors, row_without_to_is_refused_at_its_table) {
  expect_refused(
      "base = \"cia402\"\n[[rows]]\nnumber = 0\nfrom = [\"start\"]\nany = [\"automatic\"]\n", 2, 0,
      "lacks the key 'to'");
}

TEST(profile_file_errors, no_row_leaving_start_is_refused) {
  expect_refused(
      "base = \"cia402\"\n[[rows]]\nnumber = 1\nfrom = [\"not_ready_to_switch_on\"]\n"
      "to = \"switch_on_disabled\"\nany = [\"automatic\"]\n",
      2, 0, "never power up");
}

TEST(profile_file_errors, empty_rows_are_refused) {
  expect_refused("base = \"cia402\"\nrows = []\n", 2, 8, "never leave START");
}

TEST(profile_file_errors, option_default_not_supported_is_refused_at_the_default) {
  expect_refused("base = \"cia402\"\n[options.0x605A]\nsupported = [1, 2, 5]\ndefault = 6\n", 4, 11,
                 "default 6 is not a supported value");
}

TEST(profile_file_errors, supported_list_without_the_inherited_default_is_refused) {
  expect_refused("base = \"cia402\"\n[options.0x605A]\nsupported = [5, 6]\n", 3, 13,
                 "inherited default 2");
}

TEST(profile_file_errors, quick_stop_value_the_standard_does_not_define_is_refused) {
  // 0x605A is 0..8 (cia402-reference.md section 3).
  expect_refused("base = \"cia402\"\n[options.0x605A]\nsupported = [2, 9]\n", 3, 17,
                 "outside 0..8");
}

TEST(profile_file_errors, halt_code_0_is_refused_as_reserved) {
  // 0x605D is 1..4; 0 is reserved.
  expect_refused("base = \"cia402\"\n[options.0x605D]\nsupported = [0, 1]\n", 3, 14,
                 "outside 1..4");
}

TEST(profile_file_errors, negative_option_default_is_refused) {
  expect_refused("base = \"cia402\"\n[options.0x605A]\ndefault = -1\n", 3, 11, "outside 0..8");
}

TEST(profile_file_errors, supported_value_listed_twice_is_refused) {
  expect_refused("base = \"cia402\"\n[options.0x605A]\nsupported = [2, 2]\n", 3, 17,
                 "listed twice");
}

TEST(profile_file_errors, status_pattern_with_bit_4_is_refused_at_the_status) {
  expect_refused("base = \"cia402\"\n[states.fault]\nstatus = 0x18\n", 3, 10,
                 "bits other than 0..3, 5, 6");
}

TEST(profile_file_errors, negative_speed_limit_is_refused) {
  expect_refused("base = \"cia402\"\nspeed_limit_rpm = -5\n", 2, 19, "outside 0..");
}

TEST(profile_file_errors, name_longer_than_39_characters_is_refused) {
  expect_refused("base = \"cia402\"\nname = \"" + std::string(40, 'x') + "\"\n", 2, 8,
                 "longer than 39");
}

TEST(profile_file_errors, empty_name_is_refused) {
  expect_refused("base = \"cia402\"\nname = \"\"\n", 2, 8, "must not be empty");
}

// --- completeness without a base --------------------------------------------------------------

std::string without_line(std::string_view text, std::string_view line) {
  std::string s(text);
  const std::size_t at = s.find(line);
  if (at != std::string::npos) s.erase(at, line.size() + 1);
  return s;
}

TEST(profile_file_errors, file_without_base_or_name_is_refused) {
  expect_refused(without_line(test::minimal_profile, "name = \"minimal\""), 1, 1,
                 "lacks the key 'name'");
}

TEST(profile_file_errors, file_without_base_missing_a_state_is_refused) {
  std::string text(test::minimal_profile);
  const std::size_t at = text.find("[states.switched_on]");
  text.erase(at, std::string("[states.switched_on]\nstatus = 0x23\nactivity = \"idle\"\n").size());
  // The states table begins at the first [states.*] header, line 37 of the minimal profile.
  expect_refused(text, 37, 0, "states lacks switched_on");
}

TEST(profile_file_errors, file_without_base_missing_a_state_key_is_refused_at_the_state) {
  expect_refused(without_line(test::minimal_profile, "activity = \"run\""), 49, 0,
                 "states.operation_enabled lacks the key 'activity'");
}

TEST(profile_file_errors, file_without_base_missing_an_option_is_refused) {
  std::string text(test::minimal_profile);
  const std::size_t at = text.find("[options.0x6007]");
  text.erase(at);
  expect_refused(text, 61, 0, "options lacks 0x6007");
}

TEST(profile_file_errors, file_without_base_missing_supported_is_refused_at_the_option) {
  expect_refused(without_line(test::minimal_profile, "supported = [0]\ndefault = 0"), 73, 0,
                 "options.0x605E lacks the key 'supported'");
}

TEST(profile_file_errors, file_without_base_missing_the_decoder_is_refused) {
  std::string text(test::minimal_profile);
  text.erase(text.find("[[decoder]]"), std::string("[[decoder]]\nmask = 0x02\nvalue = 0x00\n"
                                                   "command = \"disable_voltage\"\n")
                                           .size());
  expect_refused(text, 1, 1, "lacks the key 'decoder'");
}

// --- the whole file is refused, never half used ------------------------------------------------

TEST(profile_file_errors, one_bad_value_in_an_otherwise_complete_file_refuses_the_whole_file) {
  const std::string text = "title = 7\n" + std::string(test::minimal_profile);
  expect_refused(text, 1, 9, "title must be a string");
}

}  // namespace
}  // namespace cia402
