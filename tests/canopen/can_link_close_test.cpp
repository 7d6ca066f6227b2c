// can_link's close before the cyclic stage (issue 42): every transfer queued, the one under way
// too, ends at the close, cancelled with a reason, so a request waiting for one does not wait for
// ever. On the in-process bus with a virtual drive, in virtual time.
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"

namespace cia402::canopen {
namespace {

struct bench {
  virtual_bus bus;
  apps::virtual_drive_node drive{standard_profile(), bus.attach(), apps::drive_node_config(2)};
  std::unique_ptr<virtual_channel> master_ch = bus.attach();
  std::unique_ptr<can_link> link;

  bench() {
    for (int i = 0; i < 10; ++i) drive.poll(1000);  // past power-up
    frame f;
    while (master_ch->receive(f)) {}  // the boot-up message
    can_link_config c;
    c.node_id = 2;
    c.drive_profile = &standard_profile();
    link = std::make_unique<can_link>(*master_ch, c);
  }
};

struct ended {
  int calls = 0;
  std::optional<axes::transfer_result> result;
  axes::transfer_done done() {
    return [this](const axes::transfer_result& r) {
      ++calls;
      result = r;
    };
  }
};

TEST(can_link_close, before_the_cyclic_stage_every_queued_transfer_ends_cancelled_with_a_reason) {
  bench b;
  ended under_way, queued;
  ASSERT_TRUE(b.link->upload(0x1008, 0, under_way.done()));
  ASSERT_TRUE(b.link->download(0x1017, 0, {100, 0}, queued.done()));
  (void)b.link->poll(0);  // the first one goes out; the node has not answered yet
  b.link->close();
  for (ended* e : {&under_way, &queued}) {
    ASSERT_EQ(e->calls, 1) << "a transfer dropped at the close never ends";
    EXPECT_TRUE(e->result->cancelled);
    EXPECT_FALSE(e->result->ok);
    EXPECT_NE(e->result->error.find("node 2: the link was closed"), std::string::npos) << e->result->error;
  }
  EXPECT_TRUE(b.link->closing().done);
  // The node's late answer changes nothing, and nothing ends twice.
  b.drive.poll(0);
  (void)b.link->poll(1000);
  EXPECT_EQ(under_way.calls, 1);
  EXPECT_EQ(queued.calls, 1);
}

TEST(can_link_close, a_close_while_recording_ends_the_transfers_queued_before_start_cyclic) {
  bench b;
  ended first, second;
  ASSERT_TRUE(b.link->upload(0x1000, 0, first.done()));
  ASSERT_TRUE(b.link->upload(0x1018, 1, second.done()));
  b.link->start_cyclic();  // the recording reads queue behind them
  (void)b.link->poll(0);
  b.link->close();
  EXPECT_EQ(first.calls, 1);
  EXPECT_EQ(second.calls, 1);
  ASSERT_TRUE(second.result);
  EXPECT_TRUE(second.result->cancelled);
  EXPECT_TRUE(b.link->closing().done);
  EXPECT_TRUE(b.link->closing().restored.empty()) << "nothing was set up, nothing put back";
}

TEST(can_link_close, a_transfer_that_ended_before_the_close_keeps_its_result) {
  bench b;
  ended read;
  ASSERT_TRUE(b.link->upload(0x1008, 0, read.done()));
  for (int i = 0; i < 20 && read.calls == 0; ++i) {
    (void)b.link->poll(1000);
    b.drive.poll(0);
  }
  ASSERT_EQ(read.calls, 1);
  EXPECT_TRUE(read.result->ok);
  b.link->close();
  EXPECT_EQ(read.calls, 1);
}

}  // namespace
}  // namespace cia402::canopen
