// The CANopen frame decoder (canopen/monitor/decoder.hpp): each kind of frame, SDO transfers followed
// across segments and blocks (against a real node where it can answer), aborts, PDO maps from a description and
// learnt from the SDO traffic, and a bus that sends nonsense. Expected texts are CiA 301's and
// CiA 402's terms, written out here.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "cia402/canopen/306/eds_reader.hpp"
#include "cia402/canopen/monitor/decoder.hpp"
#include "network.hpp"

namespace cia402::canopen::monitor {
namespace {

using namespace cia402::dictionary;

using test::network;
using test::sdo_request;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

frame bytes8(std::uint32_t id, std::initializer_list<std::uint8_t> b) {
  frame f = make_frame(id, b);
  f.len = 8;
  return f;
}

TEST(monitor, nmt_commands_name_their_node_or_every_node) {
  decoder dec;
  decoded_frame d = dec.decode(make_frame(0x000, {0x01, 0x03}), 5);
  EXPECT_EQ(d.kind, frame_kind::nmt);
  EXPECT_EQ(d.node, 3);
  EXPECT_EQ(d.event, "start");
  EXPECT_EQ(d.text, "NMT start");
  EXPECT_EQ(d.time_us, 5u);
  d = dec.decode(make_frame(0x000, {0x82, 0x00}), 0);
  EXPECT_EQ(d.event, "reset-communication");
  EXPECT_EQ(d.text, "NMT reset-communication, every node");
  EXPECT_EQ(d.node, 0);
}

TEST(monitor, sync_time_and_heartbeats_read_as_cia_301_sends_them) {
  decoder dec;
  EXPECT_EQ(dec.decode(make_frame(0x080, {}), 0).text, "SYNC");
  EXPECT_EQ(dec.decode(make_frame(0x080, {7}), 0).text, "SYNC counter 7");
  // 12:00:00.5 is 43200500 ms after midnight; day 14610 is 2024-01-01.
  const decoded_frame t = dec.decode(make_frame(0x100, {0xF4, 0x2F, 0x93, 0x02, 0x12, 0x39}), 0);
  EXPECT_EQ(t.kind, frame_kind::time);
  EXPECT_EQ(t.text, "TIME 12:00:00.500, day 14610 since 1984-01-01");
  decoded_frame hb = dec.decode(make_frame(0x703, {0x05}), 0);
  EXPECT_EQ(hb.kind, frame_kind::heartbeat);
  EXPECT_EQ(hb.node, 3);
  EXPECT_EQ(hb.event, "operational");
  EXPECT_EQ(hb.text, "heartbeat OPERATIONAL");
  EXPECT_EQ(dec.decode(make_frame(0x77F, {0x7F}), 0).text, "heartbeat PRE-OPERATIONAL");
  EXPECT_EQ(dec.decode(make_frame(0x701, {0x04}), 0).text, "heartbeat STOPPED");
  hb = dec.decode(make_frame(0x702, {0x00}), 0);
  EXPECT_EQ(hb.event, "boot-up");
  EXPECT_EQ(hb.text, "boot-up");
}

TEST(monitor, an_emcy_names_its_error_code_register_and_manufacturer_bytes) {
  decoder dec;
  decoded_frame d = dec.decode(make_frame(0x081, {0x10, 0x23, 0x03, 0x37, 0x06, 0, 0, 0}), 0);
  EXPECT_EQ(d.kind, frame_kind::emcy);
  EXPECT_EQ(d.node, 1);
  EXPECT_EQ(d.code, 0x2310u);
  EXPECT_EQ(d.code_text, "continuous over-current");
  EXPECT_EQ(d.event, "error");
  EXPECT_EQ(d.text, "EMCY 0x2310 continuous over-current, error register 0x03, manufacturer 37 06 00 00 00");
  d = dec.decode(make_frame(0x0A1, {0, 0, 0, 0, 0, 0, 0, 0}), 0);
  EXPECT_EQ(d.node, 0x21);
  EXPECT_EQ(d.event, "reset");
  EXPECT_EQ(d.text, "EMCY 0x0000 error reset or no error, error register 0x00");
}

TEST(monitor, an_expedited_upload_shows_the_object_its_value_and_what_it_means) {
  decoder dec;
  decoded_frame req = dec.decode(bytes8(0x603, {0x40, 0x41, 0x60, 0x00}), 0);
  EXPECT_EQ(req.kind, frame_kind::sdo);
  EXPECT_EQ(req.event, "upload-request");
  EXPECT_EQ(req.text, "SDO upload request 0x6041:0 (Statusword)");
  decoded_frame resp = dec.decode(bytes8(0x583, {0x4B, 0x41, 0x60, 0x00, 0x37, 0x02}), 0);
  EXPECT_EQ(resp.node, 3);
  EXPECT_EQ(resp.event, "upload");
  ASSERT_TRUE(resp.has_object);
  EXPECT_EQ(resp.index, 0x6041);
  ASSERT_EQ(resp.values.size(), 1u);
  EXPECT_EQ(resp.values[0].number, 0x0237);
  EXPECT_EQ(resp.text, "SDO upload 0x6041:0 = 0x0237 (Statusword: OPERATION_ENABLED)");
  // A signed object, a unit, and a mode's short name.
  resp = dec.decode(bytes8(0x583, {0x43, 0x6C, 0x60, 0x00, 0x88, 0xFF, 0xFF, 0xFF}), 0);
  EXPECT_EQ(resp.text, "SDO upload 0x606C:0 = -120 rpm (Velocity actual value)");
  resp = dec.decode(bytes8(0x583, {0x4F, 0x61, 0x60, 0x00, 0x08}), 0);
  EXPECT_EQ(resp.text, "SDO upload 0x6061:0 = 8 (Modes of operation display: csp)");
}

TEST(monitor, an_expedited_download_and_its_confirmation) {
  decoder dec;
  decoded_frame d = dec.decode(bytes8(0x601, {0x2B, 0x40, 0x60, 0x00, 0x0F, 0x00}), 0);
  EXPECT_EQ(d.event, "download");
  EXPECT_EQ(d.text, "SDO download 0x6040:0 = 0x000F (Controlword)");
  d = dec.decode(bytes8(0x581, {0x60, 0x40, 0x60, 0x00}), 0);
  EXPECT_EQ(d.event, "download-done");
  EXPECT_EQ(d.text, "SDO download 0x6040:0 done");
  // A confirmation whose request the monitor missed says so.
  d = dec.decode(bytes8(0x581, {0x60, 0x17, 0x10, 0x00}), 0);
  EXPECT_EQ(d.text, "SDO download 0x1017:0 done (its request was not seen)");
}

TEST(monitor, aborts_from_either_side_carry_their_code_and_text) {
  decoder dec;
  decoded_frame d = dec.decode(bytes8(0x583, {0x80, 0x60, 0x60, 0x00, 0x30, 0x00, 0x09, 0x06}), 0);
  EXPECT_EQ(d.kind, frame_kind::sdo);
  EXPECT_EQ(d.event, "abort");
  EXPECT_EQ(d.code, 0x06090030u);
  EXPECT_EQ(d.text, "SDO abort 0x6060:0 0x06090030 invalid value for parameter");
  d = dec.decode(bytes8(0x603, {0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x00, 0x08}), 0);
  EXPECT_EQ(d.text, "SDO abort 0x1008:0 0x08000000 general error (by the client)");
  d = dec.decode(bytes8(0x583, {0x80, 0x00, 0x20, 0x00, 0x78, 0x56, 0x34, 0x12}), 0);
  EXPECT_EQ(d.text, "SDO abort 0x2000:0 0x12345678 unknown abort code");
}

// A node on the virtual bus and a witness channel that sees every frame, decoded in order.
class monitor_on_a_node : public ::testing::Test {
 protected:
  void SetUp() override {
    dec.describe_other_nodes(node_objects(apps::drive_node_config(0)));  // names; its PDO maps are replaced where a test says
    witness = net.bus().attach();
    net.add(id);
    net.settle();
  }
  /// Every frame the bus carried since the last call, decoded.
  std::vector<decoded_frame> decoded() {
    std::vector<decoded_frame> out;
    for (frame f; witness->receive(f);) out.push_back(dec.decode(f, ++clock));
    return out;
  }
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, unsigned bytes) {
    return test::sdo_answer(net, id, test::sdo_download(id, index, sub, value, bytes));
  }

  static constexpr std::uint8_t id = 4;
  network net;
  std::unique_ptr<virtual_channel> witness;
  decoder dec;
  std::uint64_t clock = 0;
};

TEST_F(monitor_on_a_node, a_segmented_upload_is_followed_to_the_whole_value) {
  (void)decoded();
  net.send(sdo_request(id, 0x40, 0x1008, 0));
  net.settle();
  for (std::uint8_t toggle = 0;; toggle ^= 1) {
    const frame last = net.received.back();
    if (last.id != cob::sdo_tx + id || (last.data[0] >> 5) != 0 ? false : (last.data[0] & 1) != 0) break;
    net.send(sdo_request(id, static_cast<std::uint8_t>(0x60 | (toggle << 4)), 0, 0));
    net.settle();
    ASSERT_LT(net.received.size(), 20u);
  }
  const auto all = decoded();
  ASSERT_GE(all.size(), 4u);
  EXPECT_EQ(all[0].text, "SDO upload request 0x1008:0 (Manufacturer device name)");
  EXPECT_EQ(all[1].event, "upload-start");
  EXPECT_EQ(all[1].text, "SDO upload 0x1008:0 (Manufacturer device name), 20 bytes in segments");
  EXPECT_EQ(all[2].text, "SDO upload 0x1008:0 segment request");
  EXPECT_EQ(all[3].text, "SDO upload 0x1008:0 segment, 7 bytes");
  const decoded_frame& done = all.back();
  EXPECT_EQ(done.event, "upload");
  EXPECT_EQ(done.text, "SDO upload 0x1008:0 = \"cia402 virtual drive\" (Manufacturer device name), 20 bytes");
}

TEST_F(monitor_on_a_node, a_segmented_download_is_followed_to_the_nodes_confirmation) {
  (void)decoded();
  // "hello, segments" (15 bytes) to the device label 0x2000: initiate with size, 7 + 7 + 1 bytes.
  // A client waits for each answer before its next frame.
  for (const frame& f : {sdo_request(id, 0x21, 0x2000, 0, 15),
                         bytes8(0x600 + id, {0x00, 'h', 'e', 'l', 'l', 'o', ',', ' '}),
                         bytes8(0x600 + id, {0x10, 's', 'e', 'g', 'm', 'e', 'n', 't'}),
                         bytes8(0x600 + id, {0x0D, 's'})}) {  // toggle 0, 6 bytes unused, last
    net.send(f);
    net.settle();
  }
  const auto all = decoded();
  std::vector<std::string> texts;
  for (const auto& d : all) texts.push_back(d.text);
  ASSERT_EQ(all.size(), 8u) << testing::PrintToString(texts);
  EXPECT_EQ(all[0].text, "SDO download 0x2000:0 (Device label), 15 bytes in segments");
  EXPECT_EQ(all[1].text, "SDO download 0x2000:0 accepted, segments follow");
  EXPECT_EQ(all[2].text, "SDO download 0x2000:0 segment, 7 bytes");
  EXPECT_EQ(all[3].text, "SDO download 0x2000:0 segment confirmed");
  EXPECT_EQ(all[4].text, "SDO download 0x2000:0 segment, 7 bytes");
  EXPECT_EQ(all[6].text, "SDO download 0x2000:0 = \"hello, segments\" (Device label), 15 bytes, the last segment");
  EXPECT_EQ(all[7].event, "download-done");
  EXPECT_EQ(all[7].text, "SDO download 0x2000:0 done, 15 bytes");
}

// A block transfer is followed like a segmented one: each block's segments in order, a segment
// sent again after a short acknowledge counted once, the value once the end says what was data. A
// last segment's first byte (0x81..0x9F) is no abort.
TEST_F(monitor_on_a_node, block_transfers_are_followed_to_the_whole_value) {
  (void)decoded();
  // Block upload of 0x1008 (20 bytes) in blocks of 2, CRC offered: 2 segments, acknowledge, 1, end.
  for (const frame& f : {bytes8(0x600 + id, {0xA4, 0x08, 0x10, 0x00, 2, 0}), bytes8(0x600 + id, {0xA3}),
                         bytes8(0x600 + id, {0xA2, 2, 2}), bytes8(0x600 + id, {0xA2, 1, 2}),
                         bytes8(0x600 + id, {0xA1})}) {
    net.send(f);
    net.settle();
  }
  std::vector<decoded_frame> all = decoded();
  std::vector<std::string> texts;
  for (const auto& d : all) texts.push_back(d.text);
  ASSERT_EQ(all.size(), 10u) << testing::PrintToString(texts);
  EXPECT_EQ(all[0].text, "SDO block upload request 0x1008:0 (Manufacturer device name), blocks of 2 segments, CRC offered");
  EXPECT_EQ(all[1].text, "SDO block upload 0x1008:0 (Manufacturer device name), 20 bytes in blocks, CRC offered");
  EXPECT_EQ(all[3].text, "SDO block upload 0x1008:0 segment 1");
  EXPECT_EQ(all[6].text, "SDO block upload 0x1008:0 segment 1, the last") << "0x81 is a segment here, not an abort";
  EXPECT_EQ(all[8].event, "upload");
  EXPECT_EQ(all[8].text.rfind("SDO block upload 0x1008:0 = \"cia402 virtual drive\" (Manufacturer device name), 20 bytes, CRC 0x", 0), 0u)
      << all[8].text;
  EXPECT_EQ(all[9].text, "SDO block upload 0x1008:0 done");
  // Block download of 15 bytes to 0x2000, its second segment lost once: 1 and 3 go, the
  // acknowledge says 1, then 2 and 3 again as segments 1 and 2 of the next block.
  const std::string text = "hello, blocks!!";
  const auto seg = [&](std::uint8_t sequence, std::size_t at, bool last) {
    frame f = bytes8(0x600 + id, {static_cast<std::uint8_t>(sequence | (last ? 0x80 : 0))});
    for (std::size_t k = 0; k < 7 && at + k < text.size(); ++k) f.data[1 + k] = static_cast<std::uint8_t>(text[at + k]);
    return f;
  };
  for (const frame& f : {bytes8(0x600 + id, {0xC2, 0x00, 0x20, 0x00, 15}), seg(1, 0, false), seg(3, 14, true),
                         seg(1, 7, false), seg(2, 14, true), bytes8(0x600 + id, {0xC1 | (6 << 2)})}) {
    net.send(f);
    net.settle();
  }
  all = decoded();
  texts.clear();
  for (const auto& d : all) texts.push_back(d.text);
  ASSERT_EQ(all.size(), 10u) << testing::PrintToString(texts);
  EXPECT_EQ(all[0].text, "SDO block download 0x2000:0 (Device label), 15 bytes");
  EXPECT_EQ(all[3].text, "SDO block download 0x2000:0 segment 3, the last (out of sequence: sent again)");
  EXPECT_EQ(all[4].text, "SDO block download 0x2000:0 block acknowledged at segment 1, next block 127 segments");
  EXPECT_EQ(all[9].event, "download-done");
  EXPECT_EQ(all[9].text, "SDO block download 0x2000:0 = \"hello, blocks!!\" (Device label), 15 bytes, done");
}

TEST_F(monitor_on_a_node, a_refused_write_is_an_abort_with_the_nodes_code) {
  (void)decoded();
  EXPECT_EQ(write(0x2FFF, 0, 1, 1), 0x06020000u);
  const auto all = decoded();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[1].text, "SDO abort 0x2FFF:0 0x06020000 object does not exist in the object dictionary");
}

TEST_F(monitor_on_a_node, a_tpdo_decodes_by_the_mapping_learnt_from_the_sdo_traffic) {
  // No description: a PDO means nothing to the monitor until its mapping goes over the bus.
  dec.describe_other_nodes({});
  net.send(nmt_frame(nmt_command::start, id));
  net.settle();
  auto before = decoded();
  const decoded_frame* tpdo = nullptr;
  for (const auto& d : before) {
    if (d.raw.id == 0x180u + id) tpdo = &d;
  }
  ASSERT_NE(tpdo, nullptr);
  EXPECT_EQ(tpdo->kind, frame_kind::unknown);

  // TPDO1 = status word + error code, as `cia402 master` maps it.
  net.send(nmt_frame(nmt_command::enter_pre_operational, id));
  net.settle();
  ASSERT_EQ(write(0x1800, 1, 0x80000180u + id, 4), 0u);
  ASSERT_EQ(write(0x1A00, 0, 0, 1), 0u);
  ASSERT_EQ(write(0x1A00, 1, 0x60410010u, 4), 0u);
  ASSERT_EQ(write(0x1A00, 2, 0x603F0010u, 4), 0u);
  ASSERT_EQ(write(0x1A00, 0, 2, 1), 0u);
  ASSERT_EQ(write(0x1800, 1, 0x180u + id, 4), 0u);
  // A write the node refuses teaches nothing: moving a valid PDO's CAN-ID (0x06090030).
  ASSERT_EQ(write(0x1800, 1, 0x1A0u + id, 4), 0x06090030u);
  net.send(nmt_frame(nmt_command::start, id));
  net.settle();
  const auto after = decoded();
  tpdo = nullptr;
  for (const auto& d : after) {
    if (d.raw.id == 0x180u + id) tpdo = &d;
  }
  ASSERT_NE(tpdo, nullptr);
  EXPECT_EQ(tpdo->kind, frame_kind::pdo);
  EXPECT_EQ(tpdo->node, id);
  EXPECT_EQ(tpdo->event, "TPDO1");
  ASSERT_EQ(tpdo->values.size(), 2u);
  EXPECT_EQ(tpdo->values[0].index, 0x6041);
  EXPECT_EQ(tpdo->values[1].index, 0x603F);
  EXPECT_EQ(tpdo->values[0].number, static_cast<std::int64_t>(get_le(tpdo->raw.data.data(), 2)));
  EXPECT_EQ(tpdo->values[1].number, static_cast<std::int64_t>(get_le(tpdo->raw.data.data() + 2, 2)));
  EXPECT_TRUE(contains(tpdo->text, "TPDO1 0x6041:0 = 0x")) << tpdo->text;
  EXPECT_TRUE(contains(tpdo->text, "(Statusword: ")) << tpdo->text;
  EXPECT_TRUE(contains(tpdo->text, "), 0x603F:0 = 0x0000 (Error code)")) << tpdo->text;
  // A reset brings the communication objects back: without a description, nothing is known.
  net.send(nmt_frame(nmt_command::reset_communication, id));
  net.settle();
  (void)decoded();
  EXPECT_EQ(dec.decode(make_frame(0x180 + id, {0x50, 0x02, 0, 0}), 0).kind, frame_kind::unknown);
}

TEST_F(monitor_on_a_node, a_described_node_decodes_its_predefined_pdos_and_a_reset_restores_them) {
  dec.describe_other_nodes(node_objects(apps::drive_node_config(0)));
  const decoded_frame d = dec.decode(make_frame(0x480 + id, {0x37, 0x06, 0x88, 0xFF, 0xFF, 0xFF}), 0);
  EXPECT_EQ(d.kind, frame_kind::pdo);
  EXPECT_EQ(d.text, "TPDO4 0x6041:0 = 0x0637 (Statusword: OPERATION_ENABLED), "
                    "0x606C:0 = -120 rpm (Velocity actual value)");
  EXPECT_EQ(dec.decode(make_frame(0x200 + id, {0x0F, 0x00}), 0).text, "RPDO1 0x6040:0 = 0x000F (Controlword)");
  // Remapped RPDO1 to 0x6060, then reset: 0x6040 again.
  (void)decoded();
  ASSERT_EQ(write(0x1400, 1, 0x80000200u + id, 4), 0u);
  ASSERT_EQ(write(0x1600, 0, 0, 1), 0u);
  ASSERT_EQ(write(0x1600, 1, 0x60600008u, 4), 0u);
  ASSERT_EQ(write(0x1600, 0, 1, 1), 0u);
  ASSERT_EQ(write(0x1400, 1, 0x200u + id, 4), 0u);
  (void)decoded();
  EXPECT_EQ(dec.decode(make_frame(0x200 + id, {0x03}), 0).text, "RPDO1 0x6060:0 = 3 (Modes of operation: pv)");
  (void)dec.decode(nmt_frame(nmt_command::reset_node, id), 0);
  EXPECT_EQ(dec.decode(make_frame(0x200 + id, {0x0F, 0x00}), 0).text, "RPDO1 0x6040:0 = 0x000F (Controlword)");
}

TEST(monitor, a_node_described_by_its_eds_decodes_by_the_files_mapping) {
  const auto eds = read_eds(
      "[1800]\nParameterName=TPDO1 communication parameter\nObjectType=0x9\n"
      "[1800sub1]\nParameterName=COB-ID\nDataType=0x0007\nDefaultValue=$NODEID+0x180\n"
      "[1A00]\nParameterName=TPDO1 mapping parameter\nObjectType=0x9\n"
      "[1A00sub0]\nParameterName=Count\nDataType=0x0005\nDefaultValue=2\n"
      "[1A00sub1]\nParameterName=Entry 1\nDataType=0x0007\nDefaultValue=0x21000108\n"
      "[1A00sub2]\nParameterName=Entry 2\nDataType=0x0007\nDefaultValue=0x60640020\n"
      "[2100]\nParameterName=Temperatures\nObjectType=0x8\nDataType=0x0002\nCompactSubObj=1\n");
  ASSERT_TRUE(std::holds_alternative<eds_contents>(eds));
  decoder dec;
  dec.describe_node(9, std::get<eds_contents>(eds).objects);
  const decoded_frame d = dec.decode(make_frame(0x189, {0xFE, 0x10, 0x27, 0x00, 0x00}), 0);
  EXPECT_EQ(d.kind, frame_kind::pdo);
  EXPECT_EQ(d.node, 9);
  EXPECT_EQ(d.text, "TPDO1 0x2100:1 = -2 (Temperatures: Temperatures 1), "
                    "0x6064:0 = 10000 inc (Position actual value)");
}

// A description is a peer's: "$NODEID+X" for a node it was not written for may leave the COB-ID's
// type, and X may be INTEGER64's largest. The sum is checked (no signed overflow); a COB-ID that does
// not fit its type is no COB-ID, not one cut to 32 bits (0x100000010 taken as 0x010).
TEST(monitor, a_cob_id_that_does_not_fit_its_type_on_the_node_is_no_pdo) {
  const auto eds = read_eds(
      "[DeviceComissioning]\nNodeID=1\n"
      "[1800]\nParameterName=TPDO1 communication parameter\nObjectType=0x9\n"
      "[1800sub1]\nParameterName=COB-ID\nDataType=0x0007\nDefaultValue=$NODEID+0xFFFFFFF0\n"
      "[1A00]\nParameterName=TPDO1 mapping parameter\nObjectType=0x9\n"
      "[1A00sub0]\nParameterName=Count\nDataType=0x0005\nDefaultValue=1\n"
      "[1A00sub1]\nParameterName=Entry 1\nDataType=0x0007\nDefaultValue=0x60410010\n");
  ASSERT_TRUE(std::holds_alternative<eds_contents>(eds));  // 0xFFFFFFF0 + node 1 fits UNSIGNED32
  decoder dec;
  dec.describe_node(0x20, std::get<eds_contents>(eds).objects);  // + 0x20: 0x100000010
  EXPECT_EQ(dec.decode(make_frame(0x010, {0x37, 0x02}), 0).kind, frame_kind::unknown);

  std::vector<object_entry> hostile = std::get<eds_contents>(eds).objects;
  sub_entry& cob_id = hostile.front().subs.front();
  ASSERT_EQ(cob_id.sub, 1);
  cob_id.type = data_type::integer64;
  cob_id.default_value = std::numeric_limits<std::int64_t>::max();  // + 9 overflows int64
  decoder other;
  other.describe_node(9, hostile);
  EXPECT_EQ(other.decode(make_frame(0x008, {0x37, 0x02}), 0).kind, frame_kind::unknown);
}

TEST(monitor, frames_that_are_not_what_their_cob_id_says_decode_as_unknown_with_the_reason) {
  decoder dec;
  dec.describe_other_nodes(node_objects(apps::drive_node_config(0)));
  frame rtr_sdo = make_frame(0x601, {});
  rtr_sdo.rtr = true;
  frame extended = make_frame(0x181, {1, 2});
  extended.extended = true;
  frame too_long = make_frame(0x181, {1, 2});
  too_long.len = 12;
  const struct {
    frame f;
    const char* reason;
  } bad[] = {
      {make_frame(0x601, {0x40, 0x41, 0x60}), "SDO request of 3 bytes"},
      {rtr_sdo, "remote request"},
      {make_frame(0x081, {0x10}), "EMCY of 1 byte"},
      {make_frame(0x000, {0x01}), "NMT of 1 byte"},
      {make_frame(0x000, {0x03, 0x01}), "NMT command 0x03"},
      {make_frame(0x000, {0x01, 0x80}), "node 128"},
      {make_frame(0x701, {0x42}), "heartbeat with state 0x42"},
      {make_frame(0x701, {0x05, 0x00}), "heartbeat of 2 bytes"},
      {make_frame(0x080, {1, 2}), "SYNC of 2 bytes"},
      {make_frame(0x100, {1}), "TIME of 1 byte"},
      {extended, "29-bit identifier"},
      {too_long, "length of 12 bytes"},
      {make_frame(0x181, {0x37}), "TPDO1 of 1 bytes, shorter than its mapping (16 bits)"},
      {make_frame(0x7E5, {0x11}), "LSS"},
      {make_frame(0x123, {}), "no service or PDO known on 0x123"},
      {bytes8(0x601, {0xE0}), "command specifier 7"},
  };
  for (const auto& b : bad) {
    const decoded_frame d = dec.decode(b.f, 0);
    EXPECT_EQ(d.kind, frame_kind::unknown) << b.reason;
    EXPECT_TRUE(contains(d.text, b.reason)) << d.text;
  }
}

TEST(monitor, segments_with_no_transfer_open_and_toggle_errors_are_named_not_trusted) {
  decoder dec;
  EXPECT_EQ(dec.decode(bytes8(0x581, {0x00, 1, 2, 3, 4, 5, 6, 7}), 0).text,
            "SDO upload segment, 7 bytes, with no upload open");
  EXPECT_EQ(dec.decode(bytes8(0x601, {0x60}), 0).text, "SDO upload segment request with no upload open");
  (void)dec.decode(bytes8(0x581, {0x41, 0x08, 0x10, 0x00, 0x0E}), 0);  // 14 bytes in segments
  EXPECT_EQ(dec.decode(bytes8(0x581, {0x10, 'a', 'b', 'c', 'd', 'e', 'f', 'g'}), 0).text,
            "SDO upload 0x1008:0 segment, 7 bytes (toggle bit not alternated)");
  const decoded_frame last = dec.decode(bytes8(0x581, {0x01, 'h', 'i', 'j', 'k', 'l', 'm', 'n'}), 0);
  EXPECT_EQ(last.text, "SDO upload 0x1008:0 = \"abcdefghijklmn\", 14 bytes");
}

TEST(monitor, random_frames_never_crash_the_decoder_and_always_say_something) {
  decoder dec;
  dec.describe_other_nodes(node_objects(apps::drive_node_config(0)));
  std::mt19937 random(402);
  // Most frames where the services are (SDO, PDO, EMCY, heartbeat), some anywhere, a few malformed.
  const std::uint32_t bases[] = {0x000, 0x080, 0x100, 0x180, 0x200, 0x280, 0x300, 0x380, 0x400,
                                 0x480, 0x500, 0x580, 0x600, 0x700, 0x7E4};
  std::size_t kinds[8] = {};
  for (int i = 0; i < 100000; ++i) {
    frame f;
    const unsigned pick = random() % 20;
    f.id = pick == 0 ? static_cast<std::uint32_t>(random() % 0x800)
                     : bases[random() % std::size(bases)] + static_cast<std::uint32_t>(random() % 4);
    f.len = static_cast<std::uint8_t>(pick == 1 ? random() % 256 : (random() % 3 == 0 ? random() % 9 : 8));
    f.rtr = pick == 2;
    f.extended = pick == 3;
    for (auto& b : f.data) b = static_cast<std::uint8_t>(random() % 4 == 0 ? random() : random() % 4);
    // SDO command bytes that open and continue transfers, so the followed state is exercised.
    if (random() % 2 == 0) f.data[0] = static_cast<std::uint8_t>((random() % 8) << 5 | (random() % 32));
    const decoded_frame d = dec.decode(f, static_cast<std::uint64_t>(i));
    ASSERT_FALSE(d.text.empty());
    ASSERT_LE(d.raw.len, 8);
    ASSERT_LE(d.values.size(), 64u);
    ++kinds[static_cast<unsigned>(d.kind)];
  }
  for (std::size_t k = 0; k < 8; ++k) {
    EXPECT_GT(kinds[k], 0u) << kind_name(static_cast<frame_kind>(k));
  }
}

}  // namespace
}  // namespace cia402::canopen::monitor
