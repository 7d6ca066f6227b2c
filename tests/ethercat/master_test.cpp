// Our EtherCAT master against a line of virtual drives on the in-process wire, on virtual time:
// scan and SII, bring-up to OP with the mapping learnt over CoE, each drive's control and status
// words carried in the process data (the words of enable, quick stop and fault reset, an injected
// fault's error code and EMCY), SDO with aborts, the watchdog when the master stops, and a slave
// that refuses a state. The master carries words and steers nothing: the steering of these drives
// is the axis session's, tested over ecat_link in ecat_session_steering_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <tuple>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/master.hpp"
#include "cia402/profile.hpp"
#include "drive_line.hpp"
#include "enable_words.hpp"

namespace cia402::ethercat {
namespace {

using wire_link = testing::drive_line;

// Cycles (1 ms each) until `done` or the limit; the number of cycles, or -1.
template <typename F>
int run_until(ecat_master& m, wire_link& link, F done, int limit = 5000) {
  for (int i = 1; i <= limit; ++i) {
    (void)m.cycle();
    link.wait_us(1000);
    if (done()) return i;
  }
  return -1;
}

state shown(const ecat_slave& s) {
  state st = state::start;
  EXPECT_TRUE(decode_status(standard_profile(), s.last_status, st)) << s.last_status;
  return st;
}

// Cycles with each of `drives` sent the word that leads it towards OPERATION ENABLED
// (enable_words.hpp) until all show it; the number of cycles, or -1.
int enable(ecat_master& m, wire_link& link, const std::vector<std::size_t>& drives, int limit = 5000) {
  for (int i = 1; i <= limit; ++i) {
    for (const std::size_t d : drives) testing::send_enable_word(m, d);
    (void)m.cycle();
    link.wait_us(1000);
    if (std::all_of(drives.begin(), drives.end(), [&](std::size_t d) { return shown(m.slaves()[d]) == state::operation_enabled; })) {
      return i;
    }
  }
  return -1;
}

std::vector<std::size_t> first(std::size_t n) {
  std::vector<std::size_t> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(i);
  return v;
}

struct line {
  wire_link link;
  ecat_master master;
  explicit line(int drives) : link(drives), master(link, standard_profile()) {}
  void up() {
    ASSERT_TRUE(master.scan()) << master.error();
    ASSERT_TRUE(master.bring_to_operational()) << master.error();
    // One cycle more: the first inputs of OP are in.
    (void)master.cycle();
    link.wait_us(1000);
    (void)master.cycle();
  }
  bool all(state target) {
    for (const ecat_slave& s : master.slaves()) {
      if (shown(s) != target) return false;
    }
    return true;
  }
};

TEST(ecat_master, scan_addresses_every_slave_and_reads_its_sii) {
  line l(3);
  ASSERT_TRUE(l.master.scan()) << l.master.error();
  ASSERT_EQ(l.master.slaves().size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const ecat_slave& s = l.master.slaves()[i];
    EXPECT_EQ(s.position, i);
    EXPECT_EQ(s.station, 0x1001 + i);
    EXPECT_EQ(l.link.slaves[i]->controller().read16(0x0010), 0x1001 + i) << "the station address is in the ESC";
    const slave_description& own = l.link.slaves[i]->description();
    EXPECT_EQ(s.sii.vendor_id, own.vendor_id);
    EXPECT_EQ(s.sii.product_code, own.product_code);
    EXPECT_EQ(s.sii.serial, i + 1) << "read from each slave's own EEPROM";
    EXPECT_EQ(s.sii.device_name, own.device_name);
    EXPECT_EQ(s.al_state & 0x0F, 1) << "INIT";
  }
}

TEST(ecat_master, no_slave_and_no_line_are_errors_that_say_so) {
  wire_link empty(0);
  ecat_master m(empty, standard_profile());
  EXPECT_FALSE(m.scan());
  EXPECT_NE(m.error().find("no slave answered"), std::string::npos) << m.error();
  wire_link cut(2);
  cut.cut = true;
  ecat_master m2(cut, standard_profile());
  EXPECT_FALSE(m2.scan());
  EXPECT_NE(m2.error().find("no frame came back"), std::string::npos) << m2.error();
}

TEST(ecat_master, brings_the_line_to_op_with_the_mapping_it_learnt_over_coe) {
  line l(4);
  l.up();
  EXPECT_EQ(l.master.expected_working_counter(), 4 * 3) << "each slave: +2 write FMMU, +1 read FMMU";
  EXPECT_EQ(l.master.last_working_counter(), 4 * 3);
  for (std::size_t i = 0; i < 4; ++i) {
    const ecat_slave& s = l.master.slaves()[i];
    EXPECT_EQ(l.link.slaves[i]->state(), al_state::operational);
    EXPECT_EQ(s.mapping_source, "CoE 0x1C12/0x1C13");
    EXPECT_EQ(s.output_bytes, l.link.slaves[i]->output_bytes());
    EXPECT_EQ(s.input_bytes, l.link.slaves[i]->input_bytes());
    ASSERT_TRUE(s.control_word && s.status_word && s.position_actual);
    EXPECT_EQ(s.control_word->bit_offset, 0);
    EXPECT_EQ(s.status_word->bit_offset, 0);
    EXPECT_EQ(shown(s), state::switch_on_disabled);
  }
}

TEST(ecat_master, a_changed_mapping_is_found_where_the_drive_puts_it) {
  line l(1);
  auto& m = l.master;
  ASSERT_TRUE(m.scan());
  ASSERT_TRUE(m.bring_to_pre_operational()) << m.error();
  // TxPDO 0x1A00 = 0x6064, 0x6041: the status word second. A master that assumed the default
  // layout would read the position's low half as the status word.
  for (const auto& [index, sub, value, bytes] :
       std::vector<std::tuple<std::uint16_t, std::uint8_t, std::int64_t, unsigned>>{
           {0x1C13, 0, 0, 1}, {0x1A00, 0, 0, 1}, {0x1A00, 1, 0x60640020, 4}, {0x1A00, 2, 0x60410010, 4},
           {0x1A00, 0, 2, 1}, {0x1C13, 0, 1, 1}}) {
    const ecat_sdo_result r = m.sdo_write(0, index, sub, value, bytes);
    ASSERT_TRUE(r.ok) << r.error;
  }
  ASSERT_TRUE(m.bring_to_operational()) << m.error();
  const ecat_slave& s = m.slaves()[0];
  EXPECT_EQ(s.input_bytes, 6);
  EXPECT_EQ(s.position_actual->bit_offset, 0);
  EXPECT_EQ(s.status_word->bit_offset, 32);
  EXPECT_FALSE(s.error_code) << "0x603F is no longer mapped";
  EXPECT_GT(enable(m, l.link, {0}), 0) << "the control word out and the status word back where the mapping puts them";
  EXPECT_EQ(m.sdo_write(0, 0x1C13, 0, 0, 1).ok, false) << "PDO assignment is refused outside PRE-OP";
}

TEST(ecat_master, carries_every_drives_words_of_enable_quick_stop_fault_and_reset_over_process_data) {
  line l(16);
  l.up();
  EXPECT_GT(enable(l.master, l.link, first(16)), 0);
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(l.link.slaves[i]->device().drive().view().current(), state::operation_enabled) << "the drive's own state";
  }
  // Quick stop on every drive: QUICK STOP ACTIVE, then (0x605A = 2) SWITCH ON DISABLED at standstill.
  for (std::size_t i = 0; i < 16; ++i) l.master.send_control_word(i, control_bit::enable_voltage);  // Quick stop
  bool passed_quick_stop = false;
  EXPECT_GT(run_until(l.master, l.link, [&] {
              passed_quick_stop = passed_quick_stop || shown(l.master.slaves()[0]) == state::quick_stop_active;
              return l.all(state::switch_on_disabled);
            }),
            0);
  EXPECT_TRUE(passed_quick_stop);
  // A fault injected in drive 5 (0x2001 over the mailbox): FAULT there alone, its EMCY arrives.
  ASSERT_GT(enable(l.master, l.link, first(16)), 0);
  ASSERT_TRUE(l.master.sdo_write(5, 0x2001, 0, 0x2310, 2).ok);
  EXPECT_GT(run_until(l.master, l.link, [&] { return shown(l.master.slaves()[5]) == state::fault; }), 0);
  EXPECT_EQ(l.master.slaves()[5].last_error_code, 0x2310) << "0x603F in the process data";
  EXPECT_EQ(shown(l.master.slaves()[4]), state::operation_enabled) << "the others run on";
  // Reset once the cause is gone: the fault-reset edge, then SWITCH ON DISABLED.
  ASSERT_TRUE(l.master.sdo_write(5, 0x2001, 0, 0, 2).ok);
  ASSERT_EQ(l.master.slaves()[5].last_control & control_bit::fault_reset, 0);
  l.master.send_control_word(5, control_bit::fault_reset);  // bit 7 rising
  EXPECT_GT(run_until(l.master, l.link, [&] { return shown(l.master.slaves()[5]) == state::switch_on_disabled; }), 0);
  EXPECT_EQ(l.master.slaves()[5].last_error_code, 0);
  const auto& emcy = l.master.slaves()[5].emergencies;
  EXPECT_NE(std::find(emcy.begin(), emcy.end(), 0x2310), emcy.end()) << "the EMCY came with the next SDO";
  EXPECT_TRUE(l.master.slaves()[4].emergencies.empty());
  EXPECT_EQ(l.master.last_working_counter(), 16 * 3);
}

TEST(ecat_master, a_line_whose_image_one_frame_cannot_hold_runs_in_several_frames_a_cycle) {
  // 64 drives with the default mapping: 2,048 bytes of process data, more than a frame's 1,500.
  line l(64);
  l.up();
  std::size_t image = 0;
  for (const ecat_slave& s : l.master.slaves()) image += std::size_t{s.output_bytes} + s.input_bytes;
  ASSERT_GT(image, 1500u);
  EXPECT_EQ(l.master.expected_working_counter(), 64 * 3);
  EXPECT_EQ(l.master.last_working_counter(), 64 * 3) << "every part's LRW reached its slaves";
  ASSERT_GT(enable(l.master, l.link, first(64)), 0) << "every drive's words, in whichever frame, out and back";
  for (std::size_t i = 0; i < 64; ++i) {
    EXPECT_EQ(l.link.slaves[i]->device().drive().view().current(), state::operation_enabled) << i;
  }
  // One cycle: its frames, each within the Ethernet maximum, the LRWs covering the image once.
  std::size_t frames = 0, largest = 0;
  l.master.on_frame = [&](const std::vector<std::uint8_t>& sent, const std::vector<std::uint8_t>&) {
    ++frames;
    largest = std::max(largest, sent.size());
  };
  ASSERT_TRUE(l.master.cycle()) << l.master.error();
  l.master.on_frame = nullptr;
  EXPECT_GE(frames, (image + 1499) / 1500);
  EXPECT_LE(largest, 1514u);
  // A drive in the last part that stops taking its outputs (its FMMU 0 deactivated, 0x060C, behind
  // the master's back): the cycle fails, and the error names that part's LRW, not only the line's sum.
  frame_builder b({0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}, {0x02, 0x00, 0x00, 0x00, 0x00, 0x02});
  const std::uint16_t station = l.master.slaves()[63].station;
  const std::vector<std::uint8_t> off{0x00};
  ASSERT_GE(b.add(command::fpwr, 0x55, station | (std::uint32_t{0x060C} << 16), off, 1), 0);
  std::vector<std::uint8_t> request = b.finish();
  ASSERT_EQ(l.link.wire.pass(request), frame_error::none);
  l.link.wait_us(1000);
  bool failed = false;
  for (int i = 0; i < 5 && !failed; ++i) {
    failed = !l.master.cycle();
    l.link.wait_us(1000);
  }
  ASSERT_TRUE(failed);
  EXPECT_NE(l.master.error().find("of the LRW of image bytes"), std::string::npos) << l.master.error();
  EXPECT_EQ(l.master.error().find("image bytes 0.."), std::string::npos) << "the first part is whole: " << l.master.error();
}

TEST(ecat_master, cyclic_synchronous_position_over_the_process_data_at_1_ms) {
  // Mode 8 in 0x6060 and a ramp of 0x607A in the RxPDO, one set-point a cycle; 0x6064 and 0x6061
  // come back in the TxPDO. 100 increments a ms is 600 rpm at 10,000 increments a revolution.
  line l(2);
  l.up();
  auto& m = l.master;
  ASSERT_TRUE(m.set_output(1, 0x6060, 8));
  ASSERT_GT(enable(m, l.link, {1}), 0);
  ASSERT_EQ(m.input(1, 0x6061), 8) << "the mode display in the process data";
  const std::int64_t start = *m.input(1, 0x6064);
  std::int64_t max_error = 0;
  for (int k = 1; k <= 500; ++k) {
    ASSERT_TRUE(m.set_output(1, 0x607A, start + 100 * k));
    (void)m.cycle();
    l.link.wait_us(1000);
    // Once the shaft is up to speed (the plant's acceleration limit takes the first cycles), the
    // inputs show the drive on the set-point two cycles before (it took it, then reported).
    if (k > 50) max_error = std::max<std::int64_t>(max_error, std::llabs(*m.input(1, 0x6064) - (start + 100 * (k - 2))));
    if (k == 400) EXPECT_EQ(m.input(1, 0x606C), 600) << "600 rpm while streaming, in the process data";
  }
  for (int k = 0; k < 5; ++k) {
    (void)m.cycle();
    l.link.wait_us(1000);
  }
  EXPECT_EQ(*m.input(1, 0x6064), start + 50000) << "followed to the last set-point";
  EXPECT_LE(max_error, 100) << "within one set-point of the stream";
  EXPECT_EQ(shown(m.slaves()[1]), state::operation_enabled) << "no following error fault";
  EXPECT_EQ(*m.input(0, 0x6064), 0) << "the other drive did not move";
  EXPECT_FALSE(m.set_output(1, 0x6081, 1)) << "0x6081 is not in the RxPDO";
  EXPECT_FALSE(m.input(1, 0x6081));
}

TEST(ecat_master, a_long_run_of_sdo_transfers_keeps_the_process_data_flowing) {
  // Each frame takes 3 ms to come back: 40 SDO uploads in a row take far longer than the drives'
  // 100 ms watchdog. The master runs its cycles between the mailbox frames, so no drive leaves OP,
  // and a control word sent before the transfers reaches its drive in those cycles.
  line l(4);
  l.up();
  l.master.send_control_word(2, control_bit::enable_voltage | control_bit::quick_stop);  // Shutdown
  l.link.exchange_us = 3000;
  for (int k = 0; k < 40; ++k) {
    const ecat_sdo_result r = l.master.sdo_read(static_cast<std::size_t>(k % 4), 0x6083, 0);
    ASSERT_TRUE(r.ok) << r.error;
  }
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(l.link.slaves[i]->state(), al_state::operational) << "slave " << i;
  }
  EXPECT_EQ(l.link.slaves[2]->device().drive().view().current(), state::ready_to_switch_on) << "the word went out meanwhile";
  EXPECT_EQ(shown(l.master.slaves()[2]), state::ready_to_switch_on) << "and its status word came back";
  EXPECT_EQ(shown(l.master.slaves()[1]), state::switch_on_disabled) << "the others had their own words";
}

TEST(ecat_master, the_cycle_runs_while_the_line_goes_to_op) {
  // Each frame takes 3 ms to come back, and 24 slaves are asked for SAFE-OP and OP one by one.
  // The outputs' watchdog runs from the moment the sync managers are set up. The master used to
  // send its first LRW only once a state took more than one pass of status reads, and each cycle
  // before the line was in OP read every slave's AL status: a round trip per slave between LRWs,
  // which a loaded host stretched past the 100 ms watchdog (AL status 0x001B, the veth test's line
  // of 16 in CI). So the first LRW goes out before any slave is asked for OP, and from then on no
  // two are further apart than a cycle and the round trip in between.
  line l(24);
  ASSERT_TRUE(l.master.scan()) << l.master.error();
  l.link.exchange_us = 3000;
  std::uint64_t first_lrw = 0;
  std::uint64_t last_lrw = 0;
  std::uint64_t widest_gap = 0;
  std::uint64_t first_op_request = 0;
  l.master.on_frame = [&](const std::vector<std::uint8_t>& sent, const std::vector<std::uint8_t>&) {
    if (sent.size() <= 26) return;
    const std::uint8_t command = sent[16];  // the first datagram's, after the Ethernet and EtherCAT headers
    const unsigned offset = sent[20] | (sent[21] << 8);
    if (command == 5 && offset == 0x0120 && (sent[26] & 0x0F) == 8 && first_op_request == 0) {
      first_op_request = l.link.now;
    }
    if (command != 12) return;
    if (last_lrw == 0) first_lrw = l.link.now;
    if (last_lrw != 0) widest_gap = std::max(widest_gap, l.link.now - last_lrw);
    last_lrw = l.link.now;
  };
  ASSERT_TRUE(l.master.bring_to_operational()) << l.master.error();
  ASSERT_NE(first_lrw, 0u) << "no LRW while the line went to OP";
  ASSERT_NE(first_op_request, 0u);
  EXPECT_LT(first_lrw, first_op_request);
  EXPECT_LE(widest_gap, 1000u + 2 * 3000u);
  for (int i = 0; i < 50; ++i) {
    (void)l.master.cycle();
    l.link.wait_us(1000);
  }
  for (std::size_t i = 0; i < 24; ++i) {
    EXPECT_EQ(l.link.slaves[i]->state(), al_state::operational) << "slave " << i;
  }
}

TEST(ecat_master, the_outputs_start_as_the_drive_has_them) {
  line l(1);
  ASSERT_TRUE(l.master.scan());
  // The drive holds mode 3 (pv) and a target velocity: running the line must not zero them.
  auto& v = l.link.slaves[0]->device();
  ASSERT_EQ(v.write(0x6060, 0, 3), sdo_abort::none);
  ASSERT_EQ(v.write(0x60FF, 0, 700), sdo_abort::none);
  l.up();
  for (int i = 0; i < 20; ++i) {
    (void)l.master.cycle();
    l.link.wait_us(1000);
  }
  std::int64_t mode = 0, target = 0;
  ASSERT_EQ(v.read(0x6060, 0, mode), sdo_abort::none);
  ASSERT_EQ(v.read(0x60FF, 0, target), sdo_abort::none);
  EXPECT_EQ(mode, 3);
  EXPECT_EQ(target, 700);
  EXPECT_EQ(shown(l.master.slaves()[0]), state::switch_on_disabled) << "watching commands nothing";
}

TEST(ecat_master, sdo_reads_writes_and_reports_aborts_in_words) {
  line l(2);
  l.up();
  const ecat_sdo_result id = l.master.sdo_read(1, 0x1018, 4);
  ASSERT_TRUE(id.ok) << id.error;
  EXPECT_EQ(id.value(false), 2) << "serial of the second drive";
  const ecat_sdo_result missing = l.master.sdo_read(0, 0x5555, 0);
  EXPECT_FALSE(missing.ok);
  EXPECT_TRUE(missing.aborted);
  EXPECT_EQ(missing.abort, sdo_abort::object_does_not_exist);
  EXPECT_NE(missing.error.find("0x06020000"), std::string::npos) << missing.error;
  ASSERT_TRUE(l.master.sdo_write(0, 0x6083, 0, 2500, 4).ok);
  EXPECT_EQ(l.master.sdo_read(0, 0x6083, 0).value(false), 2500);
  const ecat_sdo_result range = l.master.sdo_write(0, 0x605A, 0, 100, 2);
  EXPECT_FALSE(range.ok) << "a quick stop option code out of range is refused, as on CAN";
  EXPECT_TRUE(range.aborted);
  EXPECT_EQ(range.abort, sdo_abort::invalid_value) << "0x605A takes only the codes the profile defines";
}

// The parameter list a tool shows over EtherCAT: every object the slave has, read through CoE SDO
// information while the line runs in OP, as the slave's own dictionary has it.
TEST(ecat_master, reads_the_slaves_whole_dictionary_through_sdo_information) {
  line l(2);
  l.up();
  const ecat_dictionary_result r = l.master.read_dictionary(1);
  ASSERT_TRUE(r.ok) << r.error;
  const std::vector<dictionary::object_entry>& own = l.link.slaves[1]->slave().dictionary().table();
  ASSERT_EQ(r.objects.size(), own.size());
  EXPECT_GT(own.size(), 40u) << "the communication objects and the drive's";
  for (std::size_t k = 0; k < own.size(); ++k) {
    const ecat_object_description& o = r.objects[k];
    const dictionary::object_entry& t = own[k];
    SCOPED_TRACE("object 0x" + std::to_string(t.index));
    EXPECT_EQ(o.index, t.index);
    EXPECT_EQ(o.name, t.name);
    EXPECT_EQ(o.object_code, static_cast<std::uint8_t>(t.code));
    ASSERT_EQ(o.entries.size(), t.subs.size()) << "every sub-index, and no other";
    for (std::size_t e = 0; e < t.subs.size(); ++e) {
      const dictionary::sub_entry& want = t.subs[e];
      EXPECT_EQ(o.entries[e].sub, want.sub);
      EXPECT_EQ(o.entries[e].name, want.name);
      EXPECT_EQ(o.entries[e].data_type, static_cast<std::uint16_t>(want.type));
      if (type_size(want.type) != 0) EXPECT_EQ(o.entries[e].bit_length, 8 * type_size(want.type));
      EXPECT_EQ((o.entries[e].access & 0x0007) != 0, dictionary::readable(want.acc)) << int(want.sub);
      EXPECT_EQ((o.entries[e].access & 0x0038) != 0, dictionary::writable(want.acc)) << int(want.sub);
      EXPECT_EQ((o.entries[e].access & 0x00C0) != 0, want.pdo_mappable) << int(want.sub);
    }
  }
  EXPECT_TRUE(l.all(state::switch_on_disabled));
  EXPECT_TRUE(l.master.cycle()) << "the process data ran on meanwhile: " << l.master.error();
  const ecat_dictionary_result none = l.master.read_dictionary(7);
  EXPECT_FALSE(none.ok);
  EXPECT_NE(none.error.find("no slave 7"), std::string::npos) << none.error;
}

TEST(ecat_master, a_master_that_stops_leaves_the_drives_to_their_watchdog) {
  line l(2);
  l.up();
  ASSERT_GT(enable(l.master, l.link, {0}), 0);
  l.link.wait_us(200'000);  // no frames for 200 ms: past the 100 ms process data watchdog
  EXPECT_EQ(l.link.slaves[0]->state(), al_state::safe_operational);
  (void)l.master.cycle();
  const ecat_slave& s = l.master.slaves()[0];
  EXPECT_EQ(s.al_state, 0x14) << "SAFE-OP with the error bit";
  EXPECT_EQ(s.al_code, 0x001B);
  EXPECT_STREQ(al_status_code_text(s.al_code), "sync manager watchdog");
  // The drive lost its master (0x6007 = 1 by default: a fault, 0x8130 heartbeat/connection error).
  for (int i = 0; i < 50; ++i) l.link.wait_us(1000);
  EXPECT_EQ(l.link.slaves[0]->device().drive().view().current(), state::fault);
}

TEST(ecat_master, configures_distributed_clocks_and_runs_the_drives_on_sync0) {
  // ETG.1000.4 §9.1 on a line of 3 whose controllers were powered on at different times.
  line l(3);
  l.link.slaves[1]->controller().advance(3'000'000);
  l.link.slaves[2]->controller().advance(11'500'000);
  l.up();
  ASSERT_EQ(l.master.dc_reference(), std::optional<std::size_t>{0});
  const std::uint64_t reference = l.link.slaves[0]->controller().system_time();
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(l.link.slaves[i]->controller().system_time(), reference) << "one system time on the line";
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const ecat_slave& s = l.master.slaves()[i];
    EXPECT_TRUE(s.dc && s.sync0) << i;
    EXPECT_EQ(s.dc_delay_ns, i * l.link.wire.hop_delay_ns) << "the hops measured from the receive times";
    esc& e = l.link.slaves[i]->controller();
    EXPECT_TRUE(e.sync0_active());
    EXPECT_EQ(e.read32(reg::dc_sync0_cycle_time), 1'000'000u) << "SYNC0 at the master's cycle";
    EXPECT_EQ(e.read32(reg::dc_system_time_difference), 0u) << "the cyclic drift distribution finds none";
    const ecat_sdo_result mode = l.master.sdo_read(i, 0x1C32, 1);
    ASSERT_TRUE(mode.ok) << mode.error;
    EXPECT_EQ(mode.value(false), 2) << "the drive runs DC SYNC0";
  }
  EXPECT_GT(enable(l.master, l.link, first(3)), 0) << "the drives follow their words on SYNC0";
}

TEST(ecat_master, a_cycle_shorter_than_a_drive_can_run_leaves_it_free_running) {
  wire_link link(1);
  ecat_master m(link, standard_profile(), 500);  // 0x1C32:05 is the drive's 1 ms step
  ASSERT_TRUE(m.scan()) << m.error();
  ASSERT_TRUE(m.bring_to_operational()) << m.error();
  EXPECT_TRUE(m.slaves()[0].dc);
  EXPECT_FALSE(m.slaves()[0].sync0);
  EXPECT_FALSE(link.slaves[0]->controller().sync0_active());
  EXPECT_EQ(m.sdo_read(0, 0x1C32, 1).value(false), 0) << "free run";
}

}  // namespace
}  // namespace cia402::ethercat
