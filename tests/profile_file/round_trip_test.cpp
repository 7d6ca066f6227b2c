// dump_profile_toml() writes any profile as a file that loads back to identical tables, and the
// loaded profile drives a drive exactly like the original.
#include <gtest/gtest.h>

#include <cstring>

#include <random>
#include <string>

#include "cia402/drive.hpp"
#include "cia402/profile_file.hpp"
#include "../core/test_support.hpp"
#include "helpers.hpp"

namespace cia402 {
namespace {

void expect_same_tables(const profile& a, const profile& b) {
  EXPECT_STREQ(a.name, b.name);
  EXPECT_STREQ(a.seed, b.seed);
  EXPECT_STREQ(a.title, b.title);
  ASSERT_EQ(a.decoder_size, b.decoder_size);
  for (std::size_t i = 0; i < a.decoder_size; ++i) {
    EXPECT_EQ(a.decoder[i].mask, b.decoder[i].mask) << "decoder rule " << i;
    EXPECT_EQ(a.decoder[i].value, b.decoder[i].value) << "decoder rule " << i;
    EXPECT_EQ(a.decoder[i].result, b.decoder[i].result) << "decoder rule " << i;
  }
  ASSERT_EQ(a.row_count, b.row_count);
  for (std::size_t i = 0; i < a.row_count; ++i) {
    const transition_row x = a.row(i);
    const transition_row y = b.row(i);
    EXPECT_EQ(x.number, y.number) << "row " << i;
    EXPECT_EQ(x.from, y.from) << "row " << i;
    EXPECT_EQ(x.to, y.to) << "row " << i;
    EXPECT_EQ(x.any, y.any) << "row " << i;
    EXPECT_EQ(x.all, y.all) << "row " << i;
    EXPECT_EQ(x.none, y.none) << "row " << i;
    EXPECT_EQ(x.stop, y.stop) << "row " << i;
    EXPECT_EQ(x.flags, y.flags) << "row " << i;
  }
  for (int s = 0; s < state_count; ++s) {
    EXPECT_EQ(a.states[s].status_pattern, b.states[s].status_pattern) << state_name(state(s));
    EXPECT_EQ(a.states[s].activity, b.states[s].activity) << state_name(state(s));
  }
  for (int o = 0; o < option_count; ++o) {
    EXPECT_EQ(a.options[o].supported, b.options[o].supported) << "option " << o;
    EXPECT_EQ(a.options[o].default_value, b.options[o].default_value) << "option " << o;
  }
  EXPECT_EQ(a.speed_limit_rpm, b.speed_limit_rpm);
  EXPECT_EQ(a.error_classes, b.error_classes);
  EXPECT_EQ(a.words, b.words) << "the bit names (word_names)";
  EXPECT_EQ(a.command_of_bits, b.command_of_bits);
  EXPECT_EQ(a.rows_from, b.rows_from);
  ASSERT_NE(a.ordinary, nullptr);
  ASSERT_NE(b.ordinary, nullptr);
  EXPECT_EQ(std::memcmp(a.ordinary, b.ordinary, sizeof(ordinary_tables)), 0)
      << "a loaded profile's ordinary cycles, compiled at load";
}

// Random plant inputs, biased towards the words and events the tables react to.
drive_inputs random_inputs(std::mt19937& rng) {
  static constexpr std::uint16_t words[] = {0x00,        0x02, 0x06,  0x07, 0x0B, 0x0F, 0x1F,
                                            0x0F | 0x80, 0x80, 0x10F, 0x1B, 0x17, 0x0D, 0x1E};
  std::uniform_int_distribution<int> pick(0, 99);
  drive_inputs in;
  in.control_word = pick(rng) < 80 ? words[static_cast<std::size_t>(pick(rng)) % std::size(words)]
                                   : static_cast<std::uint16_t>(rng());
  in.fault_code = pick(rng) < 10 ? static_cast<std::uint16_t>(0x1000 + pick(rng)) : 0;
  in.fault_class = static_cast<std::uint8_t>(pick(rng) % 5);
  in.dc_link = pick(rng) < 90;
  in.sto = pick(rng) < 5;
  in.standstill = pick(rng) < 70;
  in.brake_engaged = pick(rng) < 70;
  in.remote = pick(rng) < 95;
  in.connection_lost = pick(rng) < 3;
  in.local_enable = pick(rng) < 5;
  in.local_disable = pick(rng) < 5;
  in.actual_speed_rpm = pick(rng) < 10 ? 1500 : 0;
  return in;
}

class round_trip : public ::testing::TestWithParam<std::size_t> {};

TEST_P(round_trip, dump_then_load_gives_identical_tables) {
  const profile& original = builtin_profile(GetParam());
  const std::string text = dump_profile_toml(original);
  profile_load_result r = load_profile_toml(text, original.name);
  ASSERT_TRUE(std::holds_alternative<custom_profile>(r))
      << std::get<profile_file_error>(r).message() << "\n"
      << text;
  expect_same_tables(original, std::get<custom_profile>(r).get());
}

TEST_P(round_trip, dump_of_the_loaded_profile_is_the_same_text) {
  const profile& original = builtin_profile(GetParam());
  const std::string text = dump_profile_toml(original);
  const custom_profile loaded = test::load_ok(text);
  EXPECT_EQ(dump_profile_toml(loaded.get()), text);
}

TEST_P(round_trip, loaded_profile_steps_exactly_like_the_built_in_on_a_random_run) {
  const profile& original = builtin_profile(GetParam());
  const custom_profile loaded = test::load_ok(dump_profile_toml(original));
  axis a = make_axis(original);
  axis b = make_axis(loaded.get());
  std::mt19937 rng(402u + static_cast<unsigned>(GetParam()));
  int transitions = 0;
  for (int i = 0; i < 5000; ++i) {
    if (i % 250 == 0) {
      // A power cycle now and then, so a latched class-4 fault (lexium32) cannot end the run.
      a = make_axis(original);
      b = make_axis(loaded.get());
    }
    const drive_inputs in = random_inputs(rng);
    const drive_outputs x = step(original, a, in);
    const drive_outputs y = step(loaded.get(), b, in);
    ASSERT_TRUE(test::same_outputs(x, y))
        << "step " << i << ": " << test::describe(x) << " vs " << test::describe(y);
    ASSERT_EQ(a.pending_row, b.pending_row) << "step " << i;
    ASSERT_EQ(a.flags, b.flags) << "step " << i;
    if (x.transition != no_transition) ++transitions;
  }
  // The run must exercise the tables, or the comparison proves nothing.
  EXPECT_GT(transitions, 200);
}

std::string profile_test_name(const ::testing::TestParamInfo<std::size_t>& info) {
  std::string name = builtin_profile(info.param).name;
  for (char& c : name) {
    if (c == '-') c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(every_builtin, round_trip,
                         ::testing::Range<std::size_t>(0, builtin_profile_count()),
                         profile_test_name);

TEST(round_trip_example, custom_drive_example_loads_dumps_and_loads_back_identically) {
  profile_load_result r = load_profile_toml_file(CIA402_EXAMPLE_PROFILES_DIR "/custom-drive.toml");
  ASSERT_TRUE(std::holds_alternative<custom_profile>(r))
      << std::get<profile_file_error>(r).message();
  const custom_profile& first = std::get<custom_profile>(r);
  const custom_profile second = test::load_ok(dump_profile_toml(first.get()));
  expect_same_tables(first.get(), second.get());
}

TEST(round_trip_example, names_with_quotes_and_backslashes_survive_the_round_trip) {
  const custom_profile c =
      test::load_ok("base = \"cia402\"\ntitle = \"a \\\"quoted\\\" \\\\ title\"\n");
  EXPECT_STREQ(c.get().title, "a \"quoted\" \\ title");
  const custom_profile back = test::load_ok(dump_profile_toml(c.get()));
  EXPECT_STREQ(back.get().title, "a \"quoted\" \\ title");
}

}  // namespace
}  // namespace cia402
