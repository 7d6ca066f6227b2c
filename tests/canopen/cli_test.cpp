// The `cia402 master`, `cia402 eds` and `cia402 bus` commands through the tool's run(): the virtual
// bus path runs a virtual drive in-process in virtual time; bad options get exit status 2.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "../support/cli_run.hpp"
#include "cli/bus.hpp"

namespace cia402::cli {
namespace {

TEST(cli_master, enable_on_the_virtual_bus_reaches_operation_enabled) {
  const result r = run_tool({"master", "--can", "virtual", "--node", "5", "enable"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("node 5: configured and started"), std::string::npos);
  EXPECT_NE(r.out.find("node 5: READY_TO_SWITCH_ON"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("node 5: reached OPERATION_ENABLED"), std::string::npos) << r.out;
}

TEST(cli_master, velocity_writes_the_target_enables_and_waits_for_the_shaft) {
  const result r = run_tool({"master", "--can", "virtual", "velocity", "600"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("node 1: 0x60FF target velocity = 600 rpm"), std::string::npos) << r.out;
  const auto running = r.out.find("node 1: running at ");
  ASSERT_NE(running, std::string::npos) << r.out;
  // Within 1 % of the target, in OPERATION ENABLED.
  const int rpm = std::stoi(r.out.substr(running + 19));
  EXPECT_GE(rpm, 594);
  EXPECT_LE(rpm, 606);
  EXPECT_NE(r.out.find("rpm in OPERATION_ENABLED"), std::string::npos) << r.out;

  EXPECT_EQ(run_tool({"master", "--can", "virtual", "velocity"}).status, 2);
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "velocity", "fast"}).status, 2);
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "velocity", "3000000000"}).status, 2);
}

TEST(cli_master, mode_switches_0x6060_and_waits_for_0x6061) {
  const result r = run_tool({"master", "--can", "virtual", "mode", "csp"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("node 1: mode 8 (csp)"), std::string::npos) << r.out;
  const result json = run_tool({"master", "--can", "virtual", "--json", "mode", "6"});
  ASSERT_EQ(json.status, 0) << json.err;
  EXPECT_NE(json.out.find(R"({"node":1,"event":"mode","mode":6,"name":"hm"})"), std::string::npos) << json.out;
  // vl (2) is not among the modes 0x6502 announces: said at once, before 0x6060 is written; exit 1.
  const result refused = run_tool({"master", "--can", "virtual", "mode", "2"});
  EXPECT_TRUE(exited_saying(refused, 1, "mode 2 is not among the modes 0x6502 announces"));
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "mode", "warp"}).status, 2);
}

TEST(cli_master, move_runs_the_set_point_handshake_to_the_target) {
  const result r = run_tool({"master", "--can", "virtual", "move", "20000", "--velocity", "600"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("node 1: set-point 20000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("node 1: target reached, position 20000"), std::string::npos) << r.out;
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "move"}).status, 2);
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "move", "3000000000"}).status, 2);
}

TEST(cli_master, home_sets_the_position_to_the_home_offset) {
  for (const char* method : {"37", "3"}) {
    const result r = run_tool({"master", "--can", "virtual", "home", "--method", method, "--offset", "1234"});
    ASSERT_EQ(r.status, 0) << method << r.err;
    EXPECT_NE(r.out.find("node 1: homing attained, position 1234"), std::string::npos) << method << r.out;
  }
  // Method 15 is reserved (CiA 402-2): 0x60E3 does not list it, so it is refused before anything is
  // sent (S20), exit 2.
  const result refused = run_tool({"master", "--can", "virtual", "home", "--method", "15"});
  EXPECT_TRUE(exited_saying(refused, 2, "homing method 15 is not among 0x60E3 (supported homing methods)"));
}

TEST(cli_master, csp_stream_ramps_0x607A_by_rpdo3_and_follows_by_tpdo3) {
  const result r = run_tool({"master", "--can", "virtual", "csp-stream", "--to", "20000", "--velocity", "600"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("node 1: mode 8 (csp)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("node 1: streaming 0x607A from 0 to 20000 at 600 rpm by RPDO3, SYNC every 1000 us"),
            std::string::npos)
      << r.out;
  // 600 rpm x 10,000 increments a revolution = 100 increments a 1 ms SYNC: 200 set-points, each
  // reached within its cycle.
  EXPECT_NE(r.out.find("node 1: reached 20000 after 200 set-points, max following error 0 increments"),
            std::string::npos)
      << r.out;
  const result json = run_tool({"master", "--can", "virtual", "--json", "csp-stream", "--to", "-3000",
                                "--velocity", "300", "--sync-us", "2000"});
  ASSERT_EQ(json.status, 0) << json.err;
  EXPECT_NE(json.out.find(R"({"node":1,"event":"streamed","position":-3000,"set_points":30,)"), std::string::npos)
      << json.out;
  // Beyond 0x607F: refused before anything moves (S20), exit 2.
  const result beyond = run_tool({"master", "--can", "virtual", "csp-stream", "--to", "200000000", "--velocity", "100000"});
  EXPECT_TRUE(exited_saying(beyond, 2, "csp velocity 100000 rpm is beyond 0x607F (max profile velocity) = 6000 rpm"));
  // With the limits raised, faster than the motor can follow: the following error fault, exit 1.
  const result lost = run_tool({"master", "--can", "virtual", "sdo", "write", "0x607F", "100000", "sdo", "write", "0x6080",
                                "100000", "csp-stream", "--to", "200000000", "--velocity", "100000"});
  EXPECT_TRUE(exited_saying(lost, 1, "following error"));
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "csp-stream", "--to", "100"}).status, 2) << "no --velocity";
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "csp-stream", "--velocity", "100"}).status, 2) << "no --to";
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "csp-stream", "--to", "3000000000", "--velocity", "1"}).status, 2);
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "csp-stream", "--to", "1", "--velocity", "1", "--sync-us", "10"}).status, 2);
}

TEST(cli_master, watch_json_prints_one_object_per_event) {
  const result r = run_tool({"master", "--can", "virtual", "--json", "--timeout", "300", "watch"});
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int count = 0;
  bool started = false;
  bool state_seen = false;
  while (std::getline(lines, line)) {
    ++count;
    ASSERT_EQ(line.rfind("{\"node\":1,\"event\":\"", 0), 0u) << line;
    started = started || line.find("\"event\":\"started\"") != std::string::npos;
    state_seen = state_seen || line.find("\"event\":\"state\",\"state\":\"SWITCH_ON_DISABLED\"") !=
                                   std::string::npos;
  }
  EXPECT_GE(count, 2);
  EXPECT_TRUE(started) << r.out;
  EXPECT_TRUE(state_seen) << r.out;
}

TEST(cli_master, state_reads_the_status_word_over_sdo) {
  const result r = run_tool({"master", "--can", "virtual", "state"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "node 1: SWITCH_ON_DISABLED (statusword 0x1250)\n");
}

TEST(cli_master, reset_of_a_drive_not_in_fault_looks_and_changes_nothing) {
  const result r = run_tool({"master", "--can", "virtual", "reset"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "node 1: SWITCH_ON_DISABLED (statusword 0x1250): not in FAULT, nothing to reset\n")
      << "read over SDO, before any PDO is set up or the node started";
}

// The guard is one of the things the master put back: 0x1016 as it found it (no watch of node 127).
TEST(cli_master, guard_is_cleared_when_the_master_ends) {
  const result r = run_tool({"master", "--can", "virtual", "--guard", "20", "enable"});
  EXPECT_EQ(r.status, 0) << r.err;
  const auto reached = r.out.find("node 1: reached OPERATION_ENABLED\n");
  const auto put_back = r.out.find("node 1: put back as found: ");
  ASSERT_NE(reached, std::string::npos) << r.out;
  ASSERT_NE(put_back, std::string::npos) << r.out;
  EXPECT_GT(put_back, reached);
  EXPECT_NE(r.out.find("0x1016 (Consumer heartbeat time)", put_back), std::string::npos) << r.out;
}

TEST(cli_master, sdo_read_and_write_need_no_set_up_and_say_the_drives_answer) {
  const result sw = run_tool({"master", "--can", "virtual", "sdo", "read", "0x6041"});
  EXPECT_EQ(sw.status, 0) << sw.err;
  EXPECT_EQ(sw.out, "node 1: 0x6041:0 = 4688 (0x1250)\n") << "SWITCH ON DISABLED, remote, voltage";
  const result js = run_tool({"master", "--can", "virtual", "--json", "sdo", "read", "0x6041"});
  EXPECT_EQ(js.out, "{\"node\":1,\"event\":\"sdo\",\"object\":\"0x6041:0\",\"value\":4688,\"type\":\"unsigned16\"}\n");
  const result w = run_tool({"master", "--can", "virtual", "sdo", "write", "0x60FF", "-300"});
  EXPECT_EQ(w.status, 0) << w.err;
  EXPECT_EQ(w.out, "node 1: 0x60FF:0 written: -300 (0xFFFFFED4)\n");
  const result missing = run_tool({"master", "--can", "virtual", "sdo", "read", "0x6FFF"});
  EXPECT_TRUE(exited_saying(missing, 1, "SDO abort 0x06020000"));
  const result too_big = run_tool({"master", "--can", "virtual", "sdo", "write", "0x6060", "300"});
  EXPECT_EQ(too_big.status, 2) << "0x6060 is an INTEGER8: refused before anything is sent";
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "sdo", "read"}).status, 2);
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "sdo", "read", "0x6041:x"}).status, 2);
}

TEST(cli_master, nmt_sends_the_command_and_state_speaks_json) {
  const result nmt = run_tool({"master", "--can", "virtual", "nmt", "preop"});
  EXPECT_EQ(nmt.status, 0) << nmt.err;
  EXPECT_EQ(nmt.out, "node 1: NMT preop sent\n");
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "nmt", "fly"}).status, 2);
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "enable", "now"}).status, 2);
  const result state = run_tool({"master", "--can", "virtual", "--json", "state"});
  EXPECT_EQ(state.out,
            "{\"node\":1,\"event\":\"status\",\"state\":\"SWITCH_ON_DISABLED\",\"statusword\":\"0x1250\","
            "\"error_code\":\"0x0000\"}\n");
}

TEST(cli_master, bad_url_command_or_node_is_refused_with_status_2) {
  EXPECT_EQ(run_tool({"master", "--can", "tcp://x", "enable"}).status, 2);
  EXPECT_NE(run_tool({"master", "--can", "tcp://x", "enable"}).err.find("is not socketcand://"),
            std::string::npos);
  EXPECT_NE(run_tool({"master", "--can", "virtual", "fly"}).status, 0);
  EXPECT_NE(run_tool({"master", "--can", "virtual", "--node", "128", "state"}).status, 0);
}

TEST(cli_master, unreachable_socketcand_server_fails_with_status_1) {
  const result r = run_tool({"master", "--can", "socketcand://no.such.host.invalid:29536/can0", "state"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("cia402 master:"), std::string::npos);
}

TEST(cli_eds, eds_starts_with_file_info_and_names_the_profile) {
  const result r = run_tool({"eds", "--profile", "lexium32"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("[FileInfo]\n", 0), 0u);
  EXPECT_NE(r.out.find("profile lexium32"), std::string::npos);
  EXPECT_NE(r.out.find("[MandatoryObjects]"), std::string::npos);
}

// An EDS describes every node alike ($NODEID); --node names the node the file is written for, in
// CiA 306's commissioning section, so `--node 5` is not the file of node 1.
TEST(cli_eds, node_option_writes_the_commissioning_section) {
  const result plain = run_tool({"eds"});
  const result five = run_tool({"eds", "--node", "5"});
  ASSERT_EQ(five.status, 0) << five.err;
  EXPECT_EQ(plain.out.find("[DeviceComissioning]"), std::string::npos);
  EXPECT_NE(five.out.find("[DeviceComissioning]\nNodeID=5\n"), std::string::npos) << five.out;
  EXPECT_EQ(run_tool({"eds", "--node", "0"}).status, 2);
}

TEST(cli_bus, bad_options_are_refused_before_listening) {
  EXPECT_EQ(run_tool({"bus", "--nodes", "0-3"}).status, 2);
  EXPECT_EQ(run_tool({"bus", "--nodes", "1,1"}).status, 2);
  EXPECT_EQ(run_tool({"bus", "--listen", "nowhere"}).status, 2);
  EXPECT_EQ(run_tool({"bus", "--profile", "nosuch"}).status, 2);
  // socketcand has no authentication: beyond loopback only when asked for by name.
  const result remote = run_tool({"bus", "--listen", "0.0.0.0:0"});
  EXPECT_TRUE(exited_saying(remote, 2, "no authentication"));
  EXPECT_NE(remote.err.find("--allow-remote"), std::string::npos) << remote.err;
}

TEST(cli_bus, a_log_file_that_cannot_be_created_is_refused_before_listening) {
  const result r = run_tool({"bus", "--listen", "127.0.0.1:0", "--log", "/nonexistent-folder/bus.log"});
  EXPECT_TRUE(exited_saying(r, 2, "--log /nonexistent-folder/bus.log: cannot create the file"));
  EXPECT_EQ(r.out.find("socketcand on"), std::string::npos) << r.out;
}

TEST(cli_bus, node_lists_parse_ranges_and_singles) {
  std::vector<std::uint8_t> ids;
  std::string why;
  ASSERT_TRUE(parse_node_list("1-3,7", ids, why)) << why;
  EXPECT_EQ(ids, (std::vector<std::uint8_t>{1, 2, 3, 7}));
  EXPECT_FALSE(parse_node_list("5-2", ids, why));
  EXPECT_FALSE(parse_node_list("127-128", ids, why));
  EXPECT_FALSE(parse_node_list("", ids, why));
  EXPECT_FALSE(parse_node_list("2,1-3", ids, why));
  EXPECT_NE(why.find("node 2 is listed twice"), std::string::npos);
}

// `cia402 esi`: the EtherCAT ESI of the virtual drive, from the description its SII is built from.
TEST(cli_esi, prints_the_drives_esi_with_its_identity_and_pdos) {
  const result r = run_tool({"esi"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("<?xml", 0), 0u);
  EXPECT_NE(r.out.find("ProductCode=\"#x00000402\""), std::string::npos);
  EXPECT_NE(r.out.find("<RxPdo Sm=\"2\""), std::string::npos);
  EXPECT_NE(r.out.find("<Index>#x607A</Index>"), std::string::npos) << "target position for csp";
  EXPECT_NE(r.out.find("<Index>#x6064</Index>"), std::string::npos);
  EXPECT_NE(r.out.find("<ProfileNo>402</ProfileNo>"), std::string::npos);
  EXPECT_EQ(run_tool({"esi", "-o", "/nonexistent/dir/x.xml"}).status, 2);
}

}  // namespace
}  // namespace cia402::cli
