// Our EtherCAT master against slaves that are faulty or hostile (hostile_line.hpp): an SII that
// gives mailboxes too small for an SDO, AL status reads that get lost slave by slave, a mapping
// changed in PRE-OP after the line ran, a cycle asked for before any bring-up, SDO information that
// does not add up. Each of these read or wrote outside a buffer, or never returned, before the
// master checked what a slave says.
#include <gtest/gtest.h>

#include <array>
#include <initializer_list>
#include <string>
#include <tuple>
#include <vector>

#include "cia402/ethercat/master/ecat_master.hpp"
#include "enable_words.hpp"
#include "hostile_line.hpp"

namespace cia402::ethercat {
namespace {

using testing::al_status_read;
using testing::hostile_line;

// The master's error names every one of `parts` (the slave and what was wrong with it); the whole
// error is shown when not.
::testing::AssertionResult error_names(const ecat_master& m, std::initializer_list<const char*> parts) {
  for (const char* part : parts) {
    if (m.error().find(part) == std::string::npos) {
      return ::testing::AssertionFailure() << "the error does not name \"" << part << "\": " << m.error();
    }
  }
  return ::testing::AssertionSuccess();
}

// The first datagram's command and offset in a frame the master sent.
struct first_datagram {
  command cmd;
  std::uint16_t offset;
};
first_datagram first_of(const std::vector<std::uint8_t>& frame) {
  return {static_cast<command>(frame[16]), static_cast<std::uint16_t>(frame[20] | (frame[21] << 8))};
}

TEST(ecat_master_hostile, a_send_mailbox_of_1_byte_in_the_sii_is_refused_with_the_slave_and_the_size) {
  hostile_line line(1);
  line.describe(0, [](slave_description& d) { d.mailbox_in_size = 1; });
  ecat_master m(line, standard_profile());
  ASSERT_TRUE(m.scan()) << m.error();
  EXPECT_EQ(m.slaves()[0].sii.mailbox_in_size, 1);
  EXPECT_FALSE(m.bring_to_operational());
  EXPECT_TRUE(error_names(m, {"slave 0", "send mailbox of 1 bytes"}));
  EXPECT_FALSE(m.slaves()[0].mailbox) << "no mailbox was set up";
}

TEST(ecat_master_hostile, a_send_mailbox_of_8_bytes_is_refused_before_any_reply_is_read) {
  // 8 bytes pass "a mailbox header and a CoE header", and then a mailbox error's code lies past them.
  hostile_line line(2);
  line.describe(1, [](slave_description& d) { d.mailbox_in_size = 8; });
  ecat_master m(line, standard_profile());
  ASSERT_TRUE(m.scan()) << m.error();
  EXPECT_FALSE(m.bring_to_pre_operational());
  EXPECT_TRUE(error_names(m, {"slave 1", "send mailbox of 8 bytes"}));
  // The same for the receive mailbox, and one larger than a datagram can carry.
  hostile_line big(1);
  big.describe(0, [](slave_description& d) { d.mailbox_out_size = 4000; });
  ecat_master m2(big, standard_profile());
  ASSERT_TRUE(m2.scan()) << m2.error();
  EXPECT_FALSE(m2.bring_to_pre_operational());
  EXPECT_TRUE(error_names(m2, {"receive mailbox of 4000 bytes"}));
}

TEST(ecat_master_hostile, status_reads_lost_by_turns_then_a_dead_line_end_the_bring_up) {
  // Two drives: slave 1's first AL status read is lost, then slave 0's second, then the line goes
  // dead. No pass has both reads succeed, yet each slave was seen in PRE-OP after the request: the
  // request is met. What follows on the dead line fails with a reason instead of waiting for ever.
  hostile_line line(2);
  line.time_limit_us = 120'000'000;
  ecat_master m(line, standard_profile());
  ASSERT_TRUE(m.scan()) << m.error();
  std::array<int, 2> reads{};
  bool dead = false;
  line.lose = [&](std::size_t i, const datagram& d) {
    if (!dead && reads[0] >= 2 && reads[1] >= 2) dead = true;
    if (dead) return true;
    if (!al_status_read(d, static_cast<std::uint16_t>(0x1001 + i))) return false;
    const int n = reads[i]++;
    return (i == 1 && n == 0) || (i == 0 && n == 1);
  };
  line.lose_frame = [&] { return dead; };
  bool pre_op = false;
  ASSERT_TRUE(hostile_line::ends([&] { pre_op = m.bring_to_pre_operational(); })) << "request_state() never returned";
  EXPECT_TRUE(pre_op) << m.error();
  EXPECT_EQ(reads[0], 2);
  EXPECT_EQ(reads[1], 2);
  dead = true;
  EXPECT_TRUE(hostile_line::ends([&] { EXPECT_FALSE(m.bring_to_operational()); }))
      << "the bring-up on a dead line never returned";
  EXPECT_TRUE(error_names(m, {"slave 0"}));
}

TEST(ecat_master_hostile, a_state_already_recorded_is_not_taken_for_an_answer) {
  // One slave, already in PRE-OP as the master recorded it: asked again with its status reads lost,
  // the master must not wait for ever, and names the slave and why.
  hostile_line line(1);
  line.time_limit_us = 120'000'000;
  ecat_master m(line, standard_profile());
  ASSERT_TRUE(m.scan()) << m.error();
  ASSERT_TRUE(m.bring_to_pre_operational()) << m.error();
  line.lose = [](std::size_t, const datagram& d) { return al_status_read(d, 0x1001); };
  bool ok = true;
  ASSERT_TRUE(hostile_line::ends([&] { ok = m.bring_to_pre_operational(); })) << "request_state() never returned";
  EXPECT_FALSE(ok);
  EXPECT_TRUE(error_names(m, {"slave 0", "did not answer a read of its AL status"}));
}

TEST(ecat_master_hostile, a_mapping_changed_in_pre_op_is_never_cycled_with_the_old_image) {
  // Scan, OP, cycles, back to PRE-OP, drive 0's outputs remapped larger (0x1C12 reassigned to
  // 0x1601 with three entries), OP again. The old image was 2 + 2 bytes of outputs; a cycle run
  // during the new mapping step wrote the new layout into it.
  hostile_line line(2);
  ecat_master m(line, standard_profile());
  ASSERT_TRUE(m.scan()) << m.error();
  ASSERT_TRUE(m.bring_to_operational()) << m.error();
  for (int i = 0; i < 10; ++i) {
    (void)m.cycle();
    line.wait_us(1000);
  }
  ASSERT_TRUE(m.bring_to_pre_operational()) << m.error();
  std::vector<std::size_t> lrw_lengths;
  m.on_frame = [&](const std::vector<std::uint8_t>& sent, const std::vector<std::uint8_t>&) {
    if (first_of(sent).cmd == command::lrw) lrw_lengths.push_back(sent[22] | ((sent[23] & 0x07) << 8));
  };
  for (const auto& [index, sub, value, bytes] :
       std::vector<std::tuple<std::uint16_t, std::uint8_t, std::int64_t, unsigned>>{
           {0x1C12, 0, 0, 1}, {0x1601, 0, 0, 1}, {0x1601, 1, 0x60400010, 4}, {0x1601, 2, 0x60600008, 4},
           {0x1601, 3, 0x607A0020, 4}, {0x1601, 0, 3, 1}, {0x1C12, 1, 0x1601, 2}, {0x1C12, 0, 1, 1}}) {
    const ecat_sdo_result r = m.sdo_write(0, index, sub, value, bytes);
    ASSERT_TRUE(r.ok) << std::hex << index << ":" << int(sub) << " " << r.error;
  }
  ASSERT_TRUE(m.bring_to_operational()) << m.error();
  const ecat_slave& s = m.slaves()[0];
  EXPECT_EQ(s.output_bytes, 7);
  const std::size_t image = 7u + s.input_bytes + m.slaves()[1].output_bytes + m.slaves()[1].input_bytes;
  ASSERT_FALSE(lrw_lengths.empty());
  for (const std::size_t length : lrw_lengths) EXPECT_EQ(length, image) << "a cycle ran on the image of the mapping before";
  ASSERT_TRUE(m.set_output(0, 0x607A, 12345));
  // Leaving OP counted as a lost connection (0x6007): the words reset that fault on the way.
  for (int i = 0; i < 400 && (m.slaves()[0].last_status & 0x006F) != 0x0027; ++i) {
    testing::send_enable_word(m, 0);
    (void)m.cycle();
    line.wait_us(1000);
  }
  EXPECT_TRUE(m.slaves()[0].last_status & 0x0004) << "enabled through the new layout: status " << std::hex
                                                   << m.slaves()[0].last_status << " error code " << m.slaves()[0].last_error_code << " " << m.error();
  std::int64_t target = 0;
  ASSERT_EQ(line.slaves[0]->device().read(0x607A, 0, target), sdo_abort::none);
  EXPECT_EQ(target, 12345) << "the new entry reaches the drive";
}

TEST(ecat_master_hostile, a_cycle_before_any_bring_up_is_refused_and_sends_nothing) {
  hostile_line line(1);
  ecat_master m(line, standard_profile());
  EXPECT_FALSE(m.cycle());
  EXPECT_TRUE(error_names(m, {"bring the line to OP first"}));
  EXPECT_EQ(line.frames, 0u);
  ASSERT_TRUE(m.scan()) << m.error();
  const std::uint64_t after_scan = line.frames;
  EXPECT_FALSE(m.cycle()) << "scanned, not brought up";
  EXPECT_EQ(line.frames, after_scan);
  ASSERT_TRUE(m.bring_to_pre_operational()) << m.error();
  const std::uint64_t in_pre_op = line.frames;
  EXPECT_FALSE(m.cycle()) << "PRE-OP has no process data";
  EXPECT_EQ(line.frames, in_pre_op);
  EXPECT_EQ(m.cycles(), 0u);
}

// The data of the first SDO information fragment of kind `op` a frame on its way back brings from
// a slave's send mailbox (at `send_mailbox`): the information header's first byte, in the frame.
std::uint8_t* info_fragment(std::vector<std::uint8_t>& frame, std::uint16_t send_mailbox, sdo_info_opcode op) {
  parsed_frame parsed;
  if (parse_frame(frame, parsed) != frame_error::none) return nullptr;
  for (std::size_t k = 0; k < parsed.count; ++k) {
    const datagram& d = parsed.datagrams[k];
    if (d.cmd != command::fprd || d.offset() != send_mailbox || d.working_counter() != 1 || d.length < 16) continue;
    // Mailbox header (6 bytes: type CoE = 3 in byte 5), CoE header (service 8 in byte 7's top), then
    // the information header: opcode | incomplete, reserved, fragments left.
    if ((d.data[5] & 0x0F) != 3 || (d.data[7] >> 4) != 8 || (d.data[8] & 0x7F) != static_cast<std::uint8_t>(op)) continue;
    return d.data + 8;
  }
  return nullptr;
}

// A slave's SDO information is its word as much as any length: fragments that do not count down,
// a description of another object, a mailbox that never answers each end the read with the reason.
TEST(ecat_master_hostile, sdo_information_that_does_not_add_up_ends_the_dictionary_read_with_the_reason) {
  {
    hostile_line line(1);
    ecat_master m(line, standard_profile());
    ASSERT_TRUE(m.scan() && m.bring_to_pre_operational()) << m.error();
    const std::uint16_t mailbox = m.slaves()[0].sii.mailbox_in_start;
    bool tampered = false;
    line.tamper = [&](std::vector<std::uint8_t>& frame) {
      std::uint8_t* h = info_fragment(frame, mailbox, sdo_info_opcode::od_list_response);
      if (h == nullptr || tampered || (h[0] & 0x80) == 0) return;
      h[2] = static_cast<std::uint8_t>(h[2] + 2);  // the first of the list's fragments says two more are left
      tampered = true;
    };
    const ecat_dictionary_result r = m.read_dictionary(0);
    ASSERT_TRUE(tampered) << "the object list takes more than one fragment";
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.error.find("fragments out of order"), std::string::npos) << r.error;
  }
  {
    hostile_line line(1);
    ecat_master m(line, standard_profile());
    ASSERT_TRUE(m.scan() && m.bring_to_pre_operational()) << m.error();
    const std::uint16_t mailbox = m.slaves()[0].sii.mailbox_in_start;
    line.tamper = [&](std::vector<std::uint8_t>& frame) {
      std::uint8_t* h = info_fragment(frame, mailbox, sdo_info_opcode::object_description_response);
      if (h != nullptr) h[4] = static_cast<std::uint8_t>(h[4] ^ 0x01);  // another index
    };
    const ecat_dictionary_result r = m.read_dictionary(0);
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.error.find("described another object"), std::string::npos) << r.error;
  }
  {
    hostile_line line(1);
    ecat_master m(line, standard_profile());
    ASSERT_TRUE(m.scan() && m.bring_to_pre_operational()) << m.error();
    const std::uint16_t mailbox = m.slaves()[0].sii.mailbox_in_start;
    line.lose_answer = [&](const std::vector<std::uint8_t>& frame) {
      std::vector<std::uint8_t> copy = frame;
      return info_fragment(copy, mailbox, sdo_info_opcode::od_list_response) != nullptr;
    };
    line.time_limit_us = line.now + 60'000'000;
    ecat_dictionary_result r;
    EXPECT_TRUE(hostile_line::ends([&] { r = m.read_dictionary(0); })) << "every wait for the slave ends";
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.error.find("slave 0"), std::string::npos) << r.error;
  }
}

}  // namespace
}  // namespace cia402::ethercat

namespace cia402::ethercat {
namespace {

// ETG.1000.4 mailbox repeat, master side: a read that emptied the send mailbox but whose answer was
// lost leaves nothing to read; the master toggles SM1's repeat request (0x080E bit 1), waits for the
// repeat acknowledge (0x080F bit 1) and reads the reply again, instead of waiting out its timeout.
TEST(ecat_master_mailbox_repeat, a_reply_whose_answer_was_lost_is_read_again_after_a_repeat_request) {
  hostile_line line(2);
  ecat_master m(line, standard_profile());
  ASSERT_TRUE(m.scan()) << m.error();
  ASSERT_TRUE(m.bring_to_pre_operational()) << m.error();
  const std::uint16_t station = m.slaves()[1].station;
  const std::uint16_t send_mailbox = m.slaves()[1].sii.mailbox_in_start;
  int lost = 0;
  std::vector<std::uint8_t> repeat_writes;
  line.lose_answer = [&](const std::vector<std::uint8_t>& frame) {
    parsed_frame parsed;
    std::vector<std::uint8_t> copy = frame;
    if (parse_frame(copy, parsed) != frame_error::none) return false;
    for (std::size_t k = 0; k < parsed.count; ++k) {
      const datagram& d = parsed.datagrams[k];
      if (d.position() != station) continue;
      if (d.cmd == command::fpwr && d.offset() <= 0x080E && d.offset() + d.length > 0x080E) {
        repeat_writes.push_back(d.data[0x080E - d.offset()]);
      }
      if (d.cmd == command::fprd && d.offset() == send_mailbox && d.working_counter() == 1 && lost == 0) {
        ++lost;  // the reply left the slave's mailbox, its bytes never reach the master
        return true;
      }
    }
    return false;
  };
  const ecat_sdo_result r = m.sdo_read(1, 0x1018, 2);
  EXPECT_EQ(lost, 1);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.value(false), 0x402);
  ASSERT_EQ(repeat_writes.size(), 1u) << "one repeat request";
  EXPECT_EQ(repeat_writes[0] & 0x02, 0x02) << "bit 1 of 0x080E toggled from 0";
  // A second loss: the repeat request toggles back.
  lost = 0;
  repeat_writes.clear();
  const ecat_sdo_result again = m.sdo_read(1, 0x1018, 1);
  ASSERT_TRUE(again.ok) << again.error;
  ASSERT_EQ(repeat_writes.size(), 1u);
  EXPECT_EQ(repeat_writes[0] & 0x02, 0x00);
}

}  // namespace
}  // namespace cia402::ethercat
