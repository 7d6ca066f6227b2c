// One-click Enable and Stop, and the jog with its dead-man (issue 35; docs/instrument-page.md,
// "Enable, Stop and jog") on the in-process virtual drive, whose cycles are stepped here: Enable
// walks to OPERATION ENABLED with the core's planner and never resets a fault; the jog runs in
// profile velocity while its keep-alive comes and stops by itself within its time-to-live plus one
// cycle when it does not, on a release, and is refused outside OPERATION ENABLED.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <string>
#include <variant>

#include "page_steps.hpp"
#include "virtual_axis_page.hpp"
#include "cia402/profile.hpp"

namespace {

using cia402::page::accepted;
using cia402::page::testing::virtual_axis_page;
using cia402::page::page_command;
using cia402::page::plant_change;
using cia402::page::refused;
using cia402::page::reply;
using json = nlohmann::json;
using cia402::page::testing::steps::id_of;
using cia402::page::testing::steps::run;
using cia402::page::testing::steps::snapshot;

constexpr std::uint64_t ttl_us = 300000;  // 300 cycles of 1 ms
constexpr std::int64_t jog_rpm = 300;

json result_of(const virtual_axis_page& inst, std::uint64_t id) {
  const json s = snapshot(inst);
  for (const json& r : s["results"]) {
    if (r["id"] == id) return r;
  }
  ADD_FAILURE() << "no result " << id << " in " << s["results"];
  return json::object({{"outcome", nullptr}, {"text", ""}, {"transitions", json::array({0})}});
}

std::string refusal_of(const reply& r) {
  return std::holds_alternative<refused>(r) ? std::get<refused>(r).reason : std::string("accepted");
}

// Power-up, then SWITCH ON DISABLED.
struct commissioning : ::testing::Test {
  virtual_axis_page inst{cia402::standard_profile()};
  void SetUp() override {
    run(inst, 10);
    ASSERT_EQ(snapshot(inst)["state"], "SWITCH_ON_DISABLED");
  }
  void enable() {
    const std::uint64_t id = id_of(inst.enable());
    run(inst, 50);
    ASSERT_EQ(snapshot(inst)["state"], "OPERATION_ENABLED");
    ASSERT_EQ(result_of(inst, id)["outcome"], "done");
  }
  void plant(bool fault, bool sto) {
    plant_change c;
    c.fault = fault;
    c.fault_code = 0x2310;
    c.sto = sto;
    inst.change_plant(c);
  }
};

TEST_F(commissioning, enable_from_switch_on_disabled_reaches_operation_enabled_through_t2_t3_t4) {
  const std::uint64_t id = id_of(inst.enable());
  run(inst, 50);
  const json s = snapshot(inst);
  EXPECT_EQ(s["state"], "OPERATION_ENABLED");
  const json r = result_of(inst, id);
  EXPECT_EQ(r["outcome"], "done");
  EXPECT_EQ(r["transitions"], json({2, 3, 4}));
}

TEST_F(commissioning, enable_in_fault_reports_the_fault_with_its_text_and_resets_nothing) {
  plant(true, false);
  run(inst, 50);
  ASSERT_EQ(snapshot(inst)["state"], "FAULT");
  const std::string why = refusal_of(inst.enable());
  EXPECT_NE(why.find("0x2310"), std::string::npos) << why;
  EXPECT_NE(why.find("over-current"), std::string::npos) << why;
  EXPECT_NE(why.find("Fault reset"), std::string::npos) << why;
  // The cause gone, Enable still reports the fault and leaves it: only an explicit reset clears it.
  plant(false, false);
  run(inst, 50);
  EXPECT_NE(refusal_of(inst.enable()).find("FAULT"), std::string::npos);
  run(inst, 200);
  EXPECT_EQ(snapshot(inst)["state"], "FAULT");
  EXPECT_EQ(snapshot(inst)["control_word"], "0x0000");
  inst.command(page_command::fault_reset);
  run(inst, 50);
  ASSERT_EQ(snapshot(inst)["state"], "SWITCH_ON_DISABLED");
  enable();
}

TEST_F(commissioning, enable_under_sto_names_sto_and_changes_nothing) {
  plant(false, true);
  run(inst, 20);
  const std::string why = refusal_of(inst.enable());
  EXPECT_NE(why.find("STO"), std::string::npos) << why;
  run(inst, 100);
  EXPECT_EQ(snapshot(inst)["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(snapshot(inst)["control_word"], "0x0000");
}

TEST_F(commissioning, enable_stops_at_sto_asserted_during_the_walk_and_names_it) {
  const std::uint64_t id = id_of(inst.enable());
  run(inst, 1);
  plant(false, true);
  run(inst, 100);
  EXPECT_NE(snapshot(inst)["state"], "OPERATION_ENABLED");
  const json r = result_of(inst, id);
  EXPECT_EQ(r["outcome"], "refused");
  EXPECT_NE(r["text"].get<std::string>().find("STO"), std::string::npos) << r;
}

TEST_F(commissioning, enable_stopped_by_sto_leaves_no_enable_operation_to_act_once_sto_is_gone) {
  id_of(inst.enable());
  int cycles = 0;
  while (snapshot(inst)["decodes_to"] != "ENABLE_OPERATION" && cycles < 50) {
    inst.step();
    ++cycles;
  }
  ASSERT_NE(snapshot(inst)["state"], "OPERATION_ENABLED");
  plant(false, true);
  run(inst, 100);
  plant(false, false);
  run(inst, 200);
  EXPECT_NE(snapshot(inst)["state"], "OPERATION_ENABLED");
  EXPECT_NE(snapshot(inst)["decodes_to"], "ENABLE_OPERATION");
}

TEST_F(commissioning, stop_quick_stops_then_disables_voltage) {
  enable();
  plant_change v;
  v.target_velocity = 600;
  inst.change_plant(v);
  run(inst, 1000);
  ASSERT_EQ(snapshot(inst)["velocity"], 600);
  const std::uint64_t id = id_of(inst.stop());
  // Disable voltage waits for the quick stop's ramp: the shaft stands when the power goes off.
  int cycles = 0;
  while (snapshot(inst)["state"] != "SWITCH_ON_DISABLED" && cycles < 2000) {
    inst.step();
    ++cycles;
  }
  const json s = snapshot(inst);
  EXPECT_EQ(s["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(s["velocity"], 0);
  EXPECT_GT(cycles, 2);
  inst.step();  // the cycle after reports it
  const json r = result_of(inst, id);
  EXPECT_EQ(r["outcome"], "done");
  ASSERT_FALSE(r["transitions"].empty());
  EXPECT_EQ(r["transitions"].front(), 11);
  EXPECT_EQ(r["transitions"].back(), 12);
}

TEST_F(commissioning, jog_runs_in_profile_velocity_while_renewed) {
  enable();
  id_of(inst.jog(jog_rpm, ttl_us));
  for (int i = 0; i < 20; ++i) {
    run(inst, 100);
    id_of(inst.jog(jog_rpm, ttl_us));
  }
  const json s = snapshot(inst);
  EXPECT_EQ(s["requested_mode"], 3);
  EXPECT_EQ(s["target_velocity"], jog_rpm);
  EXPECT_EQ(s["velocity"], jog_rpm);
}

TEST_F(commissioning, jog_not_renewed_stops_within_its_time_to_live_plus_one_cycle) {
  enable();
  id_of(inst.jog(jog_rpm, ttl_us));
  run(inst, 100);  // the session switches to profile velocity (0x6061 confirms it), then turns
  ASSERT_EQ(snapshot(inst)["target_velocity"], jog_rpm);
  id_of(inst.jog(jog_rpm, ttl_us));  // the last keep-alive
  run(inst, 299);
  EXPECT_EQ(snapshot(inst)["target_velocity"], jog_rpm);
  run(inst, 2);  // the time-to-live, plus one cycle for the word to go out
  EXPECT_EQ(snapshot(inst)["target_velocity"], 0);
  run(inst, 1000);
  EXPECT_EQ(snapshot(inst)["velocity"], 0);
  EXPECT_EQ(snapshot(inst)["state"], "OPERATION_ENABLED");
}

TEST_F(commissioning, jog_released_stops_at_once) {
  enable();
  id_of(inst.jog(-jog_rpm, ttl_us));
  run(inst, 100);
  EXPECT_EQ(snapshot(inst)["target_velocity"], -jog_rpm);
  id_of(inst.jog(0, ttl_us));
  run(inst, 1);  // the release goes out in the next cycle
  EXPECT_EQ(snapshot(inst)["target_velocity"], 0);
}

TEST_F(commissioning, jog_released_before_it_turned_never_turns) {
  enable();
  id_of(inst.jog(jog_rpm, ttl_us));  // the switch to profile velocity is still under way
  id_of(inst.jog(0, ttl_us));
  for (int i = 0; i < 50; ++i) {
    run(inst, 10);
    ASSERT_EQ(snapshot(inst)["target_velocity"], 0) << "after " << 10 * (i + 1) << " cycles";
  }
  EXPECT_EQ(snapshot(inst)["velocity"], 0);
  EXPECT_EQ(snapshot(inst)["state"], "OPERATION_ENABLED");
}

TEST_F(commissioning, jog_outside_operation_enabled_is_refused_and_sets_nothing) {
  const reply r = inst.jog(jog_rpm, ttl_us);
  ASSERT_TRUE(std::holds_alternative<refused>(r));
  EXPECT_EQ(std::get<refused>(r).http_status, 409);
  EXPECT_NE(refusal_of(r).find("not OPERATION_ENABLED"), std::string::npos) << refusal_of(r);
  run(inst, 10);
  EXPECT_EQ(snapshot(inst)["target_velocity"], 0);
}

}  // namespace

#include "commissioning.hpp"

namespace {

// Each blocker of the way to OPERATION ENABLED, in the order they are named: a fault first (the walk
// never resets one), then STO, the DC link and local control (status word bit 9 off); none of them
// when all is well.
TEST(enable_blocker, names_a_fault_sto_no_dc_link_and_local_control_in_that_order) {
  using cia402::page::detail::enable_blocker;
  using cia402::state;
  EXPECT_EQ(enable_blocker(state::switch_on_disabled, 0, false, true, true), "");
  const std::string fault = enable_blocker(state::fault, 0x3220, true, false, false);
  EXPECT_NE(fault.find("0x3220"), std::string::npos) << fault;
  EXPECT_NE(enable_blocker(state::switch_on_disabled, 0, true, false, false).find("STO"), std::string::npos);
  EXPECT_NE(enable_blocker(state::ready_to_switch_on, 0, false, false, false).find("DC-link"), std::string::npos);
  const std::string local = enable_blocker(state::switched_on, 0, false, true, false);
  EXPECT_NE(local.find("bit 9"), std::string::npos) << local;
}

}  // namespace
