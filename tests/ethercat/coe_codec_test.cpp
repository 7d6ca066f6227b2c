// The CoE codec (ethercat/coe) both sides use: every request and response it builds reads back as
// what was built, every length a peer gives is checked before what it covers is read, and an abort is
// CoE service 2 whichever side sends it (ETG.1000.6 §5.6.2.7).
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "cia402/ethercat/coe/mailbox.hpp"
#include "cia402/ethercat/coe/sdo.hpp"
#include "cia402/ethercat/coe/sdo_information.hpp"

namespace cia402::ethercat {
namespace {

std::vector<std::uint8_t> bytes(std::initializer_list<int> list) {
  std::vector<std::uint8_t> v;
  for (int b : list) v.push_back(static_cast<std::uint8_t>(b));
  return v;
}

// A built CoE request or response read back the way the other side reads it (its data points into
// `coe`, which the caller keeps).
sdo_frame as_request(const std::vector<std::uint8_t>& coe) {
  const auto c = parse_coe(coe);
  EXPECT_TRUE(c.has_value());
  EXPECT_EQ(c->service, coe_service::sdo_request);
  const auto f = parse_sdo_request(c->body);
  EXPECT_TRUE(f.has_value());
  return f.value_or(sdo_frame{});
}

sdo_frame as_response(const std::vector<std::uint8_t>& coe) {
  const auto c = parse_coe(coe);
  EXPECT_TRUE(c.has_value());
  const auto f = parse_sdo_response(c->service, c->body);
  EXPECT_TRUE(f.has_value());
  return f.value_or(sdo_frame{});
}

TEST(coe_codec, a_mailbox_longer_than_it_holds_is_refused_and_its_padding_ignored) {
  mailbox_header h;
  h.type = mailbox_type::coe;
  h.counter = 3;
  const std::vector<std::uint8_t> data = bytes({1, 2, 3, 4});
  std::vector<std::uint8_t> m = make_mailbox(h, data, 16);
  ASSERT_EQ(m.size(), 16u);
  const auto v = parse_mailbox(m);
  ASSERT_TRUE(v);
  EXPECT_EQ(v->header.length, 4);
  EXPECT_EQ(v->header.counter, 3);
  EXPECT_EQ(std::vector<std::uint8_t>(v->data.begin(), v->data.end()), data) << "padding is not data";
  m[0] = 11;  // claims 11 bytes after a header in a 16-byte mailbox: one more than there are
  EXPECT_FALSE(parse_mailbox(m));
  EXPECT_FALSE(parse_mailbox(bytes({4, 0, 0, 0, 0})));
  EXPECT_TRUE(make_mailbox(h, std::vector<std::uint8_t>(11), 16).empty()) << "does not fit";
  EXPECT_EQ(next_mailbox_counter(7), 1) << "0 is reserved";
  EXPECT_EQ(parse_mailbox_error(mailbox_error_data(mailbox_error::invalid_size)), 0x0008);
  EXPECT_FALSE(parse_mailbox_error(bytes({1, 0, 8})));
}

TEST(coe_codec, requests_read_back_as_built) {
  sdo_frame f = as_request(sdo_upload_request(0x1018, 2, true));
  EXPECT_EQ(f.command, sdo_command::initiate_upload);
  EXPECT_EQ(f.index, 0x1018);
  EXPECT_EQ(f.sub, 2);
  EXPECT_TRUE(f.complete_access);

  const std::vector<std::uint8_t> two = bytes({0x0F, 0x00});
  const std::vector<std::uint8_t> expedited = sdo_download_expedited(0x6040, 0, two);  // the frame outlives f's data
  f = as_request(expedited);
  EXPECT_EQ(f.command, sdo_command::initiate_download);
  EXPECT_TRUE(f.expedited);
  EXPECT_TRUE(f.size_indicated);
  EXPECT_EQ(std::vector<std::uint8_t>(f.data.begin(), f.data.end()), two);

  const std::string text = "twelve bytes";
  const std::vector<std::uint8_t> first(text.begin(), text.begin() + 5);
  const std::vector<std::uint8_t> normal = sdo_download_normal(0x2000, 0, false, 12, first);
  f = as_request(normal);
  EXPECT_FALSE(f.expedited);
  EXPECT_EQ(f.size, 12u);
  EXPECT_EQ(f.data.size(), 5u) << "what this mailbox holds of the 12";

  for (std::size_t n : {0u, 3u, 7u, 20u}) {
    const std::vector<std::uint8_t> seg(n, 0xAB);
    const std::vector<std::uint8_t> segment = sdo_download_segment(true, n == 3, seg);
    f = as_request(segment);
    EXPECT_EQ(f.command, sdo_command::download_segment);
    EXPECT_TRUE(f.toggle);
    EXPECT_EQ(f.last, n == 3);
    EXPECT_EQ(f.data.size(), n) << "a segment of " << n << " bytes";
  }
  f = as_request(sdo_upload_segment_request(true));
  EXPECT_EQ(f.command, sdo_command::upload_segment);
  EXPECT_TRUE(f.toggle);
}

TEST(coe_codec, responses_read_back_as_built) {
  const std::vector<std::uint8_t> three = bytes({1, 2, 3});
  const std::vector<std::uint8_t> expedited = sdo_upload_expedited_response(0x6064, 0, three);
  sdo_frame f = as_response(expedited);
  EXPECT_EQ(f.command, sdo_command::initiate_upload);
  EXPECT_TRUE(f.expedited);
  EXPECT_EQ(std::vector<std::uint8_t>(f.data.begin(), f.data.end()), three);

  const std::vector<std::uint8_t> normal = sdo_upload_normal_response(0x1008, 0, false, 300, bytes({'c', 'i', 'a'}));
  f = as_response(normal);
  EXPECT_FALSE(f.expedited);
  EXPECT_EQ(f.size, 300u);
  EXPECT_EQ(f.data.size(), 3u);

  const std::vector<std::uint8_t> segment = sdo_upload_segment_response(false, true, bytes({'x', 'y'}));
  f = as_response(segment);
  EXPECT_EQ(f.command, sdo_command::upload_segment);
  EXPECT_TRUE(f.last);
  EXPECT_EQ(f.data.size(), 2u) << "7 less the unused count of a padded segment";

  f = as_response(sdo_download_response(0x1C12, 0, true));
  EXPECT_EQ(f.command, sdo_command::initiate_download);
  EXPECT_TRUE(f.complete_access);
  f = as_response(sdo_download_segment_response(true));
  EXPECT_EQ(f.command, sdo_command::download_segment);
  EXPECT_TRUE(f.toggle);
}

TEST(coe_codec, an_abort_is_service_2_from_either_side_and_a_slaves_abort_under_3_is_read_too) {
  const std::vector<std::uint8_t> a = sdo_abort_request(0x6042, 0, 0x06020000);
  const auto c = parse_coe(a);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->service, coe_service::sdo_request);
  const auto f = parse_sdo_response(c->service, c->body);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->command, sdo_command::abort);
  EXPECT_EQ(f->index, 0x6042);
  EXPECT_EQ(f->abort_code, 0x06020000u);
  const auto old = parse_sdo_response(coe_service::sdo_response, c->body);
  ASSERT_TRUE(old) << "a slave that sends its abort as a response";
  EXPECT_EQ(old->command, sdo_command::abort);
  EXPECT_FALSE(parse_sdo_response(coe_service::sdo_request, bytes({0x40, 0, 0x10, 0, 0, 0, 0, 0})))
      << "a request is no answer";
}

TEST(coe_codec, a_frame_short_for_its_command_reads_as_nothing_and_data_never_passes_the_frame) {
  EXPECT_FALSE(parse_coe(bytes({0x00})));
  EXPECT_FALSE(parse_sdo_request({}));
  EXPECT_FALSE(parse_sdo_request(bytes({0x40, 0x41, 0x60})));
  EXPECT_FALSE(parse_sdo_response(coe_service::sdo_response, bytes({0x4B, 0x41, 0x60, 0})));
  EXPECT_FALSE(parse_sdo_response(coe_service::sdo_request, bytes({0x80, 0x41, 0x60, 0, 0, 0})));
  // A normal upload response that announces 1000 bytes and holds 2: the data is the 2.
  const auto f = parse_sdo_response(coe_service::sdo_response, bytes({0x41, 0x08, 0x10, 0, 0xE8, 0x03, 0, 0, 'a', 'b'}));
  ASSERT_TRUE(f);
  EXPECT_EQ(f->size, 1000u);
  EXPECT_EQ(f->data.size(), 2u);
  // A segment that says 7 bytes (0 unused) in a frame of 3: the 2 it has.
  const auto s = parse_sdo_response(coe_service::sdo_response, bytes({0x00, 'a', 'b'}));
  ASSERT_TRUE(s);
  EXPECT_EQ(s->data.size(), 2u);
  // Block transfers are no segmented SDO: named as such with the object they name.
  const auto block = parse_sdo_request(bytes({0xC6, 0x00, 0x20, 0, 4, 0, 0, 0}));
  ASSERT_TRUE(block);
  EXPECT_EQ(block->command, sdo_command::other);
  EXPECT_EQ(block->index, 0x2000);
  EXPECT_FALSE(parse_emergency(bytes({0x30, 0x81, 1, 0, 0, 0, 0})));
  const auto e = parse_emergency(bytes({0x30, 0x81, 1, 0x37, 2, 0, 0, 0}));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->code, 0x8130);
  EXPECT_EQ(e->data[0], 0x37);
}

TEST(coe_codec, sdo_information_fragments_say_how_many_follow) {
  const std::vector<std::uint8_t> one = sdo_info_fragment(sdo_info_opcode::od_list_response, 2, bytes({1, 0}));
  const auto c = parse_coe(one);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->service, coe_service::sdo_information);
  const auto v = parse_sdo_information(c->body);
  ASSERT_TRUE(v);
  EXPECT_EQ(v->opcode, sdo_info_opcode::od_list_response);
  EXPECT_TRUE(v->incomplete);
  EXPECT_EQ(v->fragments_left, 2);
  sdo_info_view entry;
  entry.opcode = sdo_info_opcode::entry_description_request;
  const std::vector<std::uint8_t> three = bytes({0x40, 0x60, 0});
  entry.data = three;
  EXPECT_FALSE(parse_sdo_info_request(entry)) << "index, sub-index and value info: 4 bytes";
  const std::vector<std::uint8_t> four = bytes({0x40, 0x60, 1, 0});
  entry.data = four;
  const auto r = parse_sdo_info_request(entry);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->list_or_index, 0x6040);
  EXPECT_EQ(r->sub, 1);
}

}  // namespace
}  // namespace cia402::ethercat
