// `cia402 serve --can` options through the tool's run(): what is refused before anything is served
// (exit status 2, or 1 for a bus that cannot be reached), with a reason.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../support/cli_run.hpp"

namespace cia402::cli {
namespace {

TEST(cli_serve_can, a_url_that_is_no_channel_is_refused_with_status_2) {
  EXPECT_TRUE(exited_saying(run_tool({"serve", "--can", "tcp://x", "--port", "0"}), 2, "is not socketcand://"));
}

TEST(cli_serve_can, can_virtual_is_refused_with_a_pointer_to_cia402_bus) {
  EXPECT_TRUE(exited_saying(run_tool({"serve", "--can", "virtual", "--port", "0"}), 2, "cia402 bus"));
}

TEST(cli_serve_can, node_without_can_or_outside_1_to_127_is_a_usage_error) {
  EXPECT_NE(run_tool({"serve", "--node", "3", "--port", "0"}).status, 0);
  EXPECT_NE(run_tool({"serve", "--can", "socketcand://127.0.0.1:1/can0", "--node", "128"}).status, 0);
  // --nodes N is for virtual drives; on a bus each drive is named by --node.
  EXPECT_EQ(run_tool({"serve", "--can", "socketcand://127.0.0.1:1/can0", "--nodes", "2"}).status, 2);
  EXPECT_EQ(run_tool({"serve", "--nodes", "17", "--port", "0"}).status, 2);
  EXPECT_EQ(run_tool({"serve", "--nodes", "0", "--port", "0"}).status, 2);
}

TEST(cli_serve_can, a_bus_nobody_listens_on_fails_with_status_1_and_says_why) {
  // Port 1 on loopback: nothing listens there, the connection is refused at once.
  EXPECT_TRUE(exited_saying(run_tool({"serve", "--can", "socketcand://127.0.0.1:1/can0", "--port", "0"}), 1,
                            "cannot reach the bus socketcand://127.0.0.1:1/can0"));
}

TEST(cli_serve_can, an_eds_that_does_not_parse_or_cannot_be_read_is_refused_before_the_bus_is_reached) {
  const std::string path = ::testing::TempDir() + "cia402-serve-bad.eds";
  {
    std::ofstream f(path);
    f << "[1000]\nDataType=0x0007\nno key here\n";
  }
  // Port 1: were the file taken, the bus would be tried and refused with status 1.
  result r = run_tool({"serve", "--can", "socketcand://127.0.0.1:1/can0", "--eds", path, "--port", "0"});
  EXPECT_TRUE(exited_saying(r, 2, path + ":3: "));
  std::remove(path.c_str());
  r = run_tool({"serve", "--can", "socketcand://127.0.0.1:1/can0", "--eds", path, "--port", "0"});
  EXPECT_TRUE(exited_saying(r, 2, "cannot read the file"));
  EXPECT_NE(run_tool({"serve", "--eds", path, "--port", "0"}).status, 0);  // --eds needs --can
}

}  // namespace
}  // namespace cia402::cli
