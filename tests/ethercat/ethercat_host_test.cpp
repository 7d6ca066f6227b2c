// How `cia402 ecat-slave` shares its one thread between frames and the drives' application cycles:
// wall time makes cycles due, and the drives are stepped one at a time so that the host looks at
// the socket between any two steps. A frame then waits at most one drive's step, whatever the
// number of drives or the time owed after a stall: its answer time depends on the frame alone.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "cia402/apps/ethercat_host.hpp"
#include "cia402/profile.hpp"

namespace cia402::apps {
namespace {

constexpr std::uint32_t cycle_us = 1000;

// Each drive's own time: the application steps it was given.
std::vector<std::uint64_t> drive_times_ns(ethercat_host& host) {
  std::vector<std::uint64_t> t;
  for (auto& d : host.drives()) t.push_back(d->device().drive().time_us() * 1000);
  return t;
}

TEST(ethercat_host, no_drive_is_stepped_before_a_whole_cycle_has_passed) {
  ethercat_host host(standard_profile(), 3, cycle_us);
  EXPECT_FALSE(host.step_one_drive(cycle_us - 1));
  EXPECT_EQ(drive_times_ns(host), (std::vector<std::uint64_t>{0, 0, 0}));
}

TEST(ethercat_host, a_due_cycle_steps_one_drive_per_call_in_line_order) {
  ethercat_host host(standard_profile(), 3, cycle_us);
  EXPECT_TRUE(host.step_one_drive(cycle_us));
  EXPECT_EQ(drive_times_ns(host), (std::vector<std::uint64_t>{1000000, 0, 0}));
  EXPECT_TRUE(host.step_one_drive(0));
  EXPECT_EQ(drive_times_ns(host), (std::vector<std::uint64_t>{1000000, 1000000, 0}));
  EXPECT_FALSE(host.step_one_drive(0));  // the cycle done, nothing more owed
  EXPECT_EQ(drive_times_ns(host), (std::vector<std::uint64_t>{1000000, 1000000, 1000000}));
  EXPECT_FALSE(host.step_one_drive(0));
  EXPECT_EQ(drive_times_ns(host), (std::vector<std::uint64_t>{1000000, 1000000, 1000000}));
}

TEST(ethercat_host, after_a_stall_each_call_still_steps_one_drive_and_at_most_ten_cycles_are_owed) {
  constexpr int drives = 64;
  ethercat_host host(standard_profile(), drives, cycle_us);
  int calls = 1;
  bool owed = host.step_one_drive(1000000);  // a second without the host: 1,000 cycles passed
  while (owed) {
    std::vector<std::uint64_t> before = drive_times_ns(host);
    owed = host.step_one_drive(0);
    ++calls;
    const std::vector<std::uint64_t> after = drive_times_ns(host);
    int stepped = 0;
    for (std::size_t i = 0; i < after.size(); ++i) stepped += after[i] != before[i] ? 1 : 0;
    ASSERT_EQ(stepped, 1) << "call " << calls;
    ASSERT_LE(calls, drives * 10);
  }
  EXPECT_EQ(calls, drives * 10);
  for (std::uint64_t t : drive_times_ns(host)) EXPECT_EQ(t, 10u * cycle_us * 1000);
}

TEST(ethercat_host, a_frame_between_two_steps_reaches_every_drive_stepped_or_not) {
  ethercat_host host(standard_profile(), 4, cycle_us);
  ASSERT_TRUE(host.step_one_drive(cycle_us));  // drive 1 stepped, 2..4 owed
  // A BRD of the type register: every controller answers (working counter 4).
  std::vector<std::uint8_t> frame{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0, 0, 0, 0, 1, 0x88, 0xA4,
                                  14,   0x10, 7,    0,    0,    0,    0,    0, 2, 0, 0, 0, 0, 0, 0, 0};
  frame.resize(60, 0);
  ASSERT_TRUE(host.pass(frame));
  EXPECT_EQ(frame[28] | (frame[29] << 8), 4);
  EXPECT_EQ(frame[6] & 0x02, 0x02);  // the answer's source marked locally administered
}

// The controllers' clocks run on the host's time, not in the drives' steps: a frame reads the
// system time to the nanosecond, every controller the same time (plus the hops to it), and a
// drive's step moves no clock.
TEST(ethercat_host, a_frame_reads_the_system_time_the_host_clock_gave_to_the_nanosecond) {
  ethercat_host host(standard_profile(), 3, cycle_us);
  const auto system_times = [&] {
    // One APRD of 0x0910 for each position, in one frame.
    std::vector<std::uint8_t> frame{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0, 0, 0, 0, 1, 0x88, 0xA4, 0, 0x10};
    for (int i = 0; i < 3; ++i) {
      const auto adp = static_cast<std::uint16_t>(-i);
      const std::uint8_t more = i < 2 ? 0x80 : 0x00;
      const std::uint8_t header[10] = {1, static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(adp), static_cast<std::uint8_t>(adp >> 8),
                                       0x10, 0x09, 8, more, 0, 0};
      frame.insert(frame.end(), header, header + 10);
      frame.insert(frame.end(), 10, 0);  // 8 data bytes, the working counter
    }
    frame[14] = static_cast<std::uint8_t>(frame.size() - 16);
    EXPECT_TRUE(host.pass(frame));
    std::vector<std::uint64_t> t;
    for (std::size_t i = 0; i < 3; ++i) {
      std::uint64_t v = 0;
      for (int k = 7; k >= 0; --k) v = (v << 8) | frame[16 + i * 20 + 10 + static_cast<std::size_t>(k)];
      t.push_back(v);
    }
    return t;
  };
  host.advance_clocks(1'234);
  const std::vector<std::uint64_t> first = system_times();
  const std::uint64_t hop = first[1] - first[0];
  EXPECT_EQ(first[0], 1'234u);
  EXPECT_EQ(first[2] - first[1], hop) << "one time, seen a hop later at each position";
  host.advance_clocks(7);
  EXPECT_EQ(system_times(), (std::vector<std::uint64_t>{1'241, 1'241 + hop, 1'241 + 2 * hop})) << "7 ns later";
  ASSERT_TRUE(host.step_one_drive(cycle_us));  // drive 1's application: 1 ms of it
  EXPECT_EQ(drive_times_ns(host), (std::vector<std::uint64_t>{1'000'000, 0, 0}));
  EXPECT_EQ(system_times(), (std::vector<std::uint64_t>{1'241, 1'241 + hop, 1'241 + 2 * hop})) << "no clock moved with it";
}

}  // namespace
}  // namespace cia402::apps
