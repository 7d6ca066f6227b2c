// candump's log format (transport/candump_log.hpp), written and read, and `cia402 bus --log`'s tap
// on the bus (apps::bus_host::log_frames): every frame the bus carries, in order, stamped with the
// wall clock. Expected lines are written out as can-utils' candump -l prints them.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "cia402/apps/bus_host.hpp"
#include "cia402/apps/elapsed_clock.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/transport/candump_log.hpp"

namespace cia402::canopen {
namespace {

using candump::format_line;
using candump::log_entry;
using candump::parse_line;

TEST(candump_log, frames_format_as_candump_l_prints_them) {
  EXPECT_EQ(format_line(make_frame(0x183, {0x37, 0x06}), 1700000000123456, "can0"),
            "(1700000000.123456) can0 183#3706");
  EXPECT_EQ(format_line(make_frame(0x080, {}), 5, "vcan1"), "(0.000005) vcan1 080#");
  frame ext = make_frame(0x1ABCDEF, {0xDE, 0xAD});
  ext.extended = true;
  EXPECT_EQ(format_line(ext, 1000000, "can0"), "(1.000000) can0 01ABCDEF#DEAD");
  frame rtr;
  rtr.id = 0x701;
  rtr.rtr = true;
  EXPECT_EQ(format_line(rtr, 0, "can0"), "(0.000000) can0 701#R");
  rtr.len = 1;
  EXPECT_EQ(format_line(rtr, 0, "can0"), "(0.000000) can0 701#R1");
}

TEST(candump_log, every_line_written_reads_back_as_the_same_frame_and_time) {
  std::vector<frame> frames = {make_frame(0x000, {0x01, 0x00}), make_frame(0x7FF, {}),
                               make_frame(0x581, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00})};
  frame ext = make_frame(0x1FFFFFFF, {1, 2, 3});
  ext.extended = true;
  frames.push_back(ext);
  frame low_ext = make_frame(0x123, {});
  low_ext.extended = true;  // an extended frame with a small identifier stays extended
  frames.push_back(low_ext);
  frame rtr;
  rtr.id = 0x181;
  rtr.rtr = true;
  rtr.len = 2;
  frames.push_back(rtr);
  std::uint64_t t = 1700000000000001;
  for (const frame& f : frames) {
    log_entry e;
    std::string why;
    ASSERT_TRUE(parse_line(format_line(f, t, "can0") + "\n", e, why)) << why;
    EXPECT_EQ(e.f, f);
    EXPECT_EQ(e.time_us, t);
    EXPECT_EQ(e.interface, "can0");
    t += 999;
  }
}

TEST(candump_log, python_cans_writer_lines_with_a_direction_read) {
  log_entry e;
  std::string why;
  ASSERT_TRUE(parse_line("(12.5) can0 181#3712 R", e, why)) << why;
  EXPECT_EQ(e.time_us, 12500000u);
  EXPECT_EQ(e.f, make_frame(0x181, {0x37, 0x12}));
  ASSERT_TRUE(parse_line("(0.000001) vcan0 601#4000100000000000 T\r\n", e, why)) << why;
  EXPECT_EQ(e.f.id, 0x601u);
  EXPECT_EQ(e.f.len, 8);
}

TEST(candump_log, lines_that_are_no_classic_can_frame_are_refused_and_give_nothing) {
  const char* bad[] = {
      "",                                     // nothing
      "(1.0) can0",                           // no frame
      "1.0 can0 123#00",                      // no parentheses
      "(1) can0 123#00",                      // no fraction
      "(1.x) can0 123#00",                    // not digits
      "(1.0) can0 12300",                     // no '#'
      "(1.0) can0 800#00",                    // 11-bit identifier above 0x7FF
      "(1.0) can0 20000080#0000000000000000",  // an error frame
      "(1.0) can0 123##1AABB",                // CAN FD
      "(1.0) can0 123#ABC",                   // odd number of digits
      "(1.0) can0 123#000102030405060708",    // 9 bytes
      "(1.0) can0 123#GG",                    // not hexadecimal
      "(1.0) can0 123#R9",                    // remote frame longer than 8
      "(1.0) can0 12G#00",                    // identifier not hexadecimal
      "(1.0) can0 123456789#00",              // 9 digits
      "(1.0) can0 123#00 X",                  // an unknown trailing word
      "(1234567890123.0) can0 123#00",        // more seconds than the format has room for
  };
  for (const char* line : bad) {
    log_entry e;
    e.interface = "untouched";
    std::string why;
    EXPECT_FALSE(parse_line(line, e, why)) << line;
    EXPECT_FALSE(why.empty()) << line;
    EXPECT_EQ(e.interface, "untouched") << line;
  }
}

std::vector<std::string> read_lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class bus_log_test : public ::testing::Test {
 protected:
  void TearDown() override { std::remove(path.c_str()); }
  std::string path = ::testing::TempDir() + "bus_log_test.log";
  apps::bus_host host{[] {
    socketcand::server_config c;
    c.port = 0;
    return c;
  }()};
};

TEST_F(bus_log_test, the_log_holds_every_frame_the_bus_carried_in_order_with_the_wall_clock) {
  auto witness = host.bus().attach();  // sees every frame but its own (it sends none)
  auto client = host.bus().attach();
  ASSERT_FALSE(host.log_frames(path, "can0"));
  const std::uint64_t before = apps::unix_time_us();
  host.add_drive(standard_profile(), apps::drive_node_config(3));
  (void)host.cycle(1000);  // boot-up
  ASSERT_FALSE(client->send(make_frame(0x603, {0x40, 0x41, 0x60, 0, 0, 0, 0, 0})));
  ASSERT_FALSE(client->send(make_frame(0x000, {0x01, 0x03})));
  for (int i = 0; i < 5; ++i) (void)host.cycle(1000);
  const std::uint64_t after = apps::unix_time_us();

  std::vector<frame> seen;
  for (frame f; witness->receive(f);) seen.push_back(f);
  const auto lines = read_lines(path);
  ASSERT_EQ(lines.size(), seen.size());
  ASSERT_GE(seen.size(), 4u);  // boot-up, SDO request and response, NMT, TPDOs
  EXPECT_EQ(host.frames_logged(), seen.size());
  std::uint64_t last = before;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    log_entry e;
    std::string why;
    ASSERT_TRUE(parse_line(lines[i], e, why)) << lines[i] << ": " << why;
    EXPECT_EQ(e.f, seen[i]) << lines[i];
    EXPECT_EQ(e.interface, "can0");
    EXPECT_GE(e.time_us, last) << lines[i];
    EXPECT_LE(e.time_us, after) << lines[i];
    last = e.time_us;
  }
}

TEST_F(bus_log_test, a_log_that_cannot_be_opened_is_an_error_and_logs_nothing) {
  const std::error_code ec = host.log_frames("/nonexistent-folder/bus.log", "can0");
  EXPECT_TRUE(ec);
  auto client = host.bus().attach();
  ASSERT_FALSE(client->send(make_frame(0x080, {})));
  (void)host.cycle(1000);
  EXPECT_EQ(host.frames_logged(), 0u);
  EXPECT_FALSE(host.log_failure());
}

TEST_F(bus_log_test, lines_are_flushed_at_the_end_of_each_pass_so_a_reader_sees_them_at_once) {
  ASSERT_FALSE(host.log_frames(path, "can0"));
  auto client = host.bus().attach();
  ASSERT_FALSE(client->send(make_frame(0x080, {})));
  (void)host.cycle(1000);
  const auto lines = read_lines(path);  // the host is still running: nothing closed the file
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find(" can0 080#"), std::string::npos) << lines[0];
}

}  // namespace
}  // namespace cia402::canopen
