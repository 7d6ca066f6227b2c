// The SDO server over the in-process bus: expedited and segmented transfers in both directions, and
// the abort code CiA 301 §7.2.4.3.17 names for every bad request. Abort codes are written out as the
// standard's numbers, not taken from the enum under test.
#include <gtest/gtest.h>

#include <string>

#include "cia402/canopen/301/sdo_client.hpp"
#include "network.hpp"

namespace cia402::canopen::test {
namespace {

using namespace cia402::dictionary;

constexpr std::uint8_t node_id = 5;

class sdo_server_test : public ::testing::Test {
 protected:
  void SetUp() override { net.add(node_id); }

  // One raw request; the server's one answer.
  frame ask(const frame& request) {
    net.received.clear();
    net.send(request);
    net.settle();
    const auto answers = net.with_id(cob::sdo_tx + node_id);
    EXPECT_EQ(answers.size(), 1u);
    return answers.empty() ? frame{} : answers.back();
  }
  std::uint32_t abort_of(const frame& request) { return abort_code_of(ask(request)); }

  // A whole transfer by the client; returns the client when it has finished.
  sdo_client& transfer() {
    for (int i = 0; i < 200 && !client.finished(); ++i) {
      net.settle();
      frame f;
      while (client_channel->receive(f)) client.on_frame(f);
    }
    net.received.clear();
    return client;
  }
  std::string upload_text(std::uint16_t index, std::uint8_t sub) {
    client.clear();
    client.start_upload(index, sub);
    transfer();
    EXPECT_EQ(client.state(), sdo_client::status::done) << std::hex << static_cast<unsigned>(client.abort_code());
    return std::string(client.data().begin(), client.data().end());
  }
  std::uint32_t download_text(std::uint16_t index, std::uint8_t sub, const std::string& text,
                              bool segmented = true) {
    client.clear();
    client.start_download(index, sub, std::vector<std::uint8_t>(text.begin(), text.end()), segmented);
    transfer();
    return client.state() == sdo_client::status::done ? 0u : static_cast<std::uint32_t>(client.abort_code());
  }

  network net;
  std::unique_ptr<virtual_channel> client_channel = net.bus().attach();
  sdo_client client{*client_channel, node_id};
};

TEST_F(sdo_server_test, expedited_upload_of_device_type_returns_0x00020192_in_four_bytes) {
  const frame r = ask(sdo_request(node_id, 0x40, 0x1000, 0));
  EXPECT_EQ(r.data[0], 0x43);  // scs 2, expedited, size indicated, n = 0
  EXPECT_EQ(get_le(&r.data[4], 4), 0x00020192u);
  EXPECT_EQ(r.data[1], 0x00);
  EXPECT_EQ(r.data[2], 0x10);
}

TEST_F(sdo_server_test, expedited_upload_of_one_byte_object_says_three_bytes_unused) {
  const frame r = ask(sdo_request(node_id, 0x40, 0x1018, 0));
  EXPECT_EQ(r.data[0], 0x4F);  // n = 3
  EXPECT_EQ(r.data[4], 4);
}

TEST_F(sdo_server_test, expedited_download_of_two_bytes_is_confirmed_and_stored) {
  const frame r = ask(sdo_request(node_id, 0x2B, 0x1017, 0, 250));
  EXPECT_EQ(r.data[0], 0x60);
  std::int64_t v = 0;
  ASSERT_EQ(net.at(0).read(0x1017, 0, v), sdo_abort::none);
  EXPECT_EQ(v, 250);
}

TEST_F(sdo_server_test, expedited_download_without_size_takes_the_objects_own_length) {
  const frame r = ask(sdo_request(node_id, 0x22, 0x1017, 0, 0x000000C8));
  EXPECT_EQ(r.data[0], 0x60);
  std::int64_t v = 0;
  net.at(0).read(0x1017, 0, v);
  EXPECT_EQ(v, 200);
}

TEST_F(sdo_server_test, segmented_upload_of_device_name_returns_the_whole_odd_length_string) {
  // 0x1008 "cia402 virtual drive": 20 bytes = 2 full segments and one of 6.
  EXPECT_EQ(upload_text(0x1008, 0), "cia402 virtual drive");
  EXPECT_EQ(upload_text(0x100A, 0), "0.1.0");  // 5 bytes: segmented too (more than 4)
  EXPECT_EQ(upload_text(0x1009, 0), "virtual");  // exactly one full segment of 7
}

TEST_F(sdo_server_test, segmented_download_of_odd_lengths_reads_back_the_same_text) {
  for (std::size_t len : {1u, 3u, 5u, 6u, 7u, 8u, 13u, 14u, 15u, 21u, 63u, 64u}) {
    std::string text;
    for (std::size_t i = 0; i < len; ++i) text.push_back(static_cast<char>('a' + (i * 7) % 26));
    EXPECT_EQ(download_text(0x2000, 0, text), 0u) << len;
    EXPECT_EQ(upload_text(0x2000, 0), text) << len;
  }
}

TEST_F(sdo_server_test, empty_string_uploads_as_a_segmented_transfer_of_size_zero) {
  EXPECT_EQ(upload_text(0x2000, 0), "");
  const frame r = ask(sdo_request(node_id, 0x40, 0x2000, 0));
  EXPECT_EQ(r.data[0], 0x41);
  EXPECT_EQ(get_le(&r.data[4], 4), 0u);
}

TEST_F(sdo_server_test, segmented_download_of_a_number_is_accepted_like_an_expedited_one) {
  client.start_download(0x1017, 0, std::vector<std::uint8_t>{0x34, 0x12}, true);
  transfer();
  EXPECT_EQ(client.state(), sdo_client::status::done);
  std::int64_t v = 0;
  net.at(0).read(0x1017, 0, v);
  EXPECT_EQ(v, 0x1234);
}

TEST_F(sdo_server_test, unknown_index_aborts_with_0x06020000) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x40, 0x2FFF, 0)), 0x06020000u);
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x2B, 0x2FFF, 0, 1)), 0x06020000u);
}

TEST_F(sdo_server_test, unknown_sub_index_aborts_with_0x06090011) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x40, 0x1018, 9)), 0x06090011u);
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x40, 0x1800, 4)), 0x06090011u);  // TPDO sub 4 is reserved
}

TEST_F(sdo_server_test, writing_a_read_only_object_aborts_with_0x06010002) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x23, 0x1000, 0, 1)), 0x06010002u);
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x2B, 0x6041, 0, 1)), 0x06010002u);
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x21, 0x1008, 0, 3)), 0x06010002u);  // const, segmented
}

TEST_F(sdo_server_test, reading_a_write_only_object_aborts_with_0x06010001) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x40, 0x2001, 0)), 0x06010001u);
}

TEST_F(sdo_server_test, size_larger_than_the_type_aborts_with_0x06070012) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x23, 0x1017, 0, 5)), 0x06070012u);  // 4 bytes to UNSIGNED16
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x21, 0x2000, 0, 65)), 0x06070012u);  // label holds 64
}

TEST_F(sdo_server_test, size_smaller_than_the_type_aborts_with_0x06070013) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x2F, 0x1017, 0, 5)), 0x06070013u);  // 1 byte to UNSIGNED16
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x2B, 0x1400, 1, 5)), 0x06070013u);  // 2 bytes to UNSIGNED32
}

TEST_F(sdo_server_test, segments_that_disagree_with_the_indicated_size_abort_with_0x06070010) {
  EXPECT_EQ(ask(sdo_request(node_id, 0x21, 0x2000, 0, 10)).data[0], 0x60);  // says 10 bytes
  frame seg = sdo_request(node_id, 0x00, 0, 0);                           // 7 bytes, not last
  EXPECT_EQ(ask(seg).data[0], 0x20);
  seg.data[0] = 0x10 | (2 << 1) | 1;  // toggle 1, 5 bytes, last: 12 in all
  EXPECT_EQ(abort_code_of(ask(seg)), 0x06070010u);
}

TEST_F(sdo_server_test, value_below_the_objects_low_limit_aborts_with_0x06090032) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x23, 0x6083, 0, 0)), 0x06090032u);
}

TEST_F(sdo_server_test, value_above_the_objects_high_limit_aborts_with_0x06090031) {
  ASSERT_EQ(ask(sdo_request(node_id, 0x23, 0x1800, 1, 0x80000181)).data[0], 0x60);  // disable TPDO1
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x2F, 0x1A00, 0, 9)), 0x06090031u);
}

TEST_F(sdo_server_test, unsupported_option_code_value_aborts_with_0x06090030_and_changes_nothing) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x2B, 0x605A, 0, 9)), 0x06090030u);
  std::int64_t v = 0;
  net.at(0).read(0x605A, 0, v);
  EXPECT_EQ(v, 2);
}

TEST_F(sdo_server_test, modes_other_than_profile_velocity_abort_with_0x06090030) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x2F, 0x6060, 0, 1)), 0x06090030u);
  EXPECT_EQ(ask(sdo_request(node_id, 0x2F, 0x6060, 0, 3)).data[0], 0x60);
}

TEST_F(sdo_server_test, wrong_toggle_bit_in_a_download_segment_aborts_with_0x05030000) {
  ask(sdo_request(node_id, 0x21, 0x2000, 0, 14));
  frame seg = sdo_request(node_id, 0x10, 0, 0);  // toggle 1 first: wrong
  EXPECT_EQ(abort_code_of(ask(seg)), 0x05030000u);
}

TEST_F(sdo_server_test, wrong_toggle_bit_in_an_upload_segment_aborts_with_0x05030000) {
  EXPECT_EQ(ask(sdo_request(node_id, 0x40, 0x1008, 0)).data[0], 0x41);
  EXPECT_EQ(ask(sdo_request(node_id, 0x60, 0, 0)).data[0] & 0x10, 0x00);
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x60, 0, 0)), 0x05030000u);  // toggle 0 again
}

TEST_F(sdo_server_test, an_unknown_command_specifier_aborts_with_0x05040001) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0xE0, 0x1000, 0)), 0x05040001u);  // ccs 7 (block transfer: sdo_block_test.cpp)
}

TEST_F(sdo_server_test, segment_without_a_transfer_aborts_with_0x05040001) {
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x00, 0, 0)), 0x05040001u);
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x60, 0, 0)), 0x05040001u);
}

TEST_F(sdo_server_test, upload_segment_during_a_download_aborts_with_0x05040001) {
  ask(sdo_request(node_id, 0x21, 0x2000, 0, 14));
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x60, 0, 0)), 0x05040001u);
}

TEST_F(sdo_server_test, silent_client_mid_transfer_gets_0x05040000_after_the_timeout_only) {
  ask(sdo_request(node_id, 0x40, 0x1008, 0));
  net.received.clear();
  net.run(900000, 1000);
  EXPECT_TRUE(net.with_id(cob::sdo_tx + node_id).empty());
  net.run(100000, 1000);
  const auto answers = net.with_id(cob::sdo_tx + node_id);
  ASSERT_EQ(answers.size(), 1u);
  EXPECT_EQ(abort_code_of(answers[0]), 0x05040000u);
  EXPECT_EQ(get_le(&answers[0].data[1], 2), 0x1008u);
  // The server is free again.
  EXPECT_EQ(ask(sdo_request(node_id, 0x40, 0x1000, 0)).data[0], 0x43);
}

TEST_F(sdo_server_test, client_abort_ends_the_transfer_without_an_answer) {
  ask(sdo_request(node_id, 0x40, 0x1008, 0));
  net.received.clear();
  net.send(sdo_request(node_id, 0x80, 0x1008, 0, 0x08000000));
  net.run(2000000, 10000);
  EXPECT_TRUE(net.with_id(cob::sdo_tx + node_id).empty());
}

TEST_F(sdo_server_test, new_initiate_during_a_transfer_starts_over) {
  ask(sdo_request(node_id, 0x40, 0x1008, 0));
  EXPECT_EQ(ask(sdo_request(node_id, 0x40, 0x1000, 0)).data[0], 0x43);
}

TEST_F(sdo_server_test, request_shorter_than_eight_bytes_is_ignored) {
  net.received.clear();
  frame f = sdo_request(node_id, 0x40, 0x1000, 0);
  f.len = 4;
  net.send(f);
  net.settle();
  EXPECT_TRUE(net.with_id(cob::sdo_tx + node_id).empty());
}

TEST_F(sdo_server_test, request_for_another_node_gets_no_answer) {
  net.settle();  // the boot-up message
  net.received.clear();
  net.send(sdo_request(node_id + 1, 0x40, 0x1000, 0));
  net.settle();
  EXPECT_TRUE(net.received.empty());
}

TEST_F(sdo_server_test, consumer_entry_with_reserved_bits_aborts_with_0x06090030_and_keeps_the_old_value) {
  // 0x1016 entry with reserved bits 24..31 set: invalid value, 0x1016 keeps 0.
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x23, 0x1016, 1, 0x01050064)), 0x06090030u);
  std::int64_t v = -1;
  net.at(0).read(0x1016, 1, v);
  EXPECT_EQ(v, 0);
}

TEST_F(sdo_server_test, two_consumer_entries_for_one_node_abort_with_0x06040043) {
  EXPECT_EQ(ask(sdo_request(node_id, 0x23, 0x1016, 1, 0x00200064)).data[0], 0x60);
  EXPECT_EQ(abort_of(sdo_request(node_id, 0x23, 0x1016, 2, 0x002000C8)), 0x06040043u);
}

TEST_F(sdo_server_test, sdo_is_silent_in_stopped_and_answers_again_in_pre_operational) {
  net.send(nmt_frame(nmt_command::stop, node_id));
  net.settle();
  net.received.clear();
  net.send(sdo_request(node_id, 0x40, 0x1000, 0));
  net.settle();
  EXPECT_TRUE(net.with_id(cob::sdo_tx + node_id).empty());
  net.send(nmt_frame(nmt_command::enter_pre_operational, node_id));
  EXPECT_EQ(ask(sdo_request(node_id, 0x40, 0x1000, 0)).data[0], 0x43);
}

}  // namespace
}  // namespace cia402::canopen::test
