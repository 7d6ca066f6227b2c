// session::offer_set_point: profile position's set-point handshake (control bit 4, status bit 12)
// run by the session on its own cycle, for a client (the instrument page) that offers the set-point
// it wrote to 0x607A without polling the handshake itself.
#include <gtest/gtest.h>

#include "bench.hpp"
#include "cia402/words.hpp"

namespace cia402::axes::test {
namespace {

TEST(set_point_offer, bit_4_rises_until_the_acknowledge_then_falls_and_the_drive_goes_there) {
  bench b;
  ASSERT_TRUE(b.enable().ok());
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->set_mode(mode::profile_position, std::move(d)); }).ok());
  ASSERT_TRUE(b.finish([&](completion d) {
                 return b.s->write_object(object_index::target_position, 0, object_value::of_integer(4000), std::move(d));
               }).ok());
  const std::uint16_t word = b.s->control_word().value_or(0);
  ASSERT_EQ(word & control_bit::new_set_point, 0);
  b.link.words.clear();
  const result r = b.finish([&](completion d) {
    return b.s->offer_set_point(static_cast<std::uint16_t>(word | control_bit::change_set_immediately), std::move(d));
  });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_TRUE(b.sent(control_bit::new_set_point | control_bit::change_set_immediately,
                     control_bit::new_set_point | control_bit::change_set_immediately))
      << "bit 4 offered the set-point, with the word's own bits";
  ASSERT_TRUE(b.s->control_word());
  EXPECT_EQ(*b.s->control_word() & control_bit::new_set_point, 0) << "bit 4 down once acknowledged";
  EXPECT_EQ(r.shown, state::operation_enabled) << "the offer leaves the state as it was";
  b.run_ms(3000);
  EXPECT_EQ(b.link.drive.view().position(), 4000) << "the drive took the set-point";
}

TEST(set_point_offer, an_unacknowledged_offer_fails_after_the_timeout_with_bit_4_down) {
  session_config c;
  c.acknowledge_timeout_us = 50'000;
  bench b(c);
  // In pp but not OPERATION ENABLED: no drive acknowledges a set-point there.
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->set_mode(mode::profile_position, std::move(d)); }).ok());
  ASSERT_NE(b.link.drive.view().current(), state::operation_enabled);
  const result r = b.finish([&](completion d) { return b.s->offer_set_point(0, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {"no set-point acknowledge (status bit 12) within 50 ms"}));
  EXPECT_TRUE(b.sent(control_bit::new_set_point, control_bit::new_set_point));
  ASSERT_TRUE(b.s->control_word());
  EXPECT_EQ(*b.s->control_word() & control_bit::new_set_point, 0) << "bit 4 came down unacknowledged too";
}

TEST(set_point_offer, a_rising_edge_when_bit_4_was_up_already) {
  bench b;
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->send_word(control_bit::new_set_point, false, std::move(d)); }).ok());
  b.link.words.clear();
  (void)b.finish([&](completion d) { return b.s->offer_set_point(control_bit::new_set_point, std::move(d)); });
  ASSERT_GE(b.link.words.size(), 2u);
  EXPECT_EQ(b.link.words.front().second & control_bit::new_set_point, 0) << "down first, for the edge";
}

}  // namespace
}  // namespace cia402::axes::test
