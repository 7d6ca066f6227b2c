// The lease: a client that stops renewing gets the drive stopped as 0x6007 says, within the lease
// time plus one cycle of the link; a drive that is not enabled is left alone.
#include <gtest/gtest.h>

#include "bench.hpp"
#include "cia402/words.hpp"

namespace cia402::axes::test {
namespace {

constexpr std::uint64_t lease_us = 100'000;

// The drive turning at 1000 rpm under a client that renews every 10 ms, then goes silent. The time
// from its last renewal to the first control word with `mask` == `value`.
std::optional<std::uint64_t> stop_after_silence(bench& b, std::uint16_t mask, std::uint16_t value) {
  std::optional<result> turning;
  b.s->renew("page tab");
  b.s->velocity(1000, [&](const result& r) { turning = r; });
  for (int i = 0; i < 10000 && !turning; ++i) {
    (void)b.s->poll(1000);
    if (i % 10 == 0) b.s->renew("page tab");
  }
  EXPECT_TRUE(turning && turning->ok());
  b.s->renew("page tab");
  const std::uint64_t silent_from = b.link.now;
  const std::size_t words_before = b.link.words.size();
  b.run_ms(300);
  for (std::size_t i = words_before; i < b.link.words.size(); ++i) {
    if ((b.link.words[i].second & mask) == value) return b.link.words[i].first - silent_from;
  }
  return std::nullopt;
}

session_config with_lease() {
  session_config c;
  c.lease_us = lease_us;
  return c;
}

TEST(lease, lapse_with_0x6007_3_is_a_quick_stop_within_the_lease_and_one_cycle) {
  bench b(with_lease());
  ASSERT_EQ(b.link.drive.write(option_index(option::abort_connection), 0, 3), sdo_abort::none);
  const auto after = stop_after_silence(b, 0x0087, 0x0002);  // Quick stop: bit 2 low, bit 1 high
  ASSERT_TRUE(after) << "no quick stop sent";
  EXPECT_GE(*after, lease_us);
  EXPECT_LE(*after, lease_us + b.link.cycle);
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().velocity_rpm() == 0; }, 5000));
  ASSERT_EQ(b.lapses.size(), 1u);
  EXPECT_NE(b.lapses[0].find("page tab stopped renewing its lease: Quick stop (0x6007 = 3)"), std::string::npos) << b.lapses[0];
}

TEST(lease, lapse_with_0x6007_2_is_disable_voltage) {
  bench b(with_lease());
  ASSERT_EQ(b.link.drive.write(option_index(option::abort_connection), 0, 2), sdo_abort::none);
  const auto after = stop_after_silence(b, 0x0083, 0x0000);  // Disable voltage: bit 1 low
  ASSERT_TRUE(after);
  EXPECT_LE(*after, lease_us + b.link.cycle);
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().current() == state::switch_on_disabled; }, 5000));
}

TEST(lease, lapse_with_0x6007_1_quick_stops_as_a_master_cannot_raise_the_fault) {
  bench b(with_lease());
  ASSERT_EQ(b.link.drive.write(option_index(option::abort_connection), 0, 1), sdo_abort::none);
  const auto after = stop_after_silence(b, 0x0087, 0x0002);
  ASSERT_TRUE(after);
  EXPECT_LE(*after, lease_us + b.link.cycle);
}

TEST(lease, lapse_with_0x6007_0_halts_and_keeps_the_drive_enabled) {
  bench b(with_lease());
  ASSERT_EQ(b.link.drive.write(option_index(option::abort_connection), 0, 0), sdo_abort::none);
  const auto after = stop_after_silence(b, control_bit::halt, control_bit::halt);
  ASSERT_TRUE(after);
  EXPECT_LE(*after, lease_us + b.link.cycle);
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().velocity_rpm() == 0; }, 5000));
  EXPECT_EQ(b.link.drive.view().current(), state::operation_enabled);
}

TEST(lease, a_lapsed_lease_refuses_commands_until_renewed) {
  bench b(with_lease());
  ASSERT_TRUE(stop_after_silence(b, 0x0087, 0x0002));
  const result refused = b.finish([&](completion d) { return b.s->velocity(100, std::move(d)); }, 100);
  EXPECT_NE(refused.error.find("lease lapsed"), std::string::npos) << refused.error;
  b.s->renew("page tab");
  std::optional<result> again;
  b.s->velocity(100, [&](const result& r) { again = r; });
  for (int i = 0; i < 10000 && !again; ++i) {
    (void)b.s->poll(1000);
    if (i % 10 == 0) b.s->renew("page tab");
  }
  EXPECT_TRUE(again && again->ok()) << (again ? again->error : "no end");
}

TEST(lease, a_lapse_leaves_a_drive_that_is_not_enabled_alone) {
  bench b(with_lease());
  b.s->renew("page tab");
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->read_state(std::move(d)); }).ok());
  b.run_ms(300);
  ASSERT_EQ(b.lapses.size(), 1u);
  EXPECT_NE(b.lapses[0].find("nothing to stop"), std::string::npos) << b.lapses[0];
  EXPECT_TRUE(b.link.words.empty());
}

TEST(lease, closing_with_stop_first_stops_an_enabled_drive_then_closes_the_link) {
  bench b;
  ASSERT_EQ(b.link.drive.write(option_index(option::abort_connection), 0, 3), sdo_abort::none);
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(1000, std::move(d)); }).ok());
  b.s->close(true);
  ASSERT_TRUE(b.run_until([&] { return b.s->closed(); }, 10000));
  EXPECT_TRUE(b.link.closed);
  EXPECT_EQ(b.link.drive.view().velocity_rpm(), 0);
}

}  // namespace
}  // namespace cia402::axes::test
