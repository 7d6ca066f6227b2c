// Mailbox repeat (ETG.1000.4 sync manager; ET1100 datasheet 0x0806 / 0x0807): a master that lost a
// reply toggles the repeat request of SM1's activate register; the controller keeps the mailbox as
// it is and shows the request, the slave puts the reply the master read last back and toggles the
// repeat acknowledge. As SOEM's ecx_mbxreceive does it: one FPWR of 0x080D..0x080E, then 0x080F
// read until its bit 1 follows, then SM1 read again.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "drive_bench.hpp"

namespace cia402::ethercat {
namespace {

using testing::bench;

constexpr std::uint16_t sm1 = reg::sync_manager0 + 8;
constexpr std::uint16_t sm1_status = sm1 + reg::sm_status;
constexpr std::uint16_t sm1_activate = sm1 + reg::sm_activate;
constexpr std::uint16_t sm1_pdi_control = sm1 + reg::sm_pdi_control;

std::vector<std::uint8_t> read_sm1(bench& b) {
  const bench::answer a = b.send(command::fprd, b.fp(mailbox_in_start), std::vector<std::uint8_t>(mailbox_size, 0));
  EXPECT_EQ(a.wkc, 1) << "SM1 holds a reply";
  return a.data;
}

// SOEM's repeat request: the status and activate bytes written back with bit 1 of activate toggled.
void toggle_repeat_request(bench& b) {
  const std::uint16_t status_activate = b.read16(sm1_status);
  b.write16(sm1_status, static_cast<std::uint16_t>(status_activate ^ 0x0200));
}

std::vector<std::uint8_t> upload_request(std::uint16_t index, std::uint8_t sub) {
  return {0x40, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub, 0, 0, 0, 0};
}

TEST(esc_mailbox_repeat, a_toggled_repeat_request_keeps_the_mailbox_and_waits_for_the_acknowledge) {
  slave_description d;
  esc e(sii_image(d));
  chain wire;
  wire.add(e);
  const auto send = [&](command c, std::uint16_t offset, std::vector<std::uint8_t> data) {
    frame_builder fb({0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}, {0x02, 0, 0, 0, 0, 1});
    const long at = fb.add(c, 0, static_cast<std::uint32_t>(offset) << 16, data, static_cast<std::uint16_t>(data.size()));
    std::vector<std::uint8_t> f = fb.finish();
    EXPECT_EQ(wire.pass(f), frame_error::none);
    return std::vector<std::uint8_t>(f.begin() + at, f.begin() + at + static_cast<long>(data.size()));
  };
  // SM1: 0x1080, 16 bytes, mailbox the slave writes, activated.
  send(command::apwr, sm1, {0x80, 0x10, 16, 0, 0x22, 0, 1, 0});
  const std::vector<std::uint8_t> reply(16, 0x5A);
  ASSERT_TRUE(e.write_mailbox(1, reply));
  send(command::apwr, sm1_status, {0, 0x03});  // status (read-only) and activate with the repeat bit
  EXPECT_TRUE(e.sm(1).enabled);
  EXPECT_TRUE(e.mailbox_full(1)) << "the waiting reply is not discarded";
  EXPECT_EQ(send(command::aprd, sm1_status, {0})[0] & 0x08, 0x08) << "status: mailbox full";
  EXPECT_TRUE(e.repeat_requested(1));
  EXPECT_EQ(e.read8(reg::al_event_request) & 0x10, 0x10) << "0x0220 bit 4: SM activation written";
  EXPECT_EQ(send(command::aprd, sm1_pdi_control, {0})[0] & 0x02, 0) << "not acknowledged yet";
  e.acknowledge_repeat(1);
  EXPECT_FALSE(e.repeat_requested(1));
  EXPECT_EQ(send(command::aprd, sm1_pdi_control, {0})[0] & 0x02, 0x02) << "the acknowledge follows the request";
  EXPECT_EQ(e.read8(reg::al_event_request) & 0x10, 0);
  EXPECT_EQ(send(command::aprd, 0x1080, std::vector<std::uint8_t>(16, 0)), reply);
  // The enable bit still resets: deactivated and activated again, the mailbox is empty.
  ASSERT_TRUE(e.write_mailbox(1, reply));
  send(command::apwr, sm1_activate, {0x02});
  send(command::apwr, sm1_activate, {0x03});
  EXPECT_FALSE(e.mailbox_full(1));
}

TEST(drive_slave_mailbox_repeat, a_lost_reply_is_read_again_after_a_repeat_request) {
  bench b;
  b.to_pre_op();
  b.drain_mailbox();
  const std::vector<std::uint8_t> lost = b.sdo(upload_request(0x1018, 1));  // read, then lost on the way
  EXPECT_EQ(lost[8] & 0xE0, 0x40) << "an upload response";
  const std::uint8_t ack_before = static_cast<std::uint8_t>(b.read16(sm1_pdi_control) & 0x02);
  toggle_repeat_request(b);
  b.run(1);
  EXPECT_EQ(b.read16(sm1_pdi_control) & 0x02, ack_before ^ 0x02) << "the repeat acknowledge toggled";
  EXPECT_EQ(b.read16(reg::al_status), 2) << "still PRE-OP, no error";
  EXPECT_EQ(read_sm1(b), lost) << "the same reply, counter and all";
  // The next request is answered as usual.
  EXPECT_EQ(b.upload(0x1018, 1), lost[12] | (lost[13] << 8) | (lost[14] << 16) | (static_cast<std::int64_t>(lost[15]) << 24));
}

TEST(drive_slave_mailbox_repeat, a_reply_waiting_unread_goes_out_after_the_repeated_one) {
  // SOEM's case: an SDO read right after a fault injection. The emergency is in SM1 when the master
  // asks for the reply it lost; it gets that reply first, then the emergency.
  bench b;
  b.to_pre_op();
  b.drain_mailbox();
  const std::vector<std::uint8_t> lost = b.sdo({0x2B, 0x01, 0x20, 0, 0x00, 0x75, 0, 0});  // 0x2001 = 0x7500
  EXPECT_EQ(lost[8], 0x60) << "download response";
  b.run(3);
  EXPECT_EQ(b.read16(sm1_status) & 0x08, 0x08) << "the emergency waits in SM1";
  toggle_repeat_request(b);
  b.run(1);
  EXPECT_EQ(read_sm1(b), lost);
  b.run(1);
  const std::vector<std::uint8_t> next = read_sm1(b);
  EXPECT_EQ(next[5] & 0x0F, 0x03) << "CoE";
  EXPECT_EQ(next[7] >> 4, 1) << "emergency";
  EXPECT_EQ(next[8] | (next[9] << 8), 0x7500);
}

// SOEM 1.4.0 takes every emergency it reads for a lost mailbox (ecx_mbxreceive sets its working
// counter to 0) and toggles the repeat request right after. An SDO read right after a fault
// injection: the emergency is in SM1, the upload's reply is made behind it. Before, each repeat put
// the emergency back, the reply never left and SOEM's read failed after its 700 ms, whenever the
// slave saw the read and the repeat request in one cycle. As SOES does, once the repeated reply is
// read the one waiting behind it goes out and is what a further repeat request puts back.
TEST(drive_slave_mailbox_repeat, a_master_that_asks_for_a_repeat_after_every_emergency_gets_its_reply) {
  bench b;
  b.to_pre_op();
  b.drain_mailbox();
  EXPECT_EQ(b.sdo({0x2B, 0x01, 0x20, 0, 0x00, 0x75, 0, 0})[8], 0x60) << "0x2001 = 0x7500 downloaded";
  b.run(3);
  ASSERT_EQ(b.read16(sm1_status) & 0x08, 0x08) << "the emergency waits in SM1";
  // The upload of 0x603F written, not yet answered.
  std::vector<std::uint8_t> m(mailbox_size, 0);
  m[0] = 10;                                      // length
  m[5] = 0x03 | static_cast<std::uint8_t>(5 << 4);  // CoE, counter 5
  m[7] = 0x20;                                    // SDO request
  const std::vector<std::uint8_t> body = upload_request(0x603F, 0);
  std::copy(body.begin(), body.end(), m.begin() + 8);
  ASSERT_EQ(b.send(command::fpwr, b.fp(mailbox_out_start), m).wkc, 1);
  int emergencies = 0;
  std::vector<std::uint8_t> reply;
  for (int round = 0; round < 20 && reply.empty(); ++round) {
    b.run(1);
    if ((b.read16(sm1_status) & 0x08) == 0) continue;
    const std::vector<std::uint8_t> got = read_sm1(b);
    if ((got[5] & 0x0F) == 0x03 && (got[7] >> 4) == 1) {  // an emergency: SOEM asks for a repeat at once
      ++emergencies;
      toggle_repeat_request(b);
      continue;
    }
    reply = got;
  }
  ASSERT_FALSE(reply.empty()) << "the upload's reply never came, " << emergencies << " emergencies read";
  EXPECT_EQ(reply[7] >> 4, 3) << "SDO response";
  EXPECT_EQ(reply[8], 0x4B) << "expedited upload of 2 bytes";
  EXPECT_EQ(reply[9] | (reply[10] << 8), 0x603F);
  EXPECT_EQ(reply[12] | (reply[13] << 8), 0x7500);
  EXPECT_LE(emergencies, 2) << "the emergency, and once more for the repeat";
}

}  // namespace
}  // namespace cia402::ethercat
