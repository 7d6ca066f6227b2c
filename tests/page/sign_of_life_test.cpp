// The page's sign of life (issue 33; docs/page.md, "Sign of life") on the in-process virtual drive:
// a drive left in OPERATION ENABLED is stopped as its 0x6007 says once no client renewed the lease
// for the lease time, and not before; the stop is commanded within the lease plus one cycle and the
// shaft stands once the stop ramp ran (0x6085 from the speed it had). The stops per 0x6007 value are
// the standard's (cia402-reference.md §3: 0 no action, 1 fault signal, 2 Disable voltage, 3 Quick
// stop) as a master can command them (cia402/lost_client.hpp).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <string>

#include "virtual_axis_page.hpp"
#include "cia402/profile.hpp"

namespace {

using cia402::page::testing::virtual_axis_page;
using cia402::page::axis_page_config;
using cia402::page::page_command;
using cia402::page::plant_change;
using json = nlohmann::json;

constexpr int lease_ms = 200;  // cycles of 1 ms
constexpr int turning_rpm = 600;

json snapshot(const virtual_axis_page& inst) { return json::parse(inst.snapshot_json()); }

// `cycles` cycles with a renewal every `every` cycles (0: none).
void run(virtual_axis_page& inst, int cycles, int every = 0) {
  for (int i = 0; i < cycles; ++i) {
    if (every > 0 && i % every == 0) inst.renew_lease();
    inst.step();
  }
}

// Enable operation with the three command buttons, then set the plant turning at `turning_rpm`;
// renewals every `every` cycles as in run().
void enable_and_turn(virtual_axis_page& inst, int every) {
  for (page_command cmd : {page_command::shutdown, page_command::switch_on, page_command::enable_operation}) {
    inst.command(cmd);
    run(inst, 100, every);
  }
  plant_change v;
  v.target_velocity = turning_rpm;
  inst.change_plant(v);
}

std::unique_ptr<virtual_axis_page> turning_drive(std::int64_t abort_connection) {
  axis_page_config c;
  c.lease_us = lease_ms * 1000;
  auto inst = std::make_unique<virtual_axis_page>(cia402::standard_profile(), c);
  run(*inst, 10, 50);
  EXPECT_TRUE(std::holds_alternative<cia402::page::accepted>(inst->write_object(0x6007, abort_connection)));
  enable_and_turn(*inst, 50);
  // Longer than the lease, renewed all along: it keeps turning.
  run(*inst, 5 * lease_ms, 50);
  const json s = snapshot(*inst);
  EXPECT_EQ(s["state"], "OPERATION_ENABLED");
  EXPECT_EQ(s["velocity"], turning_rpm);
  return inst;
}

// Cycles from the last renewal until the drive stands (velocity 0), at most `limit`.
int cycles_to_standstill(virtual_axis_page& inst, int limit) {
  for (int k = 1; k <= limit; ++k) {
    inst.step();
    if (snapshot(inst)["velocity"] == 0) return k;
  }
  return -1;
}

TEST(sign_of_life, a_renewed_lease_keeps_the_drive_turning) {
  // turning_drive asserts it: OPERATION ENABLED at speed after five lease times with renewals.
  const auto inst = turning_drive(1);
  run(*inst, 10 * lease_ms, lease_ms / 2);
  EXPECT_EQ(snapshot(*inst)["state"], "OPERATION_ENABLED");
  EXPECT_EQ(snapshot(*inst)["velocity"], turning_rpm);
}

TEST(sign_of_life, a_silent_page_gets_the_drive_quick_stopped_within_lease_and_ramp_for_0x6007_1) {
  const auto inst = turning_drive(1);
  inst->renew_lease();
  // Not before the lease ran out.
  run(*inst, lease_ms - 1);
  EXPECT_EQ(snapshot(*inst)["state"], "OPERATION_ENABLED");
  EXPECT_EQ(snapshot(*inst)["control_word"], "0x000F");
  // The quick stop within one cycle more: 0x6007 = 1 (a fault the master cannot raise) -> Quick stop.
  run(*inst, 2);
  const json s = snapshot(*inst);
  EXPECT_EQ(s["control_word"], "0x0002");  // Quick stop, cia402-reference.md §2.2
  const std::string action = s["results"][0]["action"];
  EXPECT_NE(action.find("SIGN OF LIFE LOST"), std::string::npos) << action;
  EXPECT_NE(action.find("0x6007 = 1"), std::string::npos) << action;
  // The shaft stands once the quick-stop ramp ran: 0x6085 (rpm/s) from the speed it had.
  const int ramp_ms = turning_rpm * 1000 / s["objects"]["0x6085"].get<int>();
  const int left = cycles_to_standstill(*inst, ramp_ms + 20);
  EXPECT_GT(left, 0) << "still turning " << ramp_ms + 20 << " ms after the stop";
  run(*inst, 100);
  // 0x605A = 2 (the default): after the quick-stop ramp, SWITCH ON DISABLED.
  EXPECT_EQ(snapshot(*inst)["state"], "SWITCH_ON_DISABLED");
}

TEST(sign_of_life, each_0x6007_value_gives_its_stop) {
  struct expected {
    std::int64_t code;
    const char* state_after;  // once the shaft stands
    const char* control_word;
  };
  // 0: no action on the drive -> halt (bit 8), the drive stays enabled; 1, 3: Quick stop; 2: Disable
  // voltage (T9, no ramp: the drive coasts).
  for (const expected e : {expected{0, "OPERATION_ENABLED", "0x010F"}, expected{1, "SWITCH_ON_DISABLED", "0x0002"},
                           expected{2, "SWITCH_ON_DISABLED", "0x0000"}, expected{3, "SWITCH_ON_DISABLED", "0x0002"}}) {
    SCOPED_TRACE("0x6007 = " + std::to_string(e.code));
    const auto inst = turning_drive(e.code);
    inst->renew_lease();
    run(*inst, lease_ms + 1);
    EXPECT_EQ(snapshot(*inst)["control_word"], e.control_word);
    run(*inst, 3000);
    const json s = snapshot(*inst);
    EXPECT_EQ(s["state"], e.state_after);
    EXPECT_EQ(s["velocity"], 0);
  }
}

TEST(sign_of_life, a_page_that_comes_back_rearms_the_lease) {
  const auto inst = turning_drive(3);
  inst->renew_lease();
  run(*inst, lease_ms + 1000);
  ASSERT_EQ(snapshot(*inst)["state"], "SWITCH_ON_DISABLED");
  // Back: enabled again, turning again, then silent again: stopped again.
  enable_and_turn(*inst, 50);
  run(*inst, 1000, 50);
  ASSERT_EQ(snapshot(*inst)["state"], "OPERATION_ENABLED");
  ASSERT_EQ(snapshot(*inst)["velocity"], turning_rpm);
  run(*inst, lease_ms + 1000);
  EXPECT_EQ(snapshot(*inst)["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(snapshot(*inst)["velocity"], 0);
}

TEST(sign_of_life, without_a_lease_a_silent_page_changes_nothing) {
  virtual_axis_page inst(cia402::standard_profile());  // lease_us = 0, the library's default
  run(inst, 10);
  enable_and_turn(inst, 0);
  run(inst, 3000);
  EXPECT_EQ(snapshot(inst)["state"], "OPERATION_ENABLED");
  EXPECT_EQ(snapshot(inst)["velocity"], turning_rpm);
}

}  // namespace
