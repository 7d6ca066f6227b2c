// What the page tells a commissioning engineer about the drive beyond its state (issue 35): why
// Enable is blocked, 0x60FD's limit and home switches, and the errors the drive showed, each in the
// snapshot the page draws from.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <string>

#include "page_steps.hpp"
#include "virtual_axis_page.hpp"
#include "cia402/profile.hpp"

using cia402::page::page_command;
using cia402::page::plant_change;
using cia402::page::testing::virtual_axis_page;
using json = nlohmann::json;
using namespace cia402::page::testing::steps;

namespace {

// "Why can't I enable?" (issue 35): the snapshot names what blocks the way to OPERATION ENABLED now,
// from the drive's own inputs, and nothing once nothing does or the drive is enabled.
TEST(diagnostics, the_snapshot_says_what_blocks_enable_and_nothing_once_it_is_gone) {
  virtual_axis_page inst(cia402::standard_profile());
  run(inst, 10);
  EXPECT_TRUE(snapshot(inst)["enable_blocker"].is_null()) << snapshot(inst)["enable_blocker"];
  plant_change sto;
  sto.sto = true;
  inst.change_plant(sto);
  run(inst, 50);
  json why = snapshot(inst)["enable_blocker"];
  ASSERT_TRUE(why.is_string());
  EXPECT_NE(why.get<std::string>().find("STO"), std::string::npos) << why;
  sto.sto = false;
  plant_change no_dc;
  no_dc.dc_link = false;
  inst.change_plant(sto);
  inst.change_plant(no_dc);
  run(inst, 50);
  why = snapshot(inst)["enable_blocker"];
  ASSERT_TRUE(why.is_string());
  EXPECT_NE(why.get<std::string>().find("DC-link"), std::string::npos) << why;
  plant_change fault = fault_of(0x2310);
  fault.dc_link = true;
  inst.change_plant(fault);
  run(inst, 300);
  why = snapshot(inst)["enable_blocker"];
  ASSERT_TRUE(why.is_string());
  EXPECT_NE(why.get<std::string>().find("0x2310"), std::string::npos) << why;
  EXPECT_NE(why.get<std::string>().find("over-current"), std::string::npos) << why;
  inst.change_plant(no_fault());
  inst.command(page_command::fault_reset);
  run(inst, 300);
  EXPECT_EQ(snapshot(inst)["state"], "SWITCH_ON_DISABLED");
  EXPECT_TRUE(snapshot(inst)["enable_blocker"].is_null()) << snapshot(inst)["enable_blocker"];
}

// 0x60FD digital inputs (CiA 402: bit 0 negative limit, bit 1 positive limit, bit 2 home switch) in
// the snapshot, for the page's lamps: the home switch lights where the plant has it (from 50,000
// increments on, its default) and not at 0.
TEST(diagnostics, the_snapshot_shows_0x60fd_with_the_home_switch_where_the_plant_has_it) {
  virtual_axis_page inst(cia402::standard_profile());
  run(inst, 10);
  id_of(inst.write_object(0x6060, 1));
  enable(inst);
  EXPECT_EQ(snapshot(inst)["digital_inputs"].get<int>() & 0x7, 0);
  id_of(inst.write_object(0x607A, 60000));
  id_of(inst.new_setpoint());
  run(inst, 20);
  const json s = run_until_status_bit(inst, 10, 40000);
  ASSERT_EQ(s["position"], 60000);
  EXPECT_EQ(s["digital_inputs"].get<int>() & 0x7, 0x4) << "home switch on, no limit switch";
}

}  // namespace

namespace {

// The errors the page saw in 0x603F, newest first, each once per time it came, with the drive's
// time and the code's text (issue 35's timestamped error history).
TEST(diagnostics, the_snapshot_lists_each_error_the_drive_showed_newest_first_with_its_time) {
  virtual_axis_page inst(cia402::standard_profile());
  run(inst, 10);
  EXPECT_TRUE(snapshot(inst)["error_history"].empty());
  const auto fault = [&inst](std::uint16_t code) {
    inst.change_plant(fault_of(code));
    run(inst, 100);
    inst.change_plant(no_fault());
    inst.command(page_command::fault_reset);
    run(inst, 100);
  };
  fault(0x2310);
  fault(0x5530);
  fault(0x2310);
  const json h = snapshot(inst)["error_history"];
  ASSERT_EQ(h.size(), 3u) << h;
  EXPECT_EQ(h[0]["code"], "0x2310");
  EXPECT_EQ(h[1]["code"], "0x5530");
  EXPECT_EQ(h[2]["code"], "0x2310");
  EXPECT_EQ(h[0]["text"], "continuous over-current");
  EXPECT_GT(h[0]["time_ms"].get<int>(), h[1]["time_ms"].get<int>());
  EXPECT_GT(h[1]["time_ms"].get<int>(), h[2]["time_ms"].get<int>());
  EXPECT_EQ(snapshot(inst)["state"], "SWITCH_ON_DISABLED") << "each fault was reset";
  EXPECT_TRUE(h[0]["unix_ms"].is_null()) << "no clock of day given: the drive's time alone";
}

// Given the time of day, each error seen carries it too: when it happened, not only the drive's time.
TEST(diagnostics, an_error_seen_is_stamped_with_the_time_of_day_the_page_is_given) {
  std::uint64_t wall_us = 1'764'000'000'000'000;  // a time of day the test sets
  cia402::page::axis_page_config c;
  c.wall_clock_us = [&wall_us] { return wall_us; };
  virtual_axis_page inst(cia402::standard_profile(), c);
  run(inst, 10);
  wall_us += 5'000'000;
  inst.change_plant(fault_of(0x2310));
  run(inst, 100);
  const json h = snapshot(inst)["error_history"];
  ASSERT_EQ(h.size(), 1u) << h;
  EXPECT_EQ(h[0]["unix_ms"].get<std::uint64_t>(), wall_us / 1000);
}

}  // namespace
