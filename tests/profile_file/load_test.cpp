// Profile files that load: the example, a base with overrides, a complete file without base.
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "cia402/drive.hpp"
#include "cia402/profile_file.hpp"
#include "helpers.hpp"

namespace cia402 {
namespace {

using test::load_error;
using test::load_ok;

std::optional<transition_row> find_row(const profile& p, int number) {
  for (std::size_t i = 0; i < p.row_count; ++i) {
    if (p.row(i).number == number) return p.row(i);
  }
  return std::nullopt;
}

// Powers up a drive and commands Shutdown; returns the state it ends in.
state after_shutdown(const profile& p, bool dc_link) {
  drive d(p);
  drive_inputs in;
  in.dc_link = dc_link;
  for (int i = 0; i < 4; ++i) d.step(in);
  in.control_word = 0x06;
  d.step(in);
  return d.current();
}

TEST(profile_file_load, example_custom_drive_loads_with_the_options_its_comments_promise) {
  profile_load_result r = load_profile_toml_file(CIA402_EXAMPLE_PROFILES_DIR "/custom-drive.toml");
  ASSERT_TRUE(std::holds_alternative<custom_profile>(r))
      << std::get<profile_file_error>(r).message();
  const profile& p = std::get<custom_profile>(r).get();
  EXPECT_STREQ(p.name, "custom-drive");
  EXPECT_EQ(p.spec(option::quick_stop).supported, (1u << 2) | (1u << 6));
  EXPECT_EQ(p.spec(option::quick_stop).default_value, 6);
  EXPECT_EQ(p.spec(option::fault_reaction).supported, (1u << 0) | (1u << 2));
  int row = -1;
  EXPECT_EQ(check_profile(p, row), nullptr);
}

TEST(profile_file_load, example_custom_drive_shutdown_without_dc_link_stays_in_switch_on_disabled) {
  profile_load_result r = load_profile_toml_file(CIA402_EXAMPLE_PROFILES_DIR "/custom-drive.toml");
  ASSERT_TRUE(std::holds_alternative<custom_profile>(r));
  const profile& p = std::get<custom_profile>(r).get();
  EXPECT_EQ(after_shutdown(p, false), state::switch_on_disabled);
  EXPECT_EQ(after_shutdown(p, true), state::ready_to_switch_on);
  // The standard's T2 has no such guard (seed 002_522d2c0bb8f5a5f8.txt row 2).
  EXPECT_EQ(after_shutdown(standard_profile(), false), state::ready_to_switch_on);
}

TEST(profile_file_load, base_with_option_override_keeps_every_base_row_and_changes_the_option) {
  const custom_profile c = load_ok(R"(base = "cia402"
name = "qs-hold"
[options.0x605A]
supported = [2, 6]
default = 6
)");
  const profile& p = c.get();
  const profile& base = standard_profile();
  EXPECT_STREQ(p.name, "qs-hold");
  EXPECT_STREQ(p.seed, base.seed);
  ASSERT_EQ(p.row_count, base.row_count);
  for (std::size_t i = 0; i < p.row_count; ++i) {
    EXPECT_EQ(p.row(i).number, base.row(i).number);
    EXPECT_EQ(p.row(i).from, base.row(i).from);
    EXPECT_EQ(p.row(i).any, base.row(i).any);
  }
  EXPECT_EQ(p.spec(option::quick_stop).supported, (1u << 2) | (1u << 6));
  EXPECT_EQ(p.spec(option::quick_stop).default_value, 6);
  EXPECT_EQ(p.spec(option::shutdown).supported, base.spec(option::shutdown).supported);
}

TEST(profile_file_load, base_without_name_inherits_the_base_name) {
  const custom_profile c = load_ok("base = \"lexium32\"\n");
  EXPECT_STREQ(c.get().name, "lexium32");
  EXPECT_EQ(c.get().speed_limit_rpm, 1000);
  EXPECT_TRUE(c.get().error_classes);
}

TEST(profile_file_load, base_option_default_alone_keeps_the_supported_values) {
  const custom_profile c = load_ok("base = \"cia402\"\n[options.0x605A]\ndefault = 5\n");
  EXPECT_EQ(c.get().spec(option::quick_stop).default_value, 5);
  EXPECT_EQ(c.get().spec(option::quick_stop).supported,
            standard_profile().spec(option::quick_stop).supported);
}

TEST(profile_file_load, base_state_override_changes_only_the_given_key) {
  const custom_profile c =
      load_ok("base = \"cia402\"\n[states.switched_on]\nactivity = \"hold\"\n");
  const state_info& info = c.get().info(state::switched_on);
  EXPECT_EQ(info.activity, state_activity::hold);
  EXPECT_EQ(info.status_pattern, 0x23);
  EXPECT_TRUE(c.get().torque_allowed(state::switched_on));
}

TEST(profile_file_load, decoder_in_a_based_file_replaces_the_whole_base_decoder) {
  const custom_profile c = load_ok(R"(base = "cia402"
[[decoder]]
mask = 0x02
value = 0x00
command = "disable_voltage"
)");
  EXPECT_EQ(c.get().decoder_size, 1);
  // Without the base's bit-2 rule, 0x0B is no longer a quick stop.
  EXPECT_EQ(c.get().decode(0x0B), command::enable_operation);
  EXPECT_EQ(c.get().decode(0x09), command::disable_voltage);
}

TEST(profile_file_load, rows_in_a_based_file_replace_the_whole_base_table) {
  const custom_profile c = load_ok(test::toml({"base = \"cia402\"\n", test::t0_row}));
  ASSERT_EQ(c.get().row_count, 1);
  EXPECT_EQ(c.get().row(0).to, state::not_ready_to_switch_on);
}

TEST(profile_file_load, complete_file_without_base_loads_and_start_defaults_to_idle_zero) {
  const custom_profile c = load_ok(test::minimal_profile);
  const profile& p = c.get();
  EXPECT_STREQ(p.name, "minimal");
  EXPECT_STREQ(p.seed, "");
  EXPECT_EQ(p.row_count, 6);
  EXPECT_EQ(p.decoder_size, 1);
  EXPECT_EQ(p.info(state::start).status_pattern, 0);
  EXPECT_EQ(p.info(state::start).activity, state_activity::idle);
  EXPECT_EQ(p.spec(option::halt).default_value, 1);
  EXPECT_FALSE(p.spec(option::halt).exists());
}

TEST(profile_file_load, row_optional_keys_default_to_immediate_no_flags_no_guards) {
  const custom_profile c = load_ok(test::minimal_profile);
  const std::optional<transition_row> t2 = find_row(c.get(), 2);
  ASSERT_TRUE(t2.has_value());
  EXPECT_EQ(t2->stop, row_stop::immediate);
  EXPECT_EQ(t2->flags, 0);
  EXPECT_TRUE(t2->all.empty());
  EXPECT_TRUE(t2->none.empty());
}

TEST(profile_file_load, every_row_key_is_read_into_the_row) {
  const custom_profile c = load_ok(test::toml({"base = \"cia402\"\n", test::t0_row, R"([[rows]]
number = 17
from = ["operation_enabled", "quick_stop_active"]
to = "switch_on_disabled"
any = ["stop_and_inhibit", "local_disable"]
all = ["dc_link"]
none = ["sto", "halt"]
stop = "quick_stop_ramp"
interrupts_stop = true
clears_setpoints = true
)"}));
  ASSERT_EQ(c.get().row_count, 2);
  const transition_row r = c.get().row(1);
  EXPECT_EQ(r.number, 17);
  EXPECT_EQ(r.from, state_bit(state::operation_enabled) | state_bit(state::quick_stop_active));
  EXPECT_EQ(r.to, state::switch_on_disabled);
  EXPECT_EQ(r.any, fact::stop_and_inhibit | fact::local_disable);
  EXPECT_EQ(r.all, fact_set(fact::dc_link));
  EXPECT_EQ(r.none, fact::sto | fact::halt);
  EXPECT_EQ(r.stop, row_stop::quick_stop_ramp);
  EXPECT_EQ(r.flags, row_flag::interrupts_stop | row_flag::clears_setpoints);
}

TEST(profile_file_load, names_in_upper_case_or_with_dashes_are_accepted) {
  const custom_profile c = load_ok(R"(base = "cia402"
[[rows]]
number = 0
from = ["START"]
to = "Not-Ready-To-Switch-On"
any = ["AUTOMATIC"]
stop = "Slow-Down-Ramp"
[[decoder]]
mask = 0x02
value = 0x00
command = "DISABLE_VOLTAGE"
[states.QUICK_STOP_ACTIVE]
activity = "Quick_Stop"
[options.0x605a]
default = 6
)");
  EXPECT_EQ(c.get().row(0).to, state::not_ready_to_switch_on);
  EXPECT_EQ(c.get().row(0).stop, row_stop::slow_down_ramp);
  EXPECT_EQ(c.get().spec(option::quick_stop).default_value, 6);
}

TEST(profile_file_load, inline_tables_load_like_table_headers) {
  const custom_profile c = load_ok(R"(base = "cia402"
rows = [ { number = 0, from = ["start"], to = "not_ready_to_switch_on", any = ["automatic"] } ]
options = { 0x605A = { supported = [1, 5], default = 5 } }
)");
  EXPECT_EQ(c.get().row_count, 1);
  EXPECT_EQ(c.get().spec(option::quick_stop).supported, (1u << 1) | (1u << 5));
}

TEST(profile_file_load, loaded_profile_outlives_its_copy_source) {
  custom_profile copy;
  {
    const custom_profile c = load_ok("base = \"ax2000-profibus\"\nname = \"copied\"\n");
    copy = c;
  }
  EXPECT_STREQ(copy.get().name, "copied");
  EXPECT_EQ(copy.get().decode(0x1F), command::enable_operation);
  EXPECT_EQ(copy.get().decode(0x0F), command::quick_stop);
}

TEST(profile_file_load, missing_file_is_refused_with_its_path_and_no_line) {
  profile_load_result r = load_profile_toml_file("/nonexistent/dir/none.toml");
  ASSERT_TRUE(std::holds_alternative<profile_file_error>(r));
  const profile_file_error& e = std::get<profile_file_error>(r);
  EXPECT_EQ(e.line, 0);
  EXPECT_EQ(e.source_name, "/nonexistent/dir/none.toml");
  EXPECT_EQ(e.message(), "/nonexistent/dir/none.toml: cannot open the file");
}

TEST(profile_file_load, error_message_names_source_line_column_and_reason) {
  const profile_file_error e = load_error("base = \"cia402\"\nnmae = \"x\"\n");
  EXPECT_EQ(e.message().rfind("test.toml:2:1: unknown key 'nmae'", 0), 0u) << e.message();
}

}  // namespace
}  // namespace cia402
