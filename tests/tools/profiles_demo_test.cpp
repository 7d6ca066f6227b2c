// `cia402 profiles` and `cia402 demo`.
#include <gtest/gtest.h>

#include <algorithm>

#include <sstream>
#include <string>
#include <variant>

#include "cia402/profile.hpp"
#include "cia402/profile_file.hpp"
#include "replay_support.hpp"

namespace cia402 {
namespace {

TEST(profiles, list_has_one_line_per_builtin_with_name_seed_and_title) {
  const auto r = test::run_tool({"profiles"});
  EXPECT_EQ(r.exit_code, 0);
  ASSERT_EQ(r.lines.size(), builtin_profile_count());
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    EXPECT_EQ(r.lines[i].rfind(p.name, 0), 0u) << r.lines[i];
    EXPECT_NE(r.lines[i].find(p.seed), std::string::npos) << r.lines[i];
    EXPECT_NE(r.lines[i].find(p.title), std::string::npos) << r.lines[i];
  }
}

TEST(profiles, list_names_all_five_seed_files) {
  const auto r = test::run_tool({"profiles"});
  for (const char* seed :
       {"000_44b471b7401b86be.txt", "001_f9323c8e43dc977c.txt", "002_522d2c0bb8f5a5f8.txt",
        "003_83442f2f4b0b2bb9.txt", "004_e07fd68605b3a8c6.txt"}) {
    EXPECT_NE(r.out.find(seed), std::string::npos) << seed;
  }
}

TEST(profiles, dump_of_every_builtin_loads_back_under_its_name) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const std::string name = builtin_profile(i).name;
    const auto r = test::run_tool({"profiles", "--dump", name});
    ASSERT_EQ(r.exit_code, 0) << name;
    profile_load_result loaded = load_profile_toml(r.out, name);
    ASSERT_TRUE(std::holds_alternative<custom_profile>(loaded))
        << std::get<profile_file_error>(loaded).message();
    EXPECT_EQ(std::get<custom_profile>(loaded).get().name, name);
    EXPECT_EQ(std::get<custom_profile>(loaded).get().row_count, builtin_profile(i).row_count);
  }
}

TEST(profiles, dump_of_an_unknown_profile_is_a_usage_error) {
  const auto r = test::run_tool({"profiles", "--dump", "cia403"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("cia403"), std::string::npos);
}

// One printed cycle of the demo: "step cw state statusword T torque brake ramp rpm".
struct demo_line {
  std::string state;
  std::string transition;
  std::string torque;
  std::string brake;
  std::string ramp;
  long rpm = -1;
};

std::vector<demo_line> demo_cycles(const std::string& out) {
  std::vector<demo_line> cycles;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] < '0' || line[0] > '9') continue;
    std::istringstream words(line);
    std::string step, cw, sw;
    demo_line d;
    words >> step >> cw >> d.state >> sw >> d.transition >> d.torque >> d.brake >> d.ramp >> d.rpm;
    cycles.push_back(d);
  }
  return cycles;
}

class demo : public ::testing::TestWithParam<std::size_t> {};

TEST_P(demo, runs_through_enable_fault_and_reset_and_ends_in_switch_on_disabled_by_t15) {
  const auto r = test::run_tool({"demo", "--profile", builtin_profile(GetParam()).name});
  EXPECT_EQ(r.exit_code, 0);
  const auto cycles = demo_cycles(r.out);
  ASSERT_GT(cycles.size(), 20u) << r.out;
  bool enabled = false;
  bool faulted = false;
  std::string last_transition;
  for (const demo_line& c : cycles) {
    enabled = enabled || c.state == "OPERATION_ENABLED";
    faulted = faulted || c.state == "FAULT";
    if (c.transition != "-") last_transition = c.transition;
  }
  EXPECT_TRUE(enabled) << r.out;
  EXPECT_TRUE(faulted) << r.out;
  EXPECT_EQ(cycles.back().state, "SWITCH_ON_DISABLED") << r.out;
  EXPECT_EQ(last_transition, "15") << r.out;
}

TEST_P(demo, the_simulated_motor_speeds_up_only_when_running_and_ends_at_rest) {
  const auto r = test::run_tool({"demo", "--profile", builtin_profile(GetParam()).name});
  const auto cycles = demo_cycles(r.out);
  ASSERT_FALSE(cycles.empty()) << r.out;
  long top = 0;
  long before = 0;
  for (const demo_line& c : cycles) {
    top = std::max(top, c.rpm);
    if (c.rpm > before) {
      EXPECT_EQ(c.state, "OPERATION_ENABLED") << "only a running drive drives the motor\n" << r.out;
      EXPECT_EQ(c.torque, "on") << r.out;
    }
    before = c.rpm;
  }
  EXPECT_EQ(top, 300) << r.out;
  EXPECT_EQ(cycles.back().rpm, 0) << r.out;
}

TEST_P(demo, torque_and_released_brake_appear_only_where_the_profile_allows_torque) {
  const profile& p = builtin_profile(GetParam());
  const auto r = test::run_tool({"demo", "--profile", p.name});
  for (const demo_line& c : demo_cycles(r.out)) {
    state s;
    ASSERT_TRUE(parse_state(c.state, s)) << c.state;
    if (!p.torque_allowed(s)) {
      EXPECT_EQ(c.torque, "off") << c.state;
      EXPECT_EQ(c.brake, "engaged") << c.state;
    }
    if (c.torque == "off") EXPECT_EQ(c.brake, "engaged") << c.state;  // S12
  }
}

INSTANTIATE_TEST_SUITE_P(every_builtin, demo,
                         ::testing::Range<std::size_t>(0, builtin_profile_count()),
                         [](const auto& info) {
                           std::string n = builtin_profile(info.param).name;
                           for (char& c : n) {
                             if (c == '-') c = '_';
                           }
                           return n;
                         });

TEST(demo_standard, quick_stop_passes_through_quick_stop_active_then_t12) {
  const auto cycles = demo_cycles(test::run_tool({"demo"}).out);
  bool t11 = false;
  bool t12 = false;
  for (const demo_line& c : cycles) {
    if (c.transition == "11") t11 = c.state == "QUICK_STOP_ACTIVE";
    if (c.transition == "12") t12 = t11 && c.state == "SWITCH_ON_DISABLED";
  }
  EXPECT_TRUE(t11);
  EXPECT_TRUE(t12);
}

TEST(demo_no_quick_stop, never_shows_quick_stop_active) {
  const auto r = test::run_tool({"demo", "--profile", "no-quick-stop"});
  EXPECT_EQ(r.out.find("QUICK_STOP_ACTIVE"), std::string::npos) << r.out;
}

TEST(demo_profile_file, example_profile_runs) {
  const auto r =
      test::run_tool({"demo", "--profile-file", CIA402_EXAMPLE_PROFILES_DIR "/custom-drive.toml"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("profile custom-drive"), std::string::npos);
}

}  // namespace
}  // namespace cia402
