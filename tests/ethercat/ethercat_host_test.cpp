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

std::vector<std::uint64_t> local_times_ns(ethercat_host& host) {
  std::vector<std::uint64_t> t;
  for (auto& d : host.drives()) t.push_back(d->controller().local_time());
  return t;
}

TEST(ethercat_host, no_drive_is_stepped_before_a_whole_cycle_has_passed) {
  ethercat_host host(standard_profile(), 3, cycle_us);
  EXPECT_FALSE(host.step_one_drive(cycle_us - 1));
  EXPECT_EQ(local_times_ns(host), (std::vector<std::uint64_t>{0, 0, 0}));
}

TEST(ethercat_host, a_due_cycle_steps_one_drive_per_call_in_line_order) {
  ethercat_host host(standard_profile(), 3, cycle_us);
  EXPECT_TRUE(host.step_one_drive(cycle_us));
  EXPECT_EQ(local_times_ns(host), (std::vector<std::uint64_t>{1000000, 0, 0}));
  EXPECT_TRUE(host.step_one_drive(0));
  EXPECT_EQ(local_times_ns(host), (std::vector<std::uint64_t>{1000000, 1000000, 0}));
  EXPECT_FALSE(host.step_one_drive(0));  // the cycle done, nothing more owed
  EXPECT_EQ(local_times_ns(host), (std::vector<std::uint64_t>{1000000, 1000000, 1000000}));
  EXPECT_FALSE(host.step_one_drive(0));
  EXPECT_EQ(local_times_ns(host), (std::vector<std::uint64_t>{1000000, 1000000, 1000000}));
}

TEST(ethercat_host, after_a_stall_each_call_still_steps_one_drive_and_at_most_ten_cycles_are_owed) {
  constexpr int drives = 64;
  ethercat_host host(standard_profile(), drives, cycle_us);
  int calls = 1;
  bool owed = host.step_one_drive(1000000);  // a second without the host: 1,000 cycles passed
  while (owed) {
    std::vector<std::uint64_t> before = local_times_ns(host);
    owed = host.step_one_drive(0);
    ++calls;
    const std::vector<std::uint64_t> after = local_times_ns(host);
    int stepped = 0;
    for (std::size_t i = 0; i < after.size(); ++i) stepped += after[i] != before[i] ? 1 : 0;
    ASSERT_EQ(stepped, 1) << "call " << calls;
    ASSERT_LE(calls, drives * 10);
  }
  EXPECT_EQ(calls, drives * 10);
  for (std::uint64_t t : local_times_ns(host)) EXPECT_EQ(t, 10u * cycle_us * 1000);
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

}  // namespace
}  // namespace cia402::apps
