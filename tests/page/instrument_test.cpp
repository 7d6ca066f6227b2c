// The virtual_axis_page behind the page, without HTTP: commands reach the drive as the control words the
// standard gives them, each action is reported as done (with its transitions) or refused, and
// snapshots are published only when something changed. Expected words and transition numbers come
// from the standard's tables (cia402-reference.md §2.2) and the seeds, not from the code.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <set>

#include "page_steps.hpp"
#include "virtual_axis_page.hpp"
#include "cia402/profile.hpp"

namespace {

using cia402::page::accepted;
using cia402::page::testing::virtual_axis_page;
using cia402::page::page_command;
using cia402::page::plant_change;
using cia402::page::refused;
using json = nlohmann::json;
using namespace cia402::page::testing::steps;

const cia402::profile& by_name(const char* name) {
  const cia402::profile* p = cia402::find_builtin_profile(name);
  EXPECT_NE(p, nullptr) << name;
  return p != nullptr ? *p : cia402::standard_profile();
}

// A drive of the standard profile behind the page, powered up (T0, T1: SWITCH ON DISABLED). A test
// that needs a page not yet stepped, or another profile, makes its own (`fresh`, `profibus`).
class instrument : public ::testing::Test {
 protected:
  void SetUp() override { run(inst, 10); }
  virtual_axis_page inst{cia402::standard_profile()};
};

TEST_F(instrument, power_up_reaches_switch_on_disabled_by_t0_t1) {
  const json s = snapshot(inst);
  EXPECT_EQ(s["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(s["last_transition"]["number"], 1);
  EXPECT_EQ(s["last_transition"]["from"], "NOT_READY_TO_SWITCH_ON");
}

TEST_F(instrument, shutdown_switch_on_enable_operation_reach_operation_enabled_with_t4_last) {
  inst.command(page_command::shutdown);
  EXPECT_EQ(settled_result(inst)["transitions"], json::array({2}));
  inst.command(page_command::switch_on);
  EXPECT_EQ(settled_result(inst)["transitions"], json::array({3}));
  const std::uint64_t id = id_of(inst.command(page_command::enable_operation));
  const json r = settled_result(inst);
  EXPECT_EQ(r["id"], id);
  EXPECT_EQ(r["outcome"], "done");
  EXPECT_EQ(r["transitions"], json::array({4}));
  const json s = snapshot(inst);
  EXPECT_EQ(s["state"], "OPERATION_ENABLED");
  EXPECT_EQ(s["control_word"], "0x000F");  // Enable operation, §2.2
  EXPECT_EQ(s["last_transition"]["number"], 4);
  // Bits 0..9 as the standard's OPERATION ENABLED with voltage and remote: 0x0237. Bits 10..15
  // belong to the mode and the plant (target reached, pv speed 0).
  EXPECT_EQ(hex_value(s["status_word"]) & 0x03FF, 0x0237);
}

TEST_F(instrument, enable_operation_from_switch_on_disabled_is_reported_refused) {
  inst.command(page_command::enable_operation);
  const json r = settled_result(inst);
  EXPECT_EQ(r["outcome"], "refused");
  EXPECT_EQ(r["text"], "refused: no transition from SWITCH_ON_DISABLED for ENABLE_OPERATION");
  EXPECT_EQ(snapshot(inst)["state"], "SWITCH_ON_DISABLED");
}

TEST_F(instrument, enable_operation_from_ready_to_switch_on_reports_t3_then_t4) {
  // S3: T3 then T4 in consecutive steps, one action.
  inst.command(page_command::shutdown);
  run(inst, 100);
  inst.command(page_command::enable_operation);
  EXPECT_EQ(settled_result(inst)["transitions"], json::array({3, 4}));
}

TEST_F(instrument, commands_keep_the_bits_the_state_machine_does_not_own) {
  inst.toggle_control_bit(4);   // operation-mode specific
  inst.toggle_control_bit(13);  // manufacturer specific
  inst.command(page_command::shutdown);
  run(inst, 5);
  EXPECT_EQ(snapshot(inst)["control_word"], "0x2016");
}

TEST_F(instrument, halt_toggles_bit_8_and_keeps_the_command) {
  inst.command(page_command::shutdown);
  run(inst, 5);
  inst.command(page_command::halt);
  run(inst, 5);
  EXPECT_EQ(snapshot(inst)["control_word"], "0x0106");
  inst.command(page_command::halt);
  run(inst, 5);
  EXPECT_EQ(snapshot(inst)["control_word"], "0x0006");
}

TEST_F(instrument, halt_is_not_offered_where_bit_8_is_not_a_halt) {
  for (const char* name : {"s300-profibus", "ax2000-profibus"}) {
    virtual_axis_page profibus(by_name(name));
    run(profibus, 10);
    const json info = json::parse(profibus.info_json(true, false));
    bool listed = false;
    for (const json& c : info["commands"]) {
      if (c["key"] == "halt") {
        listed = true;
        EXPECT_FALSE(c["available"].get<bool>()) << name;
      }
    }
    EXPECT_TRUE(listed) << name;
    const auto r = profibus.command(page_command::halt);
    const auto* no = std::get_if<refused>(&r);
    ASSERT_NE(no, nullptr) << name << ": Halt would set bit 8, which this profile calls Jog";
    EXPECT_EQ(no->http_status, 409);
    EXPECT_NE(no->reason.find("Jog"), std::string::npos) << no->reason;
    run(profibus, 5);
    EXPECT_EQ(json::parse(profibus.snapshot_json())["control_word"], "0x0000") << "nothing was sent";
  }
}

TEST_F(instrument, fault_reset_is_one_edge_of_bit_7_and_leads_fault_to_switch_on_disabled_by_t15) {
  inst.change_plant(fault_of(0x2310));
  const json fr = settled_result(inst);
  EXPECT_EQ(fr["transitions"], json::array({13, 14}));
  EXPECT_EQ(snapshot(inst)["state"], "FAULT");
  EXPECT_EQ(snapshot(inst)["error_code"], "0x2310");
  EXPECT_EQ(snapshot(inst)["error_text"], "continuous over-current");  // CiA 402's error code table

  inst.change_plant(no_fault());
  run(inst, 100);
  inst.command(page_command::fault_reset);
  inst.step();
  EXPECT_EQ(hex_value(snapshot(inst)["control_word"]) & 0x80, 0x80);  // the edge
  const json r = settled_result(inst);
  EXPECT_EQ(r["transitions"], json::array({15}));
  const json s = snapshot(inst);
  EXPECT_EQ(s["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(s["last_transition"]["number"], 15);
  EXPECT_EQ(hex_value(s["control_word"]) & 0x80, 0);  // cleared after it was seen
}

TEST_F(instrument, fault_reset_after_bit_7_was_left_set_still_makes_an_edge) {
  inst.toggle_control_bit(7);
  inst.change_plant(fault_of());
  run(inst, 300);
  inst.change_plant(no_fault());
  run(inst, 100);
  ASSERT_EQ(snapshot(inst)["state"], "FAULT");
  inst.command(page_command::fault_reset);
  EXPECT_EQ(settled_result(inst)["transitions"], json::array({15}));
}

TEST_F(instrument, fault_reset_while_the_cause_persists_is_refused_and_names_the_cause) {
  inst.change_plant(fault_of(0x4310));
  run(inst, 300);
  inst.command(page_command::fault_reset);
  const json r = settled_result(inst);
  EXPECT_EQ(r["outcome"], "refused");
  EXPECT_EQ(r["text"],
            "refused: no transition from FAULT for FAULT_RESET (fault cause 0x4310 present)");
  EXPECT_EQ(snapshot(inst)["state"], "FAULT");
}

TEST_F(instrument, switch_on_without_dc_link_waits_for_it_and_acts_when_it_returns) {
  inst.command(page_command::shutdown);
  run(inst, 100);
  plant_change drop;
  drop.dc_link = false;
  inst.change_plant(drop);
  run(inst, 100);
  inst.command(page_command::switch_on);
  const json waiting = settled_result(inst);
  EXPECT_EQ(waiting["outcome"], "waiting");
  EXPECT_EQ(waiting["text"], "waiting: no DC-link voltage; SWITCH_ON acts once it is gone");
  plant_change back;
  back.dc_link = true;
  inst.change_plant(back);
  run(inst, 100);
  EXPECT_EQ(snapshot(inst)["state"], "SWITCHED_ON") << "T3 on the word still in the control word";
}

TEST_F(instrument, a_command_that_leads_where_the_drive_is_has_nothing_to_do) {
  inst.command(page_command::shutdown);
  run(inst, 100);
  inst.command(page_command::shutdown);  // again, in READY TO SWITCH ON
  const json again = settled_result(inst);
  EXPECT_EQ(again["outcome"], "nothing to do");
  EXPECT_EQ(again["text"], "nothing to do: already READY_TO_SWITCH_ON");
  inst.command(page_command::enable_operation);
  run(inst, 100);
  inst.command(page_command::enable_operation);  // again, in OPERATION ENABLED
  EXPECT_EQ(settled_result(inst)["text"], "nothing to do: already OPERATION_ENABLED");
}

TEST_F(instrument, shutdown_under_sto_waits_for_sto_to_be_released) {
  plant_change sto;
  sto.sto = true;
  inst.change_plant(sto);
  run(inst, 100);
  inst.command(page_command::shutdown);  // SWITCH ON DISABLED: T2 is held back by STO (S14)
  const json r = settled_result(inst);
  EXPECT_EQ(r["outcome"], "waiting");
  EXPECT_EQ(r["text"], "waiting: STO asserted; SHUTDOWN acts once it is gone");
}

TEST_F(instrument, a_command_with_no_row_from_the_state_is_still_refused) {
  inst.command(page_command::enable_operation);  // SWITCH ON DISABLED has no row for it
  const json r = settled_result(inst);
  EXPECT_EQ(r["outcome"], "refused");
  EXPECT_EQ(r["text"], "refused: no transition from SWITCH_ON_DISABLED for ENABLE_OPERATION");
}

TEST_F(instrument, option_write_the_profile_refuses_is_an_sdo_abort_and_changes_nothing) {
  const auto r = inst.write_object(0x605A, 9);  // 9..32767 reserved (§3)
  const auto* no = std::get_if<refused>(&r);
  ASSERT_NE(no, nullptr);
  EXPECT_EQ(no->http_status, 422);
  EXPECT_EQ(static_cast<std::uint32_t>(no->abort), 0x06090030u);
  const json s = snapshot(inst);
  EXPECT_EQ(s["objects"]["0x605A"], 2);  // the default stays
  EXPECT_EQ(s["results"][0]["outcome"], "refused");
}

TEST_F(instrument, target_velocity_outside_int32_is_refused_and_nothing_else_changes) {
  plant_change c;
  c.target_velocity = std::int64_t{1} << 40;
  c.sto = true;
  c.dc_link = false;
  const auto r = inst.change_plant(c);
  ASSERT_TRUE(std::holds_alternative<refused>(r));
  const json s = snapshot(inst);
  EXPECT_EQ(s["sto"], false);
  EXPECT_EQ(s["dc_link"], true);
  EXPECT_EQ(s["target_velocity"], 0);
}

TEST_F(instrument, toggle_of_a_bit_outside_0_to_15_is_refused) {
  virtual_axis_page fresh(cia402::standard_profile());
  EXPECT_TRUE(std::holds_alternative<refused>(fresh.toggle_control_bit(16)));
  EXPECT_TRUE(std::holds_alternative<refused>(fresh.toggle_control_bit(-1)));
}

TEST_F(instrument, ax2000_enable_operation_word_sets_fast_stop_bit_4) {
  // 004_e07fd68605b3a8c6.txt: fast stop is bit 4 (T11 "Bit 4 is canceled", T16 "Bit 4 is set"),
  // so enabling needs bits 0..4: 0x001F.
  virtual_axis_page profibus(by_name("ax2000-profibus"));
  run(profibus, 10);
  profibus.command(page_command::shutdown);
  run(profibus, 100);
  profibus.command(page_command::enable_operation);
  EXPECT_EQ(settled_result(profibus)["transitions"], json::array({3, 4}));
  EXPECT_EQ(snapshot(profibus)["control_word"], "0x001F");
}

TEST_F(instrument, drivecom_profiles_name_bits_as_stw_and_zsw) {
  virtual_axis_page s300(by_name("s300-profibus"));
  const json info = json::parse(s300.info_json(true, false));
  // STW bits 1 and 2 act when cleared: their names say so, as the standard's do.
  EXPECT_EQ(info["control_bits"][1]["name"], "Inhibit voltage (active low)");  // §6.1 STW
  EXPECT_EQ(info["control_bits"][2]["name"], "Fast stop, switch-on inhibited (active low)");
  EXPECT_EQ(info["control_bits"][8]["name"], "Jog");
  EXPECT_EQ(info["status_bits"][6]["name"], "Switch-on inhibit");  // §6.1 ZSW
  virtual_axis_page standard(cia402::standard_profile());
  const json std_info = json::parse(standard.info_json(true, false));
  EXPECT_EQ(std_info["control_bits"][8]["name"], "Halt");
}

TEST_F(instrument, info_rows_come_from_the_profile_table_with_t13_from_six_states) {
  virtual_axis_page fresh(cia402::standard_profile());
  const json info = json::parse(fresh.info_json(false, true));
  EXPECT_EQ(info["control"], false);
  EXPECT_EQ(info["token_required"], true);
  std::set<int> numbers;
  for (const json& r : info["rows"]) {
    numbers.insert(r["number"].get<int>());
    if (r["number"] == 13) {
      EXPECT_EQ(r["from"].size(), 6u);
      EXPECT_EQ(r["to"], "FAULT_REACTION_ACTIVE");
    }
  }
  // The standard's transitions 0..16 (seed 002_522d2c0bb8f5a5f8.txt, table 7.8).
  for (int n = 0; n <= 16; ++n) EXPECT_TRUE(numbers.count(n)) << n;
  EXPECT_FALSE(numbers.count(17));
}

TEST_F(instrument, a_snapshot_is_published_only_when_something_changed) {
  virtual_axis_page fresh(cia402::standard_profile());
  run(fresh, 400);  // power-up settles
  const std::uint64_t before = fresh.latest().version;
  run(fresh, 400);  // nothing happens
  EXPECT_EQ(fresh.latest().version, before);
  fresh.command(page_command::shutdown);
  run(fresh, 40);
  EXPECT_GT(fresh.latest().version, before);
}

TEST_F(instrument, snapshots_are_published_at_most_once_per_40_cycles) {
  inst.command(page_command::shutdown);
  run(inst, 5);
  inst.command(page_command::enable_operation);
  run(inst, 60);  // T3, T4, the brake lets go
  ASSERT_EQ(snapshot(inst)["state"], "OPERATION_ENABLED");
  plant_change c;
  c.target_velocity = 3000;  // after T4, which clears the set-points
  inst.change_plant(c);
  const std::uint64_t before = inst.latest().version;
  run(inst, 400);  // the motor accelerates: every snapshot differs
  EXPECT_LE(inst.latest().version - before, 10u);
  EXPECT_GE(inst.latest().version - before, 9u);
}

TEST_F(instrument, wait_for_update_returns_after_close_without_an_update) {
  virtual_axis_page fresh(cia402::standard_profile());
  fresh.close();
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(fresh.wait_for_update(0, std::chrono::seconds(5)).has_value());
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1));
}

}  // namespace

namespace {

// The page offers the modes 0x6502 announces and the homing methods the drive runs as choices, and
// the snapshot carries the mode and its actual values.
TEST_F(instrument, modes_are_a_choice_and_the_snapshot_shows_mode_position_and_torque) {
  const json info = json::parse(inst.info_json(true, false));
  json modes, methods;
  for (const json& o : info["objects"]) {
    if (o["index"] == "0x6060") modes = o["values"];
    if (o["index"] == "0x6098") methods = o["values"];
  }
  EXPECT_EQ(modes, json::parse("[1, 3, 4, 6, 8, 9, 10]"));
  EXPECT_EQ(methods, json::parse("[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 33, 34, 35, 37]"));
  EXPECT_EQ(info["modes"]["8"], "csp");

  EXPECT_EQ(snapshot(inst)["mode"], 3);
  id_of(inst.write_object(0x6060, 6));
  id_of(inst.write_object(0x607C, 1234));
  for (const cia402::page::page_command c : {cia402::page::page_command::shutdown, cia402::page::page_command::switch_on,
                                             cia402::page::page_command::enable_operation}) {
    id_of(inst.command(c));
    run(inst, 100);
  }
  id_of(inst.toggle_control_bit(4));  // homing operation start
  run(inst, 20);
  const json s = snapshot(inst);
  EXPECT_EQ(s["mode"], 6);
  EXPECT_EQ(s["position"], 1234);
  EXPECT_EQ(s["following_error"], 0);
  EXPECT_TRUE(s["torque_actual"].is_number());
  EXPECT_EQ(s["objects"]["0x6060"], 6);
  EXPECT_EQ(hex_value(s["status_word"]) & 0x1400, 0x1400) << "homing attained, target reached";
}

}  // namespace

namespace {

// Profile position from the page: 0x6060 = 1, 0x607A, the new set-point handshake (bit 4 up until
// status bit 12, then down: CiA 402-2's set-point handshake), the move to the target (bit 10), a
// relative move adding to it (bit 6).
TEST_F(instrument, the_new_setpoint_handshake_moves_in_profile_position) {
  id_of(inst.write_object(0x6060, 1));
  EXPECT_EQ(snapshot(inst)["requested_mode"], 1);
  enable(inst);
  ASSERT_EQ(snapshot(inst)["mode"], 1);
  id_of(inst.write_object(0x607A, 5000));
  id_of(inst.new_setpoint());
  json s = snapshot(inst);
  EXPECT_EQ(s["results"][0]["action"], "NEW_SET-POINT");
  EXPECT_EQ(s["results"][0]["outcome"], "done");
  run(inst, 20);  // target reached (bit 10) falls as the move starts
  s = run_until_status_bit(inst, 10, 20000);
  EXPECT_EQ(s["position"], 5000);
  EXPECT_EQ(hex_value(s["control_word"]) & 0x0010, 0) << "bit 4 is down after the acknowledge";
  EXPECT_EQ(hex_value(s["status_word"]) & 0x1000, 0) << "bit 12 follows bit 4 down";
  // The recording holds the handshake: a cycle with bit 4 up and bit 12 acknowledging it.
  const json rec = json::parse(inst.recording_json(0, 0));
  bool handshake = false;
  for (const json& row : rec["rows"]) {
    if ((row[1].get<int>() & 0x0010) != 0 && (row[2].get<int>() & 0x1000) != 0) handshake = true;
  }
  EXPECT_TRUE(handshake);
  EXPECT_EQ(rec["rows"].back()[6], 5000) << "the position is the recording's 7th column";

  id_of(inst.toggle_control_bit(6));  // relative
  id_of(inst.write_object(0x607A, 1000));
  id_of(inst.new_setpoint());
  run(inst, 20);
  s = run_until_status_bit(inst, 10, 20000);
  EXPECT_EQ(s["position"], 6000);
  EXPECT_NE(std::string(s["results"][0]["text"]).find("relative"), std::string::npos) << s["results"];

  // Another mode: the handshake is refused, nothing changes.
  id_of(inst.write_object(0x6060, 3));
  run(inst, 5);
  const auto r = inst.new_setpoint();
  const auto* no = std::get_if<refused>(&r);
  ASSERT_NE(no, nullptr);
  EXPECT_EQ(no->http_status, 409);
  EXPECT_NE(no->reason.find("(pv)"), std::string::npos) << no->reason;
}

// A set-point the drive does not acknowledge (not enabled): bit 4 falls after a second, reported.
TEST_F(instrument, an_unacknowledged_setpoint_lets_bit_4_fall_and_says_so) {
  id_of(inst.write_object(0x6060, 1));
  run(inst, 5);
  id_of(inst.new_setpoint());
  run(inst, 5);
  EXPECT_EQ(hex_value(snapshot(inst)["control_word"]) & 0x0010, 0x0010);
  run(inst, 1100);
  const json s = snapshot(inst);
  EXPECT_EQ(hex_value(s["control_word"]) & 0x0010, 0);
  EXPECT_EQ(s["results"][0]["outcome"], "refused");
  EXPECT_NE(std::string(s["results"][0]["text"]).find("status bit 12"), std::string::npos);
}

// The names of the mode-specific bits per mode, as CiA 402-2 gives them; a DRIVECOM profile keeps
// the names it gives its control bits, and has no set-point handshake on bit 4.
TEST_F(instrument, info_names_the_mode_specific_bits_per_mode) {
  virtual_axis_page fresh(cia402::standard_profile());
  const json info = json::parse(fresh.info_json(true, false));
  EXPECT_EQ(info["mode_names"]["1"], "Profile position");
  EXPECT_EQ(info["mode_names"]["8"], "Cyclic synchronous position");
  EXPECT_EQ(info["mode_bits"]["1"]["control"]["4"], "New set-point");
  EXPECT_EQ(info["mode_bits"]["1"]["control"]["5"], "Change set immediately");
  EXPECT_EQ(info["mode_bits"]["1"]["control"]["9"], "Change on set-point");
  EXPECT_EQ(info["mode_bits"]["1"]["status"]["12"], "Set-point acknowledge");
  EXPECT_EQ(info["mode_bits"]["1"]["status"]["13"], "Following error");
  EXPECT_EQ(info["mode_bits"]["6"]["control"]["4"], "Homing operation start");
  EXPECT_EQ(info["mode_bits"]["6"]["status"]["12"], "Homing attained");
  EXPECT_EQ(info["mode_bits"]["6"]["status"]["13"], "Homing error");
  EXPECT_EQ(info["mode_bits"]["3"]["status"]["12"], "Speed = 0");
  EXPECT_EQ(info["mode_bits"]["3"]["control"]["4"], "Reserved in pv");
  EXPECT_EQ(info["mode_bits"]["8"]["status"]["12"], "Drive follows the command value");
  EXPECT_FALSE(info["mode_bits"]["1"]["control"].contains("8")) << "halt is the profile's";
  EXPECT_TRUE(info["new_setpoint"]);

  virtual_axis_page s300(by_name("s300-profibus"));
  const json d = json::parse(s300.info_json(true, false));
  EXPECT_TRUE(d["mode_bits"]["1"]["control"].empty()) << "STW bits 4, 5, 6 and 9 have names";
  EXPECT_EQ(d["mode_bits"]["6"]["status"]["12"], "Homing attained") << "ZSW 12 is \"Mode specific\"";
  EXPECT_FALSE(d["new_setpoint"]);
  const auto r = s300.new_setpoint();
  const auto* no = std::get_if<refused>(&r);
  ASSERT_NE(no, nullptr);
  EXPECT_NE(no->reason.find("Fast stop / inhibit ramp function generator"), std::string::npos) << no->reason;
}

}  // namespace

