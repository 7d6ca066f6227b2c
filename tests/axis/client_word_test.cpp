// A client's own control word (send_word: the instrument page's buttons and bit toggles) and the
// once-a-cycle hook a client samples the drive with (on_cycle).
#include <gtest/gtest.h>

#include "bench.hpp"
#include "cia402/words.hpp"

namespace cia402::axes::test {
namespace {

result send(bench& b, std::uint16_t word, bool reset_edge = false) {
  return b.finish([&](completion d) { return b.s->send_word(word, reset_edge, std::move(d)); });
}

TEST(client_word, every_bit_goes_as_given_and_the_planner_does_not_steer) {
  bench b;
  // Shutdown with halt and a mode bit: held as it is, READY TO SWITCH ON is not driven further.
  const result r = send(b, 0x0106 | 0x0200);
  ASSERT_TRUE(r.ok()) << r.error;
  b.run_ms(50);
  EXPECT_EQ(b.link.drive.view().control_word(), 0x0306);
  EXPECT_EQ(b.link.drive.view().current(), state::ready_to_switch_on);
  EXPECT_EQ(b.s->control_word(), 0x0306);
}

TEST(client_word, a_word_given_supersedes_the_running_operation) {
  bench b;
  std::optional<result> moving;
  b.s->velocity(1000, [&](const result& r) { moving = r; });
  b.run_ms(30);
  const result r = send(b, 0x0000);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_TRUE(moving);
  EXPECT_EQ(moving->end, outcome::superseded);
}

TEST(client_word, a_reset_edge_takes_a_faulted_drive_out_of_fault_with_bit_7_rising_once) {
  bench b;
  ASSERT_TRUE(b.enable().ok());
  b.link.drive.view().inject_fault(0x2310);
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().current() == state::fault; }, 1000));
  b.link.drive.view().clear_faults();
  const std::size_t before = b.link.words.size();
  const result r = send(b, 0x0000, true);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().current() == state::switch_on_disabled; }, 200));
  int rises = 0;
  std::uint16_t last = before > 0 ? b.link.words[before - 1].second : 0;
  for (std::size_t i = before; i < b.link.words.size(); ++i) {
    const std::uint16_t w = b.link.words[i].second;
    if ((w & control_bit::fault_reset) && !(last & control_bit::fault_reset)) ++rises;
    last = w;
  }
  EXPECT_EQ(rises, 1);
  EXPECT_EQ(b.link.words.back().second, 0x0000) << "bit 7 low again, the word as given";
}

TEST(client_word, a_plain_word_to_a_drive_in_fault_is_sent_not_refused) {
  bench b;
  b.link.drive.view().inject_fault(0x2310);
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().current() == state::fault; }, 1000));
  const result r = send(b, 0x0006);
  EXPECT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(b.link.drive.view().control_word(), 0x0006);
}

TEST(client_word, a_lapsed_lease_stops_a_drive_the_client_enabled_by_its_own_words) {
  session_config c;
  c.lease_us = 100'000;
  bench b(c);
  b.s->renew("page");
  ASSERT_TRUE(send(b, 0x0006).ok());
  ASSERT_TRUE(send(b, 0x000F).ok());
  b.s->renew("page");
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().current() == state::operation_enabled; }, 100));
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().current() != state::operation_enabled; }, 300));
  ASSERT_EQ(b.lapses.size(), 1u);
  EXPECT_NE(b.lapses[0].find("page stopped renewing its lease"), std::string::npos) << b.lapses[0];
}

TEST(client_word, a_lapsed_lease_with_0x6007_written_0_halts_a_drive_the_client_enabled_by_its_words) {
  session_config c;
  c.lease_us = 100'000;
  bench b(c);
  b.s->renew("page");
  // 0x6007 = 0 (no action) written by the client after start-up: the lease uses it, not the code
  // read at start (1 by default, a quick stop).
  ASSERT_TRUE(b.finish([&](completion d) {
                 return b.s->write_object(0x6007, 0, object_value::of_integer(0), std::move(d));
               }).ok());
  EXPECT_EQ(b.s->option_code(option::abort_connection), 0);
  ASSERT_TRUE(send(b, 0x0006).ok());
  ASSERT_TRUE(send(b, 0x000F).ok());
  b.s->renew("page");
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().current() == state::operation_enabled; }, 100));
  ASSERT_TRUE(b.run_until([&] { return !b.lapses.empty(); }, 300));
  b.run_ms(50);
  // A halt (control bit 8) on the client's own word: the drive stays enabled and stops the shaft.
  EXPECT_EQ(b.link.drive.view().current(), state::operation_enabled);
  EXPECT_NE(b.link.drive.view().control_word() & control_bit::halt, 0) << b.lapses[0];
}

TEST(client_word, on_cycle_is_called_once_a_cycle_before_the_outputs_go) {
  bench b;
  int calls = 0;
  std::uint64_t counts_seen = 0;
  b.s->on_cycle = [&] {
    ++calls;
    counts_seen = b.link.status_count();
  };
  b.run_ms(100);
  EXPECT_EQ(calls, 100);
  EXPECT_EQ(counts_seen, 99u) << "the hook sees the inputs of the cycle before";
}

TEST(client_word, output_is_the_set_point_last_put_into_the_cyclic_outputs) {
  bench b;
  EXPECT_FALSE(b.s->output(object_index::target_velocity));
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(700, std::move(d)); }).ok());
  EXPECT_EQ(b.s->output(object_index::target_velocity), 700);
  ASSERT_TRUE(b.finish([&](completion d) {
                 return b.s->write_object(object_index::target_velocity, 0, object_value::of_integer(-20), std::move(d));
               }).ok());
  EXPECT_EQ(b.s->output(object_index::target_velocity), -20);
}

}  // namespace
}  // namespace cia402::axes::test
