// Running scenarios: expectations pass and fail as they should, the log says so, the rules catch
// what they are for, and every example under examples/scenarios passes.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <initializer_list>
#include <set>
#include <string>
#include <variant>

#include "cia402/sim/scenario.hpp"

namespace {

using namespace cia402;
using namespace cia402::sim;

scenario load(const std::string& text) {
  scenario_load_result r = load_scenario_toml(text, "run.toml");
  if (const auto* e = std::get_if<scenario_error>(&r)) {
    ADD_FAILURE() << e->message();
    return {};
  }
  return std::get<scenario>(std::move(r));
}

const std::string enable =
    "cycle = \"1ms\"\n"
    "duration = \"200ms\"\n"
    "plant.brake_release_delay = \"10ms\"\n"
    "objects.0x6083 = 10000\n"
    "events = [\n"
    "  { at = \"2ms\", cw = 0x0006 },\n"   // T1 is at 1 ms: Shutdown from 2 ms on
    "  { at = \"3ms\", cw = 0x000F },\n"   // T3 at 3 ms, T4 at 4 ms
    "  { at = \"5ms\", target_velocity = 500 },\n"
    "]\n";

std::size_t count_failed(const run_result& r) {
  return static_cast<std::size_t>(std::count_if(r.log.begin(), r.log.end(),
                                                [](const log_entry& e) { return e.failed; }));
}

// The run counted `checks` expectations, `failures` of them failed, and it passed only without one.
void expect_tally(const run_result& r, int checks, int failures) {
  EXPECT_EQ(r.checks, checks);
  EXPECT_EQ(r.failures, failures);
  EXPECT_EQ(r.passed(), failures == 0);
}

// The run's log, as `cia402 scenario` prints it, names every one of `parts`; the whole log is shown
// when not.
::testing::AssertionResult log_names(const run_result& r, std::initializer_list<const char*> parts) {
  std::string log;
  for (const log_entry& e : r.log) log += format_log_entry(e) + "\n";
  for (const char* part : parts) {
    if (log.find(part) == std::string::npos) return ::testing::AssertionFailure() << "no \"" << part << "\" in:\n" << log;
  }
  return ::testing::AssertionSuccess();
}

TEST(scenario_run, true_expectations_pass_and_are_logged_as_pass) {
  const scenario s = load(enable +
                          "expect = [\n"
                          "  { transition = 4, at = \"4ms\" },\n"
                          "  { at = \"14ms\", velocity = 0, brake = \"released\" },\n"  // 4 + 10 ms
                          "  { at = \"15ms\", velocity = 10 },\n"
                          "  { between = [\"70ms\", \"200ms\"], velocity = 500, state = \"OPERATION_ENABLED\" },\n"
                          "]\n");
  const run_result r = run_scenario(s);
  expect_tally(r, 6, 0);
  EXPECT_EQ(r.trace.size(), 201u);
  EXPECT_EQ(count_failed(r), 0u);
}

TEST(scenario_run, false_expectations_fail_with_what_was_seen) {
  const scenario s = load(enable +
                          "expect = [\n"
                          "  { at = \"100ms\", state = \"QUICK_STOP_ACTIVE\" },\n"
                          "  { at = \"100ms\", velocity = { below = 100 } },\n"
                          "  { transition = 11, between = [\"50ms\", \"60ms\"] },\n"
                          "  { between = [\"0ms\", \"200ms\"], torque = false },\n"
                          "  { at = \"100ms\", statusword = 0x0000 },\n"
                          "]\n");
  const run_result r = run_scenario(s);
  expect_tally(r, 5, 5);
  EXPECT_TRUE(log_names(r, {"FAIL  state QUICK_STOP_ACTIVE at 0.100 s (line 11): state is OPERATION_ENABLED",
                           "velocity is 500 rpm", "not taken in the window",
                           "torque is on at 0.004 s"}));  // the torque fails at T4
}

TEST(scenario_run, writes_refused_unexpectedly_or_accepted_against_an_expected_abort_fail) {
  const scenario s = load(enable.substr(0, enable.size() - 2) +
                          "  { at = \"5ms\", write = { 0x605A = 9 } },\n"
                          "  { at = \"6ms\", write = { 0x605A = 5 }, abort = 0x06090030 },\n"
                          "  { at = \"7ms\", write = { 0x605A = 10 }, abort = 0x06090030 },\n"
                          "]\n");
  const run_result r = run_scenario(s);
  expect_tally(r, 3, 2);
  EXPECT_TRUE(log_names(r, {"FAIL  write 0x605A = 9: refused, SDO abort 0x06090030",
                           "accepted, but the scenario expects SDO abort 0x06090030", "refused as expected"}));
}

TEST(scenario_run, the_log_has_one_line_per_event_transition_and_expectation_in_time_order) {
  const scenario s = load(enable + "expect = [ { at = \"150ms\", torque = true } ]\n");
  const run_result r = run_scenario(s, run_options{false});
  EXPECT_TRUE(r.trace.empty());
  int events = 0, transitions = 0, expectations = 0;
  std::uint64_t last = 0;
  for (const log_entry& e : r.log) {
    EXPECT_GE(e.time_us, last);
    last = e.time_us;
    events += e.what == log_entry::kind::event;
    transitions += e.what == log_entry::kind::transition;
    expectations += e.what == log_entry::kind::expectation;
  }
  EXPECT_EQ(events, 3);
  EXPECT_EQ(transitions, 5);  // T0 T1 T2 T3 T4
  EXPECT_EQ(expectations, 1);
  EXPECT_EQ(format_log_entry(r.log[0]).substr(0, 20), "    0.000 s  T0    S");
}

// The rules, on rows made by hand, so each can be seen to fail.
trace_row row(bool torque, stop_ramp ramp, bool brake_engaged, std::int64_t velocity = 0) {
  trace_row r;
  r.torque = torque;
  r.ramp = ramp;
  r.brake_engaged = brake_engaged;
  r.velocity = velocity;
  r.control_word = 0x000B;  // a quick stop
  return r;
}

TEST(invariants, brake_before_torque_off_fails_when_a_ramped_stop_drops_torque_on_an_open_brake) {
  const profile& p = standard_profile();
  std::string why;
  const trace_row ramping = row(true, stop_ramp::quick_stop, false);
  EXPECT_FALSE(invariant_holds(invariant::brake_engaged_before_torque_off, p, &ramping,
                               row(false, stop_ramp::none, false), why));
  EXPECT_NE(why.find("quick_stop"), std::string::npos);
  EXPECT_TRUE(invariant_holds(invariant::brake_engaged_before_torque_off, p, &ramping,
                              row(false, stop_ramp::none, true), why));
  EXPECT_TRUE(invariant_holds(invariant::brake_engaged_before_torque_off, p, &ramping,
                              row(false, stop_ramp::coast, false), why))
      << "a coast that takes over is exempt";
  trace_row disable_voltage = row(false, stop_ramp::none, false);
  disable_voltage.control_word = 0x0000;
  EXPECT_TRUE(invariant_holds(invariant::brake_engaged_before_torque_off, p, &ramping,
                              disable_voltage, why))
      << "T9 interrupting the stop is exempt";
}

TEST(invariants, motion_waits_fails_when_speed_grows_from_a_cycle_with_the_brake_engaged) {
  const profile& p = standard_profile();
  std::string why;
  const trace_row held = row(true, stop_ramp::none, true, 0);
  EXPECT_FALSE(invariant_holds(invariant::motion_waits_for_brake_release, p, &held,
                               row(true, stop_ramp::none, false, 5), why));
  const trace_row open = row(true, stop_ramp::none, false, 0);
  EXPECT_TRUE(invariant_holds(invariant::motion_waits_for_brake_release, p, &open,
                              row(true, stop_ramp::none, false, 5), why));
  const trace_row braking = row(false, stop_ramp::coast, true, -100);
  EXPECT_TRUE(invariant_holds(invariant::motion_waits_for_brake_release, p, &braking,
                              row(false, stop_ramp::coast, true, -80), why));
}

TEST(invariants, coast_rule_fails_for_torque_in_a_coasting_or_sto_cycle) {
  const profile& p = standard_profile();
  std::string why;
  EXPECT_FALSE(invariant_holds(invariant::coast_removes_torque_at_once, p, nullptr,
                               row(true, stop_ramp::coast, false), why));
  trace_row sto = row(true, stop_ramp::none, false);
  sto.sto = true;
  EXPECT_FALSE(invariant_holds(invariant::coast_removes_torque_at_once, p, nullptr, sto, why));
  EXPECT_TRUE(invariant_holds(invariant::coast_removes_torque_at_once, p, nullptr,
                              row(false, stop_ramp::coast, false), why));
}

// ------------------------------------------------------------------------------------------------

std::vector<std::filesystem::path> example_files() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(CIA402_EXAMPLE_SCENARIOS_DIR)) {
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(examples, every_example_scenario_loads_runs_and_passes_every_expectation) {
  const auto files = example_files();
  ASSERT_GE(files.size(), 14u);
  for (const auto& f : files) {
    scenario_load_result r = load_scenario_file(f.string());
    if (const auto* e = std::get_if<scenario_error>(&r)) {
      ADD_FAILURE() << e->message();
      continue;
    }
    const scenario& s = std::get<scenario>(r);
    const run_result result = run_scenario(s, run_options{false});
    EXPECT_TRUE(result.passed()) << f.filename() << ": " << result.failures << " failed";
    EXPECT_GE(result.checks, 10) << f.filename() << " pins too little";
    const bool has_rule = std::any_of(s.expectations.begin(), s.expectations.end(), [](const expectation& e) {
      return e.what == expectation::kind::always &&
             e.rule == invariant::brake_engaged_before_torque_off;
    });
    EXPECT_TRUE(has_rule) << f.filename() << " does not check the brake before torque off";
  }
}

TEST(examples, quick_stop_examples_cover_every_0x605A_code_of_the_standard_profile) {
  std::set<std::int64_t> codes;
  for (const auto& f : example_files()) {
    scenario_load_result r = load_scenario_file(f.string());
    ASSERT_TRUE(std::holds_alternative<scenario>(r)) << f;
    const scenario& s = std::get<scenario>(r);
    if (f.filename().string().rfind("quick-stop-", 0) != 0) continue;
    EXPECT_EQ(std::string(s.drive_profile.get().name), "cia402");
    for (const scenario::object_write& w : s.initial_writes) {
      if (w.index == 0x605A) codes.insert(w.value);
    }
  }
  EXPECT_EQ(codes, (std::set<std::int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8}));
}

}  // namespace
