// The SDO server's block transfer (CiA 301 §7.2.4.3) frame by frame over the in-process bus:
// block download and upload with the CRC, a segment lost in a block and sent again, blocks of the
// client's size, the upload's protocol switch threshold, and the abort codes of the block protocol.
// Commands and abort codes are written out as the standard's numbers, not taken from the code.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/301/sdo_client.hpp"
#include "cia402/canopen/301/sdo_server.hpp"
#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "network.hpp"

namespace cia402::canopen::test {
namespace {

constexpr std::uint8_t node_id = 5;

// A frame to the node's SDO server with these 8 bytes.
frame request(std::initializer_list<std::uint8_t> bytes) {
  frame f;
  f.id = cob::sdo_rx + node_id;
  f.len = 8;
  std::size_t i = 0;
  for (const std::uint8_t b : bytes) f.data[i++] = b;
  return f;
}

// Segment `sequence` of `data` (7 bytes from `at`), flagged last when it holds the last byte.
frame segment(std::uint8_t sequence, const std::string& data, std::size_t at) {
  frame f;
  f.id = cob::sdo_rx + node_id;
  f.len = 8;
  const bool last = at + 7 >= data.size();
  f.data[0] = static_cast<std::uint8_t>(sequence | (last ? 0x80 : 0));
  for (std::size_t k = 0; k < 7 && at + k < data.size(); ++k) f.data[1 + k] = static_cast<std::uint8_t>(data[at + k]);
  return f;
}

class sdo_block_test : public ::testing::Test {
 protected:
  void SetUp() override { net.add(node_id); }

  // Sends the frames; the server's answers to them.
  std::vector<frame> send(const std::vector<frame>& frames) {
    net.received.clear();
    for (const frame& f : frames) {
      net.send(f);
      net.settle();
    }
    return net.with_id(cob::sdo_tx + node_id);
  }
  std::string upload_text(std::uint16_t index, std::uint8_t sub) {
    frame stale;
    while (client_channel->receive(stale)) {
    }  // what the server said to the frames above is not the client's
    client.clear();
    client.start_upload(index, sub);
    for (int i = 0; i < 200 && !client.finished(); ++i) {
      net.settle();
      frame f;
      while (client_channel->receive(f)) client.on_frame(f);
    }
    return std::string(client.data().begin(), client.data().end());
  }
  std::uint16_t crc_of(const std::string& s) {
    return sdo_block_crc(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
  }

  network net;
  std::unique_ptr<virtual_channel> client_channel = net.bus().attach();
  sdo_client client{*client_channel, node_id};
};

TEST(sdo_block_crc, is_crc_16_ccitt_with_the_check_value_of_its_catalogue) {
  // CRC-16/XMODEM (poly 0x1021, init 0, no reflection, no final XOR): check value of "123456789".
  const std::string check = "123456789";
  EXPECT_EQ(sdo_block_crc(std::span(reinterpret_cast<const std::uint8_t*>(check.data()), check.size())), 0x31C3);
  EXPECT_EQ(sdo_block_crc({}), 0x0000);
}

TEST_F(sdo_block_test, a_block_download_with_the_crc_stores_the_value) {
  const std::string text = "a string of thirty-one letters.";  // 31 bytes: 5 segments, 4 unused in the last
  ASSERT_EQ(text.size(), 31u);
  // Initiate: 110 00 cc=1 s=1 0, the size.
  std::vector<frame> a = send({request({0xC6, 0x00, 0x20, 0x00, 31, 0, 0, 0})});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0xA4) << "101 00 sc=1 0 0: the server's CRC too";
  EXPECT_EQ(a[0].data[1], 0x00);
  EXPECT_EQ(a[0].data[2], 0x20);
  const std::uint8_t block = a[0].data[4];
  EXPECT_GE(block, 5);
  EXPECT_LE(block, 127);
  std::vector<frame> segments;
  for (std::uint8_t s = 1; s <= 5; ++s) segments.push_back(segment(s, text, (s - 1) * 7u));
  a = send(segments);
  ASSERT_EQ(a.size(), 1u) << "one answer, after the block's last segment";
  EXPECT_EQ(a[0].data[0], 0xA2);
  EXPECT_EQ(a[0].data[1], 5) << "acknowledged up to segment 5";
  // End: 110 n=4 0 1, the CRC.
  const std::uint16_t crc = crc_of(text);
  a = send({request({static_cast<std::uint8_t>(0xC1 | (4 << 2)), static_cast<std::uint8_t>(crc), static_cast<std::uint8_t>(crc >> 8), 0, 0, 0, 0, 0})});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0xA1);
  EXPECT_EQ(upload_text(0x2000, 0), text);
}

TEST_F(sdo_block_test, a_wrong_crc_aborts_with_0x05040004_and_stores_nothing) {
  // 0x2000 holds "before" (an expedited download of 6 bytes is not possible: segmented by the client).
  client.start_download(0x2000, 0, std::vector<std::uint8_t>{'b', 'e', 'f', 'o', 'r', 'e'}, true);
  for (int i = 0; i < 50 && !client.finished(); ++i) {
    net.settle();
    frame f;
    while (client_channel->receive(f)) client.on_frame(f);
  }
  const std::string before = upload_text(0x2000, 0);
  ASSERT_EQ(before, "before");
  const std::string text = "fourteen bytes";
  send({request({0xC6, 0x00, 0x20, 0x00, 14, 0, 0, 0})});
  send({segment(1, text, 0), segment(2, text, 7)});
  const std::uint16_t wrong = static_cast<std::uint16_t>(crc_of(text) ^ 0x0100);
  const std::vector<frame> a = send({request({0xC1, static_cast<std::uint8_t>(wrong), static_cast<std::uint8_t>(wrong >> 8), 0, 0, 0, 0, 0})});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(abort_code_of(a[0]), 0x05040004u);
  EXPECT_EQ(upload_text(0x2000, 0), before);
}

TEST_F(sdo_block_test, a_segment_lost_in_a_block_is_acknowledged_before_it_and_taken_when_sent_again) {
  const std::string text = "twenty-one bytes here";
  ASSERT_EQ(text.size(), 21u);
  send({request({0xC2, 0x00, 0x20, 0x00, 21, 0, 0, 0})});  // no CRC from this client
  // Segment 2 is lost: 1 and 3 (the last) arrive.
  std::vector<frame> a = send({segment(1, text, 0), segment(3, text, 14)});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0xA2);
  EXPECT_EQ(a[0].data[1], 1) << "only segment 1 in order";
  // The client goes on from the second segment, in a new block counted from 1.
  a = send({segment(1, text, 7), segment(2, text, 14)});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[1], 2);
  a = send({request({0xC1, 0, 0, 0, 0, 0, 0, 0})});  // n = 0, no CRC used
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0xA1);
  EXPECT_EQ(upload_text(0x2000, 0), text);
}

TEST_F(sdo_block_test, a_block_upload_in_blocks_of_the_clients_size_ends_with_the_crc) {
  const std::string name = "cia402 virtual drive";  // 0x1008: 20 bytes, 3 segments
  // Initiate: 101 00 cc=1 00, block size 2, no protocol switch.
  std::vector<frame> a = send({request({0xA4, 0x08, 0x10, 0x00, 2, 0, 0, 0})});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0xC6) << "110 00 sc=1 s=1 0";
  EXPECT_EQ(get_le(&a[0].data[4], 4), 20u);
  a = send({request({0xA3, 0, 0, 0, 0, 0, 0, 0})});  // start
  ASSERT_EQ(a.size(), 2u) << "a block of two segments";
  EXPECT_EQ(a[0].data[0], 0x01);
  EXPECT_EQ(a[1].data[0], 0x02);
  std::string got;
  for (const frame& f : a) got.append(f.data.begin() + 1, f.data.begin() + 8);
  a = send({request({0xA2, 2, 2, 0, 0, 0, 0, 0})});  // both received; next block of 2
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0x81) << "segment 1 of the next block, the last";
  got.append(a[0].data.begin() + 1, a[0].data.begin() + 8);
  a = send({request({0xA2, 1, 2, 0, 0, 0, 0, 0})});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0xC1 | (1 << 2)) << "end: 1 byte of the last segment unused";
  got.resize(got.size() - 1);
  EXPECT_EQ(got, name);
  EXPECT_EQ(get_le(&a[0].data[1], 2), crc_of(name));
  EXPECT_TRUE(send({request({0xA1, 0, 0, 0, 0, 0, 0, 0})}).empty()) << "the end response is not answered";
  EXPECT_EQ(send({request({0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0})})[0].data[0], 0x43) << "the server is free again";
}

TEST_F(sdo_block_test, an_upload_block_acknowledged_short_is_sent_again_from_the_first_segment_missed) {
  send({request({0xA0, 0x08, 0x10, 0x00, 3, 0, 0, 0})});  // no CRC, blocks of 3
  std::vector<frame> a = send({request({0xA3, 0, 0, 0, 0, 0, 0, 0})});
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[2].data[0], 0x83);
  a = send({request({0xA2, 1, 3, 0, 0, 0, 0, 0})});  // segments 2 and 3 lost
  ASSERT_EQ(a.size(), 2u) << "the rest again: what was segment 2 and 3";
  EXPECT_EQ(a[0].data[0], 0x01);
  EXPECT_EQ(a[1].data[0], 0x82);
  EXPECT_EQ(std::string(a[0].data.begin() + 1, a[0].data.begin() + 8), "virtual");
  a = send({request({0xA2, 2, 3, 0, 0, 0, 0, 0})});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0xC1 | (1 << 2));
  EXPECT_EQ(get_le(&a[0].data[1], 2), 0u) << "no CRC asked for";
}

TEST_F(sdo_block_test, a_value_within_the_protocol_switch_threshold_goes_as_an_ordinary_upload) {
  std::vector<frame> a = send({request({0xA4, 0x08, 0x10, 0x00, 127, 21, 0, 0})});  // 20 bytes <= 21
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0x41) << "segmented: initiate upload response, size indicated";
  EXPECT_EQ(get_le(&a[0].data[4], 4), 20u);
  a = send({request({0xA4, 0x00, 0x10, 0x00, 127, 4, 0, 0})});  // 0x1000, 4 bytes
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0x43) << "expedited";
  EXPECT_EQ(get_le(&a[0].data[4], 4), 0x00020192u);
}

TEST_F(sdo_block_test, the_block_protocols_own_errors_abort_with_their_codes) {
  EXPECT_EQ(abort_code_of(send({request({0xA0, 0x08, 0x10, 0x00, 0, 0, 0, 0})})[0]), 0x05040002u) << "block size 0";
  EXPECT_EQ(abort_code_of(send({request({0xA0, 0x08, 0x10, 0x00, 128, 0, 0, 0})})[0]), 0x05040002u) << "block size 128";
  send({request({0xA0, 0x08, 0x10, 0x00, 2, 0, 0, 0}), request({0xA3, 0, 0, 0, 0, 0, 0, 0})});
  EXPECT_EQ(abort_code_of(send({request({0xA2, 3, 2, 0, 0, 0, 0, 0})})[0]), 0x05040003u) << "acknowledges a segment never sent";
  send({request({0xC2, 0x00, 0x20, 0x00, 14, 0, 0, 0})});
  EXPECT_EQ(abort_code_of(send({request({0x00, 1, 2, 3, 4, 5, 6, 7})})[0]), 0x05040003u) << "sequence number 0";
  EXPECT_EQ(abort_code_of(send({request({0xA3, 0, 0, 0, 0, 0, 0, 0})})[0]), 0x05040001u) << "a start with no upload open";
  EXPECT_EQ(abort_code_of(send({request({0xC1, 0, 0, 0, 0, 0, 0, 0})})[0]), 0x05040001u) << "an end with no download open";
  EXPECT_EQ(abort_code_of(send({request({0xC6, 0x08, 0x10, 0x00, 4, 0, 0, 0})})[0]), 0x06010002u) << "0x1008 is read-only";
}

TEST_F(sdo_block_test, a_client_abort_ends_a_block_download_and_the_next_request_is_a_command_again) {
  send({request({0xC2, 0x00, 0x20, 0x00, 14, 0, 0, 0})});
  EXPECT_TRUE(send({request({0x80, 0x00, 0x20, 0x00, 0, 0, 0, 0x08})}).empty());
  const std::vector<frame> a = send({request({0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0})});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].data[0], 0x43);
}

// Our own client's block transfers against the server: the whole value both ways, the CRC checked.
TEST_F(sdo_block_test, our_client_reads_and_writes_by_block_transfer) {
  const auto run = [&] {
    for (int i = 0; i < 400 && !client.finished(); ++i) {
      net.settle();
      frame f;
      while (client_channel->receive(f)) client.on_frame(f);
    }
  };
  std::string text(64, ' ');
  for (std::size_t i = 0; i < text.size(); ++i) text[i] = static_cast<char>('A' + i % 26);
  ASSERT_TRUE(client.start_block_download(0x2000, 0, std::vector<std::uint8_t>(text.begin(), text.end())));
  run();
  ASSERT_EQ(client.state(), sdo_client::status::done) << std::hex << static_cast<std::uint32_t>(client.abort_code());
  client.clear();
  ASSERT_TRUE(client.start_block_upload(0x2000, 0));
  run();
  ASSERT_EQ(client.state(), sdo_client::status::done) << std::hex << static_cast<std::uint32_t>(client.abort_code());
  EXPECT_EQ(std::string(client.data().begin(), client.data().end()), text);
  EXPECT_FALSE(client.server_refuses_blocks());
  // Within the switch threshold the server answers the ordinary way, and the client follows it.
  client.clear();
  ASSERT_TRUE(client.start_block_upload(0x1008, 0, 21));
  run();
  ASSERT_EQ(client.state(), sdo_client::status::done);
  EXPECT_EQ(std::string(client.data().begin(), client.data().end()), "cia402 virtual drive");
  client.clear();
  ASSERT_TRUE(client.start_block_upload(0x1000, 0, 4));
  run();
  ASSERT_EQ(client.state(), sdo_client::status::done);
  EXPECT_EQ(client.value(), 0x00020192);
}

// A server without block transfer refuses it with 0x05040001: the client asks again the ordinary
// way at once, and from then on does not ask for blocks.
TEST(sdo_client_block, a_server_that_refuses_blocks_is_asked_the_ordinary_way) {
  virtual_bus bus;
  auto client_side = bus.attach();
  auto server_side = bus.attach();
  sdo_client c(*client_side, node_id);
  ASSERT_TRUE(c.start_block_upload(0x1008, 0));
  frame f;
  ASSERT_TRUE(server_side->receive(f));
  EXPECT_EQ(f.data[0], 0xA4);
  frame refusal;
  refusal.id = cob::sdo_tx + node_id;
  refusal.len = 8;
  refusal.data = {0x80, 0x08, 0x10, 0x00, 0x01, 0x00, 0x04, 0x05};  // 0x05040001
  EXPECT_TRUE(c.on_frame(refusal));
  EXPECT_EQ(c.state(), sdo_client::status::busy) << "not aborted: asked again";
  ASSERT_TRUE(server_side->receive(f));
  EXPECT_EQ(f.data[0], 0x40) << "an ordinary initiate upload";
  EXPECT_TRUE(c.server_refuses_blocks());
  c.cancel();
  while (server_side->receive(f)) {
  }
  c.clear();
  ASSERT_TRUE(c.start_block_download(0x2000, 0, std::vector<std::uint8_t>(40, 'x')));
  ASSERT_TRUE(server_side->receive(f));
  EXPECT_EQ(f.data[0], 0x21) << "segmented download, size indicated, not a block initiate";
}

// The link a session talks through uses block transfer for a long value: a download by its length,
// an upload by what the entry holds (0x2000, up to 64 characters), and not for a short one.
TEST(can_link_block, a_long_value_goes_by_block_transfer_and_a_short_one_does_not) {
  virtual_bus bus;
  apps::virtual_drive_node drive{standard_profile(), bus.attach(), apps::drive_node_config(2)};
  auto master_side = bus.attach();
  auto tap = bus.attach();
  for (int i = 0; i < 10; ++i) drive.poll(1000);
  can_link_config c;
  c.node_id = 2;
  c.drive_profile = &standard_profile();
  c.known_objects = node_objects(apps::drive_node_config(2));
  can_link link(*master_side, c);
  const auto first_request = [&](auto start) {
    frame f;
    while (tap->receive(f)) {
    }
    std::optional<axes::transfer_result> result;
    EXPECT_TRUE(start([&](const axes::transfer_result& r) { result = r; }));
    std::optional<std::uint8_t> first;
    for (int i = 0; i < 2000 && !result; ++i) {
      (void)link.poll(100);
      drive.poll(100);
      while (tap->receive(f)) {
        if (!first && f.id == cob::sdo_rx + 2) first = f.data[0];
      }
    }
    EXPECT_TRUE(result && result->ok) << (result ? result->error : "no result");
    return std::make_pair(first.value_or(0), result ? result->data : std::vector<std::uint8_t>{});
  };
  // The device name first, as every link reads it: 20 bytes, the ordinary upload.
  auto [name_command, name] = first_request([&](axes::transfer_done d) { return link.upload(0x1008, 0, std::move(d)); });
  EXPECT_EQ(name_command, 0x40);
  EXPECT_EQ(std::string(name.begin(), name.end()), "cia402 virtual drive");
  const std::string label = "a device label longer than twenty-nine bytes";
  auto [down_command, unused] = first_request([&](axes::transfer_done d) {
    return link.download(0x2000, 0, std::vector<std::uint8_t>(label.begin(), label.end()), std::move(d));
  });
  EXPECT_EQ(down_command, 0xC6) << "block download initiate";
  auto [up_command, back] = first_request([&](axes::transfer_done d) { return link.upload(0x2000, 0, std::move(d)); });
  EXPECT_EQ(up_command, 0xA4) << "block upload initiate";
  EXPECT_EQ(std::string(back.begin(), back.end()), label);
  auto [short_command, small] = first_request([&](axes::transfer_done d) { return link.download(0x2000, 0, {'s', 'h', 'o', 'r', 't'}, std::move(d)); });
  EXPECT_EQ(short_command, 0x21) << "5 bytes: segmented";
}

}  // namespace
}  // namespace cia402::canopen::test
