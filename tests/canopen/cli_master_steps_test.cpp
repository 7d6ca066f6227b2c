// `cia402 master` as one command set: several steps in one run on the virtual bus, the steps the
// old command lacked, objects with their types, and every failure exiting non-zero at once.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../support/cli_run.hpp"

namespace cia402::cli {
namespace {

std::vector<nlohmann::json> lines_of(const std::string& out) {
  std::vector<nlohmann::json> v;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) v.push_back(nlohmann::json::parse(line));
  return v;
}

TEST(cli_master_steps, the_done_when_command_runs_every_step_in_one_session) {
  const result r = run_tool({"master", "--can", "virtual", "--json", "enable", "mode", "pp", "move", "20000", "mode", "pv",
                             "velocity", "300", "wait", "500", "home", "37", "sdo", "write", "0x1017", "100", "sdo",
                             "read", "0x1017", "sdo", "read", "0x1008", "quick-stop", "reset", "disable"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto lines = lines_of(r.out);
  bool moved = false, read_back = false, named = false;
  std::string last_state;
  for (const auto& l : lines) {
    ASSERT_EQ(l["node"], 1) << l;
    moved = moved || (l["event"] == "reached" && l.value("position", 0) == 20000);
    read_back = read_back || (l["event"] == "sdo" && l["object"] == "0x1017:0" && l["value"] == 100);
    named = named || (l["event"] == "sdo" && l["object"] == "0x1008:0" && l["value"] == "cia402 virtual drive");
    if (l["event"] == "reached" && l.contains("state")) last_state = l["state"];
  }
  EXPECT_TRUE(moved) << r.out;
  EXPECT_TRUE(read_back) << "0x1017 written as UNSIGNED16, as CiA 301 types it" << r.out;
  EXPECT_TRUE(named) << "0x1008 as text" << r.out;
  EXPECT_EQ(last_state, "SWITCH_ON_DISABLED");
}

TEST(cli_master_steps, velocity_outside_pv_switches_the_mode_itself) {
  const result r = run_tool({"master", "--can", "virtual", "mode", "pp", "velocity", "500"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("node 1: mode 3 (pv)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("node 1: running at "), std::string::npos) << r.out;
}

TEST(cli_master_steps, hold_with_a_timeout_that_is_not_met_exits_1) {
  const result r = run_tool({"master", "--can", "virtual", "--hold", "--timeout", "300", "move", "2000000", "--velocity", "10"});
  EXPECT_TRUE(exited_saying(r, 1,
                            "move 2000000 --velocity 10: did not finish within 300 ms (the drive shows "
                            "OPERATION_ENABLED"));
}

TEST(cli_master_steps, torque_jog_and_halt_run_on_the_virtual_bus) {
  const result r = run_tool({"master", "--can", "virtual", "torque", "150", "jog", "200", "300", "halt", "on", "halt", "off",
                             "disable"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("node 1: mode 4 (tq)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("permille reached"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("node 1: jogging at 200 rpm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("node 1: jog released"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("node 1: halt on (control bit 8)"), std::string::npos) << r.out;
}

TEST(cli_master_steps, a_fault_injected_and_cleared_is_reset_in_the_same_run) {
  const result r = run_tool({"master", "--can", "virtual", "--json", "enable", "sdo", "write", "0x2001", "0x2310", "wait",
                             "50", "sdo", "write", "0x2001", "0", "reset", "state"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(R"("event":"state","state":"FAULT","statusword":"0x1218","error_code":"0x2310")"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find(R"("event":"emcy","error_code":"0x2310")"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(R"("event":"sdo_written","object":"0x2001:0","value":8976,"type":"unsigned16")"), std::string::npos)
      << "0x2001 typed as the virtual drive's dictionary says" << r.out;
  EXPECT_NE(r.out.find(R"({"node":1,"event":"status","state":"SWITCH_ON_DISABLED")"), std::string::npos) << r.out;
}

TEST(cli_master_steps, a_fault_whose_cause_persists_fails_the_reset_at_once_with_its_text) {
  const result r = run_tool({"master", "--can", "virtual", "enable", "sdo", "write", "0x2001", "0x2310", "wait", "50",
                             "reset"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("still in FAULT after the fault-reset edge: error code 0x2310 (continuous over-current); is the "
                       "fault cause still present?"),
            std::string::npos)
      << r.err;
  const result refused = run_tool({"master", "--can", "virtual", "enable", "sdo", "write", "0x2001", "0x2310", "wait", "50",
                                   "velocity", "100"});
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("velocity 100: the drive is in FAULT: error code 0x2310 (continuous over-current); reset it "
                             "first"),
            std::string::npos)
      << refused.err;
  // Faulted before the node was set up: the refusal still says what to do.
  const result first = run_tool({"master", "--can", "virtual", "sdo", "write", "0x2001", "0x2310", "wait", "50", "enable"});
  EXPECT_EQ(first.status, 1);
  EXPECT_NE(first.err.find("enable: the drive is in FAULT: error code 0x2310 (continuous over-current); reset it first"),
            std::string::npos)
      << first.err;
}

TEST(cli_master_steps, texts_and_bytes_go_with_their_type) {
  const result r = run_tool({"master", "--can", "virtual", "--json", "sdo", "write", "0x2000", "\"axis 1\"", "sdo", "read",
                             "0x2000", "sdo", "read", "0x1018:2"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(R"("object":"0x2000:0","value":"axis 1","type":"visible_string")"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(R"("object":"0x1018:2","value":1026,"type":"unsigned32")"), std::string::npos) << r.out;
  const result bad = run_tool({"master", "--can", "virtual", "sdo", "write", "0x1017", "\"text\""});
  EXPECT_EQ(bad.status, 2) << "a text for an UNSIGNED16";
  EXPECT_NE(bad.err.find("a text for an object of type unsigned16"), std::string::npos) << bad.err;
}

TEST(cli_master_steps, options_belong_to_the_step_before_them) {
  EXPECT_EQ(run_tool({"master", "--can", "virtual", "--velocity", "5", "move", "10"}).status, 2);
  const result wrong = run_tool({"master", "--can", "virtual", "enable", "--relative"});
  EXPECT_TRUE(exited_saying(wrong, 2, "--relative belongs to move, not enable"));
  const result two = run_tool({"master", "--can", "virtual", "--json", "move", "1000", "--velocity", "600", "move", "500",
                               "--relative", "--velocity", "300"});
  ASSERT_EQ(two.status, 0) << two.err;
  EXPECT_NE(two.out.find(R"({"node":1,"event":"reached","position":1500})"), std::string::npos) << two.out;
}

// Issue 42: NMT stop and start within one run. A STOPPED node serves no SDO: the link holds its
// transfers (the session's start-up reads among them) until NMT start instead of losing the node to
// an SDO time-out, and after stop the status word it knew is old until a PDO brings a new one.
TEST(cli_master_steps, nmt_stop_then_start_goes_on_in_the_same_run) {
  const result r = run_tool({"master", "--can", "virtual", "--node", "2", "nmt", "stop", "nmt", "start", "state"});
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("node 2: SWITCH_ON_DISABLED (statusword 0x1250)"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("does not answer"), std::string::npos) << r.err;
  const result waited = run_tool({"master", "--can", "virtual", "--node", "2", "nmt", "stop", "wait", "100", "nmt", "start",
                                  "state"});
  ASSERT_EQ(waited.status, 0) << waited.err << waited.out;
}

TEST(cli_master_steps, after_nmt_stop_and_start_the_state_is_the_drives_new_one_not_the_last_seen) {
  // Enabled, the drive takes NMT STOPPED for a lost connection (0x6007 = 1: a fault, 0x8130); the
  // state after NMT start is that FAULT, not the OPERATION ENABLED seen before the stop.
  const result r = run_tool({"master", "--can", "virtual", "--node", "2", "--json", "enable", "nmt", "stop", "nmt", "start",
                             "state"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto lines = lines_of(r.out);
  bool started = false;
  std::string first_after;
  for (const auto& l : lines) {
    if (l["event"] == "nmt" && l["command"] == "start") started = true;
    if (started && first_after.empty() && (l["event"] == "state" || l["event"] == "status")) first_after = l["state"];
  }
  EXPECT_EQ(first_after, "FAULT") << r.out;
  const result again = run_tool({"master", "--can", "virtual", "--node", "2", "enable", "nmt", "stop", "nmt", "start", "enable"});
  EXPECT_EQ(again.status, 1) << "not 'reached' from the old status word" << again.out;
  EXPECT_NE(again.err.find("enable: the drive is in FAULT: error code 0x8130"), std::string::npos) << again.err;
}

TEST(cli_master_steps, a_stopped_node_is_said_stopped_and_set_up_from_pre_operational) {
  const result r = run_tool({"master", "--can", "virtual", "--node", "2", "nmt", "stop", "state"});
  EXPECT_TRUE(exited_saying(r, 1, "node 2 is STOPPED (NMT stop): it serves no SDO until NMT start or preop"));
  const result enabled = run_tool({"master", "--can", "virtual", "--node", "2", "nmt", "stop", "enable"});
  ASSERT_EQ(enabled.status, 0) << enabled.err << enabled.out;
  EXPECT_NE(enabled.out.find("node 2: reached OPERATION_ENABLED"), std::string::npos) << enabled.out;
  const result left = run_tool({"master", "--can", "virtual", "--node", "2", "enable", "nmt", "stop"});
  ASSERT_EQ(left.status, 0) << left.err;
  EXPECT_NE(left.out.find("0x1A00 (TPDO1 mapping parameter) not put back: node 2 is STOPPED (NMT stop)"), std::string::npos)
      << left.out;
  EXPECT_NE(left.out.find("NMT state STOPPED, as NMT stop left it"), std::string::npos) << left.out;
}

TEST(cli_master_steps, a_node_reset_after_it_was_read_is_read_again) {
  const result r = run_tool({"master", "--can", "virtual", "--node", "2", "state", "nmt", "reset", "state"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("node 2: node 2 restarted (boot-up message)"), std::string::npos) << r.out;
}

TEST(cli_master_steps, nmt_on_ethercat_is_refused_before_the_line_is_opened) {
  EXPECT_TRUE(exited_saying(run_tool({"master", "--ecat", "no-such-interface", "nmt", "start"}), 2,
                            "nmt is CANopen's"));
}

TEST(cli_master_steps, an_eds_that_does_not_parse_is_refused_with_its_line) {
  const std::string path = ::testing::TempDir() + "bad.eds";
  std::ofstream(path) << "[1000]\nDataType=banana\n";
  EXPECT_TRUE(exited_saying(run_tool({"master", "--can", "virtual", "--eds", path, "state"}), 2,
                            "--eds " + path + ":"));
}

}  // namespace
}  // namespace cia402::cli
