// The in-process bus: every other channel gets every frame, in send order; nobody hears itself;
// acceptance filters and overruns behave like a CAN controller's.
#include <gtest/gtest.h>

#include "cia402/canopen/transport/virtual_bus.hpp"

namespace cia402::canopen {
namespace {

TEST(virtual_bus, frame_reaches_every_other_channel_in_send_order_but_not_its_sender) {
  virtual_bus bus;
  auto a = bus.attach();
  auto b = bus.attach();
  auto c = bus.attach();
  ASSERT_FALSE(a->send(make_frame(0x181, {1})));
  ASSERT_FALSE(b->send(make_frame(0x182, {2})));
  frame f;
  ASSERT_TRUE(c->receive(f));
  EXPECT_EQ(f.id, 0x181u);
  ASSERT_TRUE(c->receive(f));
  EXPECT_EQ(f.id, 0x182u);
  EXPECT_FALSE(c->receive(f));
  ASSERT_TRUE(a->receive(f));
  EXPECT_EQ(f.id, 0x182u);
  EXPECT_FALSE(a->receive(f));
  ASSERT_TRUE(b->receive(f));
  EXPECT_EQ(f.id, 0x181u);
  EXPECT_FALSE(b->receive(f));
  EXPECT_EQ(bus.frames(), 2u);
}

TEST(virtual_bus, acceptance_filter_drops_identifiers_it_does_not_take) {
  virtual_bus bus;
  auto a = bus.attach();
  auto b = bus.attach();
  b->accept_none();
  b->accept(0x080);
  a->send(make_frame(0x181, {}));
  a->send(make_frame(0x080, {}));
  frame f;
  ASSERT_TRUE(b->receive(f));
  EXPECT_EQ(f.id, 0x080u);
  EXPECT_FALSE(b->receive(f));
}

TEST(virtual_bus, full_queue_drops_new_frames_and_counts_overruns) {
  virtual_bus bus(2);
  auto a = bus.attach();
  auto b = bus.attach();
  for (std::uint8_t i = 0; i < 5; ++i) a->send(make_frame(0x100 + i, {i}));
  EXPECT_EQ(b->pending(), 2u);
  EXPECT_EQ(b->overruns(), 3u);
  frame f;
  ASSERT_TRUE(b->receive(f));
  EXPECT_EQ(f.id, 0x100u);
}

TEST(virtual_bus, bad_frames_are_refused_without_reaching_the_bus) {
  virtual_bus bus;
  auto a = bus.attach();
  auto b = bus.attach();
  frame too_long = make_frame(0x100, {});
  too_long.len = 9;
  EXPECT_TRUE(a->send(too_long));
  EXPECT_TRUE(a->send(make_frame(0x800, {})));  // 12 bits without the extended flag
  EXPECT_EQ(b->pending(), 0u);
  EXPECT_EQ(bus.frames(), 0u);
}

TEST(virtual_bus, detached_channel_no_longer_receives_and_orphans_refuse_to_send) {
  auto bus = std::make_unique<virtual_bus>();
  auto a = bus->attach();
  {
    auto b = bus->attach();
    EXPECT_EQ(bus->channels(), 2u);
  }
  EXPECT_EQ(bus->channels(), 1u);
  EXPECT_FALSE(a->send(make_frame(0x100, {})));
  bus.reset();
  EXPECT_EQ(a->send(make_frame(0x100, {})), std::make_error_code(std::errc::not_connected));
}

}  // namespace
}  // namespace cia402::canopen
