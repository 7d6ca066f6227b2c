// `cia402 monitor` through the tool's run(): a candump log on standard input decoded as lines and
// as JSON, --count / --duration, --eds, and the refusals (exit status 2) and a bus it cannot join (1).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"

namespace cia402::cli {
namespace {

// A session on node 3 as `cia402 bus --log` writes it.
const std::string session =
    "(1700000000.000000) can0 703#00\n"
    "(1700000000.001000) can0 603#2F60600002000000\n"
    "(1700000000.001200) can0 583#8060600030000906\n"
    "(1700000000.002000) can0 000#0103\n"
    "(1700000000.002100) can0 183#3706\n"
    "(1700000000.003000) can0 083#1023033706000000\n"
    "(1700000000.100000) can0 703#05\n";

TEST(cli_monitor, a_log_decodes_one_line_per_frame_with_the_time_since_the_first) {
  const result r = run_tool({"monitor", "--log", "-"}, session);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out,
            "  0.000000  node 3   boot-up\n"
            "  0.001000  node 3   SDO download 0x6060:0 = 2 (Modes of operation)\n"
            "  0.001200  node 3   SDO abort 0x6060:0 0x06090030 invalid value for parameter\n"
            "  0.002000  node 3   NMT start\n"
            "  0.002100  node 3   TPDO1 0x6041:0 = 0x0637 (Statusword: OPERATION_ENABLED)\n"
            "  0.003000  node 3   EMCY 0x2310 continuous over-current, error register 0x03, "
            "manufacturer 37 06 00 00 00\n"
            "  0.100000  node 3   heartbeat OPERATIONAL\n");
}

TEST(cli_monitor, json_gives_one_object_per_frame_with_its_fields) {
  const result r = run_tool({"monitor", "--log", "-", "--json"}, session);
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<nlohmann::json> records;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) records.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(records.size(), 7u);
  EXPECT_EQ(records[2]["kind"], "sdo");
  EXPECT_EQ(records[2]["event"], "abort");
  EXPECT_EQ(records[2]["object"], "0x6060:0");
  EXPECT_EQ(records[2]["code"], "0x06090030");
  EXPECT_EQ(records[4]["kind"], "pdo");
  EXPECT_EQ(records[4]["event"], "TPDO1");
  EXPECT_EQ(records[4]["id"], "0x183");
  EXPECT_EQ(records[4]["data"], "3706");
  EXPECT_EQ(records[4]["values"][0]["value"], 0x0637);
  EXPECT_EQ(records[4]["values"][0]["meaning"], "OPERATION_ENABLED");
  EXPECT_EQ(records[5]["code"], "0x2310");
  EXPECT_EQ(records[5]["code_text"], "continuous over-current");
  EXPECT_EQ(records[6]["time_us"], 1700000000100000u);
  EXPECT_EQ(records[6]["event"], "operational");
}

TEST(cli_monitor, count_and_duration_stop_the_decoding) {
  const result counted = run_tool({"monitor", "--log", "-", "--count", "2"}, session);
  EXPECT_EQ(counted.status, 0);
  EXPECT_EQ(std::count(counted.out.begin(), counted.out.end(), '\n'), 2);
  const result timed = run_tool({"monitor", "--log", "-", "--duration", "50"}, session);
  EXPECT_EQ(timed.status, 0);
  EXPECT_EQ(std::count(timed.out.begin(), timed.out.end(), '\n'), 6);  // not the heartbeat at 100 ms
}

TEST(cli_monitor, lines_that_are_no_frame_are_named_and_the_rest_is_decoded_with_status_2) {
  const result r = run_tool({"monitor", "--log", "-"}, "(1.0) can0 080#\ngarbage\n(1.1) can0 123##1AB\n(1.2) can0 080#\n");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 2);
  EXPECT_NE(r.err.find("-:2: expected"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("-:3: a CAN FD frame"), std::string::npos) << r.err;
}

TEST(cli_monitor, an_eds_describes_its_node) {
  const std::string path = ::testing::TempDir() + "cli_monitor_test.eds";
  {
    std::ofstream eds(path);
    eds << "[DeviceComissioning]\nNodeID=3\n"
           "[1800]\nObjectType=0x9\n[1A00]\nObjectType=0x9\n"
           "[1800sub1]\nDataType=0x0007\nDefaultValue=$NODEID+0x180\n"
           "[1A00sub0]\nDataType=0x0005\nDefaultValue=1\n"
           "[1A00sub1]\nDataType=0x0007\nDefaultValue=0x60640020\n";
  }
  const result named = run_tool({"monitor", "--log", "-", "--eds", path}, "(1.0) can0 183#10270000\n");
  EXPECT_EQ(named.status, 0) << named.err;
  EXPECT_NE(named.out.find("TPDO1 0x6064:0 = 10000 inc (Position actual value)"), std::string::npos) << named.out;
  const result other = run_tool({"monitor", "--log", "-", "--eds", path, "--node", "5"}, "(1.0) can0 183#3706\n");
  EXPECT_NE(other.out.find("TPDO1 0x6041:0 = 0x0637"), std::string::npos) << other.out;  // node 3: the drive's
  std::remove(path.c_str());
}

TEST(cli_monitor, refused_options_exit_2_and_a_bus_it_cannot_join_exits_1) {
  EXPECT_EQ(run_tool({"monitor"}).status, 2);
  EXPECT_EQ(run_tool({"monitor", "socketcand://127.0.0.1:1/can0", "--log", "x.log"}).status, 2);
  EXPECT_EQ(run_tool({"monitor", "tcp://x"}).status, 2);
  EXPECT_EQ(run_tool({"monitor", "virtual"}).status, 2);
  EXPECT_EQ(run_tool({"monitor", "--log", "/nonexistent-folder/x.log"}).status, 2);
  const result no_eds = run_tool({"monitor", "--log", "-", "--eds", "/nonexistent-folder/x.eds"});
  EXPECT_EQ(no_eds.status, 2);
  EXPECT_NE(no_eds.err.find("cannot read the file"), std::string::npos);
  EXPECT_EQ(run_tool({"monitor", "--log", "-", "--eds", "a.eds", "--eds", "b.eds", "--node", "1"}).status, 2);
  const result unreachable = run_tool({"monitor", "socketcand://no.such.host.invalid:29536/can0"});
  EXPECT_EQ(unreachable.status, 1);
  EXPECT_NE(unreachable.err.find("cia402 monitor:"), std::string::npos);
}

}  // namespace
}  // namespace cia402::cli
