// Scenario files: what they accept, and every refusal with its line and reason.
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "cia402/sim/scenario.hpp"

namespace {

using namespace cia402;
using namespace cia402::sim;

const std::string header =
    "name = \"t\"\n"            // line 1
    "cycle = \"1ms\"\n"         // line 2
    "duration = \"100ms\"\n";   // line 3

scenario_error refused(const std::string& text) {
  scenario_load_result r = load_scenario_toml(text, "test.toml", CIA402_EXAMPLE_PROFILES_DIR);
  if (const auto* e = std::get_if<scenario_error>(&r)) return *e;
  ADD_FAILURE() << "accepted:\n" << text;
  return {};
}

scenario accepted(const std::string& text) {
  scenario_load_result r = load_scenario_toml(text, "test.toml", CIA402_EXAMPLE_PROFILES_DIR);
  if (const auto* e = std::get_if<scenario_error>(&r)) {
    ADD_FAILURE() << e->message();
    return {};
  }
  return std::get<scenario>(std::move(r));
}

void expect_refusal(const std::string& text, int line, const std::string& reason_part) {
  const scenario_error e = refused(text);
  EXPECT_EQ(e.line, line) << e.message();
  EXPECT_NE(e.reason.find(reason_part), std::string::npos) << e.message();
  EXPECT_EQ(e.source_name, "test.toml");
}

TEST(scenario_file, a_complete_file_loads_with_times_in_cycles_and_events_in_time_order) {
  const scenario s = accepted(header +
                              "objects.0x605A = 6\n"
                              "plant.brake = false\n"
                              "events = [\n"
                              "  { at = \"20ms\", cw = 0x000F },\n"
                              "  { at = \"10ms\", cw = 0x0006, target_velocity = 100 },\n"
                              "  { at = \"0.05s\", fault = 0x2310 },\n"
                              "]\n"
                              "expect = [\n"
                              "  { at = \"30ms\", state = \"operation_enabled\", torque = true },\n"
                              "  { transition = 11, between = [\"40ms\", \"60ms\"] },\n"
                              "  { at = \"99ms\", velocity = { within = [-1.5, 2] } },\n"
                              "  { always = \"coast_removes_torque_at_once\" },\n"
                              "]\n");
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.cycles, 101u);  // 0, 1 ms, ..., 100 ms
  EXPECT_FALSE(s.plant.brake_fitted);
  ASSERT_EQ(s.initial_writes.size(), 1u);
  EXPECT_EQ(s.initial_writes[0].index, 0x605A);
  EXPECT_EQ(s.initial_writes[0].sub, 0);
  ASSERT_EQ(s.events.size(), 4u);
  EXPECT_EQ(s.events[0].cycle, 10u);
  EXPECT_EQ(s.events[0].index, 0x60FF);  // within one event: writes of 0x60FF before cw
  EXPECT_EQ(s.events[1].index, 0x6040);
  EXPECT_EQ(s.events[2].cycle, 20u);
  EXPECT_EQ(s.events[3].what, scenario_event::kind::inject_fault);
  EXPECT_EQ(s.events[3].cycle, 50u);
  ASSERT_EQ(s.expectations.size(), 5u);
  EXPECT_EQ(s.expectations[0].expected_state, state::operation_enabled);
  EXPECT_EQ(s.expectations[2].first_cycle, 40u);
  EXPECT_EQ(s.expectations[2].last_cycle, 60u);
  EXPECT_EQ(s.expectations[3].low, -1500000);
  EXPECT_EQ(s.expectations[3].high, 2000000);
  EXPECT_EQ(s.expectations[4].what, expectation::kind::always);
}

TEST(scenario_file, toml_syntax_errors_give_their_line) {
  expect_refusal(header + "events = [\n  { at = \"1ms\" cw = 6 },\n]\n", 5, "");
}

TEST(scenario_file, a_missing_duration_is_refused) {
  expect_refusal("cycle = \"1ms\"\n", 1, "duration");
}

TEST(scenario_file, unknown_keys_are_refused_with_the_allowed_ones) {
  expect_refusal(header + "profil = \"cia402\"\n", 4, "unknown key 'profil'");
  expect_refusal(header + "events = [ { at = \"1ms\", cww = 6 } ]\n", 4, "unknown key 'cww'");
  expect_refusal(header + "[plant]\nbreak = true\n", 5, "allowed: brake");
}

TEST(scenario_file, root_keys_after_a_table_header_get_a_hint) {
  const scenario_error e = refused(header + "[objects]\n0x605A = 2\nevents = []\n");
  EXPECT_EQ(e.line, 6);
  EXPECT_NE(e.reason.find("before [objects]"), std::string::npos) << e.message();
}

TEST(scenario_file, times_need_a_unit_a_whole_number_of_cycles_and_to_lie_in_the_run) {
  expect_refusal(header + "events = [ { at = 10, cw = 6 } ]\n", 4, "unit");
  expect_refusal(header + "events = [ { at = \"10 minutes\", cw = 6 } ]\n", 4, "not a time");
  expect_refusal(header + "events = [ { at = \"1.5ms\", cw = 6 } ]\n", 4, "not a multiple of the cycle");
  expect_refusal(header + "events = [ { at = \"101ms\", cw = 6 } ]\n", 4, "after the end");
  expect_refusal(header + "events = [ { at = \"0.0000001s\", cw = 6 } ]\n", 4, "finer than a microsecond");
  expect_refusal("cycle = \"3ms\"\nduration = \"10ms\"\n", 2, "not a multiple of the cycle");
  expect_refusal("cycle = \"0ms\"\nduration = \"10ms\"\n", 1, "cycle");
}

TEST(scenario_file, the_profile_must_exist) {
  expect_refusal(header + "profile = \"cia-402\"\n", 4, "unknown profile 'cia-402'");
  expect_refusal(header + "profile = \"cia402\"\nprofile_file = \"custom-drive.toml\"\n", 5,
                 "either");
  expect_refusal(header + "profile_file = \"no-such-file.toml\"\n", 4, "cannot open");
  // Only a .toml file is read, and only a regular one: never a device, a FIFO or a foreign file
  // whose lines an error would show.
  expect_refusal(header + "profile_file = \"/dev/zero\"\n", 4, "must name a .toml profile file");
  expect_refusal(header + "profile_file = \"/etc/passwd\"\n", 4, "must name a .toml profile file");
  expect_refusal(header + "profile_file = \"/dev/stdin\"\n", 4, "must name a .toml profile file");
}

TEST(scenario_file, a_profile_file_is_found_next_to_the_scenario) {
  const scenario s = accepted(header + "profile_file = \"custom-drive.toml\"\n");
  EXPECT_EQ(std::string(s.drive_profile.get().name), "custom-drive");
}

TEST(scenario_file, start_up_writes_the_drive_refuses_are_refused_with_the_abort_code) {
  expect_refusal(header + "objects.0x605A = 9\n", 4, "0x06090030");
  expect_refusal(header + "[objects]\n0x6041 = 1\n", 5, "0x06010002");
  expect_refusal(header + "[objects]\n0x6083 = 0\n", 5, "0x06090032");
  expect_refusal(header + "[objects]\nquick_stop = 2\n", 5, "not an index");
  expect_refusal(header + "profile = \"no-quick-stop\"\nobjects.0x605A = 2\n", 5, "0x06020000");
}

TEST(scenario_file, events_are_checked_before_anything_runs) {
  expect_refusal(header + "events = [ { at = \"1ms\" } ]\n", 4, "needs an action");
  expect_refusal(header + "events = [ { cw = 6 } ]\n", 4, "needs 'at'");
  expect_refusal(header + "events = [ { at = \"1ms\", fault = 0 } ]\n", 4, "outside 1..65535");
  expect_refusal(header + "events = [ { at = \"1ms\", fault = 0x2310, fault_class = 1 } ]\n", 4,
                 "no error classes");
  expect_refusal(header + "events = [ { at = \"1ms\", fault_class = 1 } ]\n", 4, "needs a fault");
  expect_refusal(header + "events = [ { at = \"1ms\", clear_fault = \"some\" } ]\n", 4, "\"all\"");
  expect_refusal(header + "events = [ { at = \"1ms\", sto = \"on\" } ]\n", 4, "true or false");
  expect_refusal(header + "events = [ { at = \"1ms\", cw = 6, target_velocity = 1, abort = 1 } ]\n",
                 4, "exactly one write");
  expect_refusal(header + "events = [ { at = \"1ms\", write = { x605A = 1 } } ]\n", 4, "not an index");
}

TEST(scenario_file, lexium32_faults_may_carry_an_error_class) {
  const scenario s = accepted(header + "profile = \"lexium32\"\n"
                                       "events = [ { at = \"1ms\", fault = 0x2310, fault_class = 1 } ]\n");
  ASSERT_EQ(s.events.size(), 1u);
  EXPECT_EQ(s.events[0].fault_class, 1);
}

TEST(scenario_file, expectations_are_checked_before_anything_runs) {
  expect_refusal(header + "expect = [ { state = \"OPERATION_ENABLED\" } ]\n", 4, "needs 'at'");
  expect_refusal(header + "expect = [ { at = \"1ms\" } ]\n", 4, "needs a claim");
  expect_refusal(header + "expect = [ { at = \"1ms\", state = \"RUNNING\" } ]\n", 4, "unknown state 'RUNNING'");
  expect_refusal(header + "expect = [ { at = \"1ms\", state = \"START\" } ]\n", 4, "unknown state");
  expect_refusal(header + "expect = [ { at = \"1ms\", between = [\"1ms\", \"2ms\"], torque = true } ]\n",
                 4, "either 'at' or 'between'");
  expect_refusal(header + "expect = [ { between = [\"5ms\", \"2ms\"], torque = true } ]\n", 4,
                 "forwards");
  expect_refusal(header + "expect = [ { between = [\"5ms\"], torque = true } ]\n", 4, "two times");
  expect_refusal(header + "expect = [ { at = \"1ms\", velocity = { below = 1, above = 0 } } ]\n", 4,
                 "one comparison");
  expect_refusal(header + "expect = [ { at = \"1ms\", velocity = { within = [2, 1] } } ]\n", 4,
                 "LOW <= HIGH");
  expect_refusal(header + "expect = [ { at = \"1ms\", velocity = \"fast\" } ]\n", 4, "number of rpm");
  expect_refusal(header + "expect = [ { at = \"1ms\", brake = \"open\" } ]\n", 4, "engaged");
  expect_refusal(header + "expect = [ { at = \"1ms\", transition = 18 } ]\n", 4, "outside 0..17");
  expect_refusal(header + "expect = [ { at = \"1ms\", statusword = { mask = 0x0F, value = 0x10 } } ]\n",
                 4, "outside the mask");
  expect_refusal(header + "expect = [ { always = \"safe\" } ]\n", 4, "unknown rule 'safe'");
  expect_refusal(header + "expect = [ { always = \"coast_removes_torque_at_once\", at = \"1ms\" } ]\n",
                 4, "whole run");
  expect_refusal(header + "plant.brake = false\n"
                          "expect = [ { always = \"motion_waits_for_brake_release\" } ]\n",
                 5, "needs a brake");
}

TEST(scenario_file, the_error_message_names_file_line_and_column) {
  const scenario_error e = refused(header + "expect = [ { at = \"1ms\", state = \"RUNNING\" } ]\n");
  EXPECT_EQ(e.message().rfind("test.toml:4:", 0), 0u) << e.message();
}

TEST(scenario_file, a_missing_file_is_refused_without_a_line) {
  scenario_load_result r = load_scenario_file("/no/such/scenario.toml");
  ASSERT_TRUE(std::holds_alternative<scenario_error>(r));
  EXPECT_EQ(std::get<scenario_error>(r).line, 0);
}

}  // namespace

namespace {

using namespace cia402;
using namespace cia402::sim;

TEST(scenario_file, the_plant_takes_limit_switches_and_a_home_switch_with_two_edges_or_none) {
  const scenario s = accepted(header +
                              "plant.home_switch = { from = 50000, to = 80000 }\n"
                              "plant.negative_limit_switch = -200000\n"
                              "plant.positive_limit_switch = \"none\"\n");
  EXPECT_TRUE(s.plant.home_switch_fitted);
  EXPECT_EQ(s.plant.home_switch_position, std::optional<std::int64_t>(50000));
  EXPECT_EQ(s.plant.home_switch_end, std::optional<std::int64_t>(80000));
  EXPECT_EQ(s.plant.negative_limit_switch, std::optional<std::int64_t>(-200000));
  EXPECT_FALSE(s.plant.positive_limit_switch.has_value());
  // A negative home switch: active from the negative end of travel up to 0.
  const scenario negative = accepted(header + "plant.home_switch = { to = 0 }\n");
  EXPECT_FALSE(negative.plant.home_switch_position.has_value());
  EXPECT_EQ(negative.plant.home_switch_end, std::optional<std::int64_t>(0));
  const scenario none = accepted(header + "plant.home_switch = \"none\"\n");
  EXPECT_FALSE(none.plant.home_switch_fitted);
  // The integer form is today's: from there to the positive end.
  const scenario from = accepted(header + "plant.home_switch = 1234\n");
  EXPECT_EQ(from.plant.home_switch_position, std::optional<std::int64_t>(1234));
  EXPECT_FALSE(from.plant.home_switch_end.has_value());
  // The defaults leave today's scenarios as they were: a home switch from 50,000 up, limit switches
  // 100 revolutions either side.
  const scenario plain = accepted(header);
  EXPECT_EQ(plain.plant.home_switch_position, std::optional<std::int64_t>(50000));
  EXPECT_EQ(plain.plant.negative_limit_switch, std::optional<std::int64_t>(-1000000));
  EXPECT_EQ(plain.plant.positive_limit_switch, std::optional<std::int64_t>(1000000));
}

TEST(scenario_file, switches_that_cannot_be_are_refused_at_their_line) {
  expect_refusal(header + "plant.home_switch = { from = 80000, to = 50000 }\n", 4, "'to' >= 'from'");
  expect_refusal(header + "plant.home_switch = {}\n", 4, "needs from, to or both");
  expect_refusal(header + "plant.home_switch = { form = 1 }\n", 4, "form");
  expect_refusal(header + "plant.negative_limit_switch = \"off\"\n", 4, "\"none\"");
  expect_refusal(header + "plant.positive_limit_switch = 5\nplant.negative_limit_switch = 10\n", 4,
                 "at or above the negative one");
  expect_refusal(header + "plant.positive_limit_switch = 2000000000000\n", 4, "positive_limit_switch");
  expect_refusal(header + "plant.target_window = 70000\n", 4, "target_window");
}

}  // namespace
