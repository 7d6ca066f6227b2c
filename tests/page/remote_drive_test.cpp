// The page's remote backend against a `cia402 bus`-equivalent node (the simulator's drive behind a
// CiA 301 slave) on the in-process virtual bus, in virtual time, no sockets: set-up over SDO, the
// page's commands in RPDO1, states from TPDO1 with inferred transition numbers, fault injection
// through 0x2001, SDO refusals with their abort codes, and a node that stops answering. Expected
// words, states and transition numbers are the standard's (cia402-reference.md §1.3, §2.2; seed
// 002_522d2c0bb8f5a5f8.txt), not the code's output.
#include "remote_bench.hpp"

namespace {

using namespace remote_drive_testing;

TEST(remote_drive, set_up_reads_the_drive_and_shows_switch_on_disabled) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  b.run_ms(250);
  const json s = b.snapshot();
  EXPECT_EQ(s["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(s["remote"]["status"], "running");
  EXPECT_EQ(s["remote"]["device_name"], "cia402 virtual drive");
  // The link's own state (NMT, PDOs, heartbeats) is the link's: the page sees the cyclic exchange run.
  EXPECT_TRUE(s["remote"]["cyclic"].get<bool>());
  // The option codes' defaults (semantics.md S5, S7, S9, S10), read from the node.
  EXPECT_EQ(s["objects"]["0x605A"], 2);
  EXPECT_EQ(s["objects"]["0x605E"], 2);
  EXPECT_EQ(s["objects"]["0x6007"], 1);
  // The mode panel's profile parameters, which no PDO carries, read from the node too.
  for (const char* index : {"0x6081", "0x6083", "0x6084", "0x6085"}) {
    EXPECT_TRUE(s["objects"].contains(index) && s["objects"][index].is_number()) << index << " " << s["objects"].dump();
  }
  EXPECT_TRUE(s["last_transition"].is_null());
  EXPECT_TRUE(b.remote().fault_injection_available());
}

TEST(remote_drive, shutdown_switch_on_enable_operation_reach_operation_enabled_by_inferred_2_3_4) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  const json r2 = command_result(b, page_command::shutdown);
  EXPECT_EQ(r2["outcome"], "done") << r2;
  EXPECT_EQ(r2["transitions"], json::array({2}));
  EXPECT_EQ(b.snapshot()["state"], "READY_TO_SWITCH_ON");
  EXPECT_EQ(b.snapshot()["control_word"], "0x0006");

  const json r3 = command_result(b, page_command::switch_on);
  EXPECT_EQ(r3["transitions"], json::array({3}));
  EXPECT_EQ(b.snapshot()["state"], "SWITCHED_ON");

  const json r4 = command_result(b, page_command::enable_operation);
  EXPECT_EQ(r4["transitions"], json::array({4}));
  EXPECT_NE(r4["text"].get<std::string>().find("inferred"), std::string::npos) << r4;
  const json s = b.snapshot();
  EXPECT_EQ(s["state"], "OPERATION_ENABLED");
  EXPECT_EQ(s["control_word"], "0x000F");
  EXPECT_EQ(s["last_transition"]["number"], 4);
  EXPECT_EQ(s["last_transition"]["from"], "SWITCHED_ON");
  EXPECT_TRUE(s["last_transition"]["inferred"].get<bool>());
  // The drive itself agrees: the page showed what happened, not what it hoped for.
  EXPECT_EQ(b.drive().view().current(), cia402::state::operation_enabled);
}

TEST(remote_drive, enable_operation_from_ready_to_switch_on_is_inferred_as_3_then_4) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  command_result(b, page_command::shutdown);
  const json r = command_result(b, page_command::enable_operation);
  EXPECT_EQ(r["transitions"], json::array({3, 4})) << r;
  EXPECT_EQ(b.snapshot()["state"], "OPERATION_ENABLED");
}

TEST(remote_drive, a_vendor_profile_is_decoded_with_that_profile_and_disable_voltage_is_t9) {
  // Seed 004_e07fd68605b3a8c6.txt (Beckhoff AX2000): fast stop on bit 4, T9 on bit 1 cleared.
  const cia402::profile* ax = cia402::find_builtin_profile("ax2000-profibus");
  ASSERT_NE(ax, nullptr);
  remote_bench b(test_config(), *ax);
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  enable(b);
  const json r = command_result(b, page_command::disable_voltage);
  EXPECT_EQ(r["transitions"], json::array({9})) << r;
  EXPECT_EQ(b.snapshot()["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(b.drive().view().current(), cia402::state::switch_on_disabled);
}

TEST(remote_drive, fault_through_0x2001_gives_fault_and_fault_reset_gives_switch_on_disabled_by_15) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  enable(b);
  plant_change fault;
  fault.fault = true;
  fault.fault_code = 0x2310;
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().change_plant(fault); })));
  b.run_ms(1000);
  json s = b.snapshot();
  EXPECT_EQ(s["state"], "FAULT");
  EXPECT_EQ(s["error_code"], "0x2310");
  EXPECT_EQ(s["error_text"], "continuous over-current");  // CiA 402's error code table
  EXPECT_EQ(s["fault_cause"], "0x2310");
  EXPECT_EQ(s["results"][0]["transitions"], json::array({13, 14})) << s["results"][0];
  EXPECT_EQ(s["last_transition"]["number"], 14);

  // With the cause present a reset is used up and changes nothing (S2).
  const json early = command_result(b, page_command::fault_reset);
  EXPECT_EQ(early["outcome"], "refused") << early;
  EXPECT_NE(early["text"].get<std::string>().find("0x2310"), std::string::npos) << early;

  plant_change clear;
  clear.fault = false;
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().change_plant(clear); })));
  b.run_ms(100);
  const json r = command_result(b, page_command::fault_reset);
  EXPECT_EQ(r["outcome"], "done") << r;
  EXPECT_EQ(r["transitions"], json::array({15}));
  s = b.snapshot();
  EXPECT_EQ(s["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(s["last_transition"]["number"], 15);
  EXPECT_EQ(s["last_transition"]["from"], "FAULT");
  // The reset edge went out and came back down: bit 7 is clear again.
  EXPECT_EQ(std::stoi(s["control_word"].get<std::string>(), nullptr, 16) & 0x80, 0);
}

TEST(remote_drive, option_write_the_drive_refuses_carries_its_abort_code_and_changes_nothing) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  const reply no = b.blocking([&] { return b.remote().write_object(0x605A, 12); });
  ASSERT_TRUE(std::holds_alternative<refused>(no));
  EXPECT_EQ(std::get<refused>(no).http_status, 422);
  // S5: a value the profile does not support is 0x06090030.
  EXPECT_EQ(std::get<refused>(no).abort, cia402::sdo_abort::invalid_value);
  EXPECT_NE(std::get<refused>(no).reason.find("0x06090030"), std::string::npos);
  EXPECT_EQ(b.snapshot()["objects"]["0x605A"], 2);
  EXPECT_EQ(b.newest_result()["outcome"], "refused");

  const reply yes = b.blocking([&] { return b.remote().write_object(0x605A, 6); });
  EXPECT_TRUE(is_accepted(yes));
  EXPECT_EQ(b.snapshot()["objects"]["0x605A"], 6);
  std::int64_t on_drive = 0;
  ASSERT_EQ(b.drive().read(0x605A, 0, on_drive), cia402::sdo_abort::none);
  EXPECT_EQ(on_drive, 6);
}

TEST(remote_drive, value_outside_the_objects_type_is_refused_before_sending) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  const reply r = b.remote().write_object(0x605A, 70000);  // INTEGER16
  ASSERT_TRUE(std::holds_alternative<refused>(r));
  EXPECT_EQ(std::get<refused>(r).abort, cia402::sdo_abort::value_too_high);
  // An object the core's table does not know goes to the drive, which says it has none.
  const reply unknown = b.blocking([&] { return b.remote().write_object(0x1234, 1); });
  ASSERT_TRUE(std::holds_alternative<refused>(unknown));
  EXPECT_EQ(std::get<refused>(unknown).http_status, 422);
  EXPECT_EQ(std::get<refused>(unknown).abort, cia402::sdo_abort::object_does_not_exist);
}

TEST(remote_drive, target_velocity_goes_out_by_sdo_and_actual_velocity_comes_back) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  enable(b);
  plant_change c;
  c.target_velocity = 300;
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().change_plant(c); })));
  b.run_ms(2000);  // 300 rpm at the default acceleration of 1000 rpm/s
  const json s = b.snapshot();
  EXPECT_EQ(s["target_velocity"], 300);
  EXPECT_EQ(s["velocity"], 300);
  EXPECT_EQ(b.drive().view().target_velocity(), 300);
  // The mode panel's set-point: pv's 0x60FF, written by SDO here (not in the PDOs the page maps).
  EXPECT_EQ(s["set_point"]["index"], "0x60FF") << s["set_point"];
  EXPECT_EQ(s["set_point"]["value"], 300) << s["set_point"];
  EXPECT_EQ(s["set_point"]["unit"], "rpm") << s["set_point"];
}

TEST(remote_drive, dc_link_and_sto_are_refused_and_the_capabilities_say_why) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  const json info = json::parse(b.remote().info_json(true, false));
  EXPECT_EQ(info["backend"], "remote");
  EXPECT_FALSE(info["capabilities"]["dc_link"].get<bool>());
  EXPECT_FALSE(info["capabilities"]["sto"].get<bool>());
  EXPECT_TRUE(info["capabilities"]["fault"].get<bool>());
  EXPECT_EQ(info["capabilities"]["reasons"]["dc_link"], "not available on a remote drive");
  plant_change c;
  c.sto = true;
  const reply r = b.remote().change_plant(c);
  ASSERT_TRUE(std::holds_alternative<refused>(r));
  EXPECT_EQ(std::get<refused>(r).http_status, 409);
  EXPECT_NE(std::get<refused>(r).reason.find("not available on a remote drive"), std::string::npos);
  EXPECT_FALSE(b.drive().view().sto());
}

TEST(remote_drive, silent_node_shows_does_not_answer_and_is_picked_up_again_when_it_returns) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  command_result(b, page_command::shutdown);
  b.silence();
  b.run_ms(500);  // heartbeat 100 ms, watched at 300 ms
  EXPECT_EQ(b.status(), "no_answer");
  EXPECT_NE(b.remote().link_text().find("node 1 does not answer"), std::string::npos)
      << b.remote().link_text();
  const json s = b.snapshot();
  EXPECT_EQ(s["state"], "UNKNOWN");
  EXPECT_EQ(s["remote"]["status"], "no_answer");
  const reply r = b.remote().command(page_command::switch_on);
  ASSERT_TRUE(std::holds_alternative<refused>(r));
  EXPECT_EQ(std::get<refused>(r).http_status, 503);
  EXPECT_NE(std::get<refused>(r).reason.find("does not answer"), std::string::npos);

  b.revive();
  ASSERT_TRUE(b.run_until_running(5000)) << b.remote().link_text();
  EXPECT_EQ(b.snapshot()["state"], "READY_TO_SWITCH_ON");
}

TEST(remote_drive, the_drive_watches_the_pages_heartbeat_and_applies_0x6007_when_the_page_is_gone) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running());
  // 0x6007 acts on an enabled drive (CiA 402-2; a disabled one has nothing to protect).
  enable(b);
  std::int64_t watch = 0;
  ASSERT_EQ(b.drive_node().node().read(0x1016, 1, watch), cia402::sdo_abort::none);
  EXPECT_EQ(watch, (127 << 16) | 300) << "node-ID 127, 3 x 100 ms";
  b.run_ms(500);
  EXPECT_FALSE(b.drive_node().node().connection_lost());
  b.run_drive_only_ms(500);  // the page's server stopped
  EXPECT_TRUE(b.drive_node().node().connection_lost());
  std::int64_t err = 0;
  ASSERT_EQ(b.drive_node().node().read(0x603F, 0, err), cia402::sdo_abort::none);
  EXPECT_EQ(err, 0x8130) << "0x6007 = 1 by default: a fault with the heartbeat error code";
}

// The page's sign of life (docs/page.md): the page's process is still there, but no page renews the
// lease (the tab was closed). The drive, enabled and turning, is quick-stopped by the page's master
// as its 0x6007 (1 by default: a fault, which a master cannot raise) says within the lease plus a
// cycle, and not before; its heartbeat watch cannot see this, the page's heartbeat goes on.
TEST(remote_drive, a_silent_page_gets_the_turning_drive_quick_stopped_after_the_lease) {
  constexpr int lease_ms = 300;
  remote_config c = test_config();
  c.page.lease_us = lease_ms * 1000;
  remote_bench b(c);
  auto renewed = [&b](int ms) {
    for (int i = 0; i < ms; ++i) {
      if (i % 100 == 0) b.remote().renew_lease();
      b.run_ms(1);
    }
  };
  b.remote().renew_lease();
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  for (page_command cmd : {page_command::shutdown, page_command::switch_on, page_command::enable_operation}) {
    b.remote().renew_lease();
    ASSERT_TRUE(is_accepted(b.remote().command(cmd)));
    renewed(600);
  }
  ASSERT_EQ(b.snapshot()["state"], "OPERATION_ENABLED");
  plant_change v;
  v.target_velocity = 300;
  b.remote().renew_lease();
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().change_plant(v); })));
  renewed(2000);  // 300 rpm at 1000 rpm/s, renewed for many lease times
  ASSERT_EQ(b.drive().view().current(), cia402::state::operation_enabled);
  ASSERT_EQ(b.drive().view().velocity_rpm(), 300);

  b.remote().renew_lease();
  b.run_ms(lease_ms - 5);
  EXPECT_EQ(b.drive().view().current(), cia402::state::operation_enabled) << "stopped before the lease ran out";
  b.run_ms(10);
  const json s = b.snapshot();
  EXPECT_EQ(s["control_word"], "0x0002");  // Quick stop, cia402-reference.md §2.2
  const std::string action = s["results"][0]["action"];
  EXPECT_NE(action.find("SIGN OF LIFE LOST"), std::string::npos) << action;
  // 300 rpm at the quick stop deceleration (0x6085, 10000 rpm/s by default): 30 ms.
  b.run_ms(100);
  EXPECT_EQ(b.drive().view().velocity_rpm(), 0);
  b.run_ms(300);
  EXPECT_EQ(b.drive().view().current(), cia402::state::switch_on_disabled);  // 0x605A = 2
  EXPECT_FALSE(b.drive_node().node().connection_lost()) << "the page's heartbeat went on";
}

// The page's runner on a loaded machine: each step() stands for 1 ms while 4 ms pass on the wall
// and for the drive, which watches the page's heartbeat (100 ms) at 300 ms. On step() time the
// heartbeat would go out every 400 ms of the drive's time; on the wall's clock, every 100 ms.
struct slowed_page_result {
  int heartbeats = 0;  // the page's heartbeats on the bus in one second of wall time
  std::int64_t error_code = 0;  // the drive's 0x603F afterwards: 0x8130 if it missed the heartbeat
};

slowed_page_result run_slowed_page(bool heartbeat_on_wall_clock) {
  auto wall_us = std::make_shared<std::uint64_t>(0);
  remote_config c = test_config();
  if (heartbeat_on_wall_clock) c.link.heartbeat_clock_us = [wall_us] { return *wall_us; };
  remote_bench b(c);
  for (int i = 0; i < 2000 && b.status() != "running"; ++i) {
    *wall_us += 1000;
    b.cycle(1000);
  }
  EXPECT_EQ(b.status(), "running") << b.remote().link_text();
  // Enabled, on the wall's time too: 0x6007 acts on an enabled drive only.
  for (const page_command c : {page_command::shutdown, page_command::switch_on, page_command::enable_operation}) {
    EXPECT_TRUE(is_accepted(b.remote().command(c)));
    for (int i = 0; i < 600; ++i) {
      *wall_us += 1000;
      b.cycle(1000);
    }
  }
  EXPECT_EQ(b.snapshot()["state"], "OPERATION_ENABLED");
  const auto listener = b.bus().attach();
  slowed_page_result r;
  for (int i = 0; i < 250; ++i) {
    *wall_us += 4000;
    b.cycle(4000);
    co::frame f;
    while (listener->receive(f)) r.heartbeats += f.id == 0x700 + 127 ? 1 : 0;
  }
  EXPECT_EQ(b.drive_node().node().read(0x603F, 0, r.error_code), cia402::sdo_abort::none);
  return r;
}

TEST(remote_drive, a_page_slower_than_the_wall_sends_its_heartbeat_on_its_heartbeat_clock) {
  const slowed_page_result on_wall = run_slowed_page(true);
  EXPECT_GE(on_wall.heartbeats, 9);
  EXPECT_LE(on_wall.heartbeats, 11);
  EXPECT_EQ(on_wall.error_code, 0);

  // Why serve sets the clock: on step() time the drive misses the heartbeat and faults (0x6007).
  const slowed_page_result on_steps = run_slowed_page(false);
  EXPECT_LE(on_steps.heartbeats, 3);
  EXPECT_EQ(on_steps.error_code, 0x8130);
}

TEST(remote_drive, node_that_is_not_on_the_bus_does_not_answer_set_up) {
  remote_bench b(test_config(5));  // the bench's drive is node 1
  b.run_ms(700);
  EXPECT_EQ(b.status(), "no_answer");
  EXPECT_NE(b.remote().link_text().find("node 5 does not answer (SDO timeout"),
            std::string::npos)
      << b.remote().link_text();
  EXPECT_EQ(b.snapshot()["state"], "UNKNOWN");
}

}  // namespace

namespace {

// The operation modes on a remote drive: 0x6061, 0x6064, 0x6077 and 0x60F4 read by SDO in rounds
// (every 100 ms), the mode select's choices from the drive's own 0x6502, a pp move by the
// new set-point handshake in RPDO1 (bit 4 up until status bit 12, then down), and the position in
// the recording.
TEST(remote_drive, reads_mode_and_actual_values_and_moves_by_the_setpoint_handshake) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  b.run_ms(300);
  json s = b.snapshot();
  EXPECT_EQ(s["mode"], 3);
  EXPECT_EQ(s["requested_mode"], 3);
  EXPECT_EQ(s["position"], 0);
  EXPECT_TRUE(s["torque_actual"].is_number());
  EXPECT_EQ(s["following_error"], 0);
  const json info = json::parse(b.remote().info_json(true, false));
  for (const json& o : info["objects"]) {
    if (o["index"] == "0x6060") {
      EXPECT_EQ(o["values"], json::parse("[1, 3, 4, 6, 8, 9, 10]"));
    }
  }

  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().write_object(0x6060, 1); })));
  enable(b);
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().write_object(0x607A, 4000); })));
  b.run_ms(300);
  EXPECT_EQ(b.snapshot()["mode"], 1);
  ASSERT_TRUE(is_accepted(b.remote().new_setpoint()));
  b.run_ms(2000);
  s = b.snapshot();
  EXPECT_EQ(s["position"], 4000);
  EXPECT_EQ(b.drive().view().position(), 4000);
  EXPECT_EQ(s["control_word"], "0x000F") << "bit 4 down again after the acknowledge";
  EXPECT_EQ(s["results"][0]["action"], "NEW_SET-POINT") << s["results"];
  EXPECT_EQ(s["results"][0]["outcome"], "done") << s["results"];
  const json rec = json::parse(b.remote().recording_json(0, 0));
  bool bit4 = false;
  for (const json& row : rec["rows"]) bit4 = bit4 || (row[1].get<int>() & 0x0010) != 0;
  EXPECT_TRUE(bit4) << "the recording shows bit 4 up";
  EXPECT_EQ(rec["rows"].back()[6], 4000);

  // Homing: the page's mode select writes 0x6060; the handshake is refused in that mode.
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().write_object(0x6060, 6); })));
  b.run_ms(300);
  EXPECT_EQ(b.snapshot()["mode"], 6);
  const reply r = b.remote().new_setpoint();
  ASSERT_TRUE(std::holds_alternative<refused>(r));
  EXPECT_EQ(std::get<refused>(r).http_status, 409);
}

}  // namespace

// Issue 35 on a bus: the homing objects and 0x1003 are read by SDO at start, POST /api/homing's
// writes and run go by SDO and the drive's status bits, a fault enters the node's 0x1003 and the
// page reads it again, and 0x1003 sub 0 = 0 empties it.
TEST(remote_drive, homing_method_3_runs_over_sdo_and_a_fault_enters_the_nodes_0x1003) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  b.run_ms(300);
  json s = b.snapshot();
  EXPECT_EQ(s["homing"]["method"], 35) << s["homing"];  // the object table's default
  EXPECT_EQ(s["homing"]["fast"], 1000);
  EXPECT_EQ(s["homing"]["slow"], 100);
  EXPECT_EQ(s["drive_errors"]["count"], 0) << s["drive_errors"];
  cia402::page::homing_request h;
  h.method = 3;
  h.switch_speed = 600;
  h.zero_speed = 60;
  h.start = true;
  const reply started = b.blocking([&] { return b.remote().home(h); });
  ASSERT_TRUE(is_accepted(started)) << std::get<refused>(started).reason;
  EXPECT_EQ(std::get<accepted>(started).text, "0x6098 = 3, 0x6099:1 = 600, 0x6099:2 = 60");
  bool searching_seen = false;
  for (int ms = 0; ms < 5000 && b.snapshot()["homing"]["phase"] != "homing attained"; ms += 10) {
    b.run_ms(10);
    searching_seen = searching_seen || b.snapshot()["homing"]["phase"] == "searching home switch at 0x6099:1 = 600 rpm";
  }
  s = b.snapshot();
  EXPECT_EQ(s["homing"]["phase"], "homing attained") << s["homing"];
  EXPECT_TRUE(searching_seen);
  b.run_ms(200);
  EXPECT_EQ(b.newest_result()["text"], "done: homing attained, 0x6064 = 0") << b.newest_result();

  plant_change fault;
  fault.fault = true;
  fault.fault_code = 0x2310;
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().change_plant(fault); })));
  b.run_ms(500);
  s = b.snapshot();
  ASSERT_EQ(s["drive_errors"]["count"], 1) << s["drive_errors"];
  EXPECT_EQ(s["drive_errors"]["entries"][0]["code"], "0x2310");
  EXPECT_EQ(s["drive_errors"]["entries"][0]["text"], "continuous over-current");
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.remote().clear_error_field(); })));
  b.run_ms(300);
  EXPECT_EQ(b.snapshot()["drive_errors"]["count"], 0) << b.snapshot()["drive_errors"];
}
