// The virtual drive as an EtherCAT slave, driven through frames on the in-process wire as a master
// drives it: SII identity, the AL state machine and its refusals, CoE SDO through the mailbox, the
// process data in OP (enable the drive, read its status word), the watchdog, emergencies.
#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "drive_bench.hpp"

namespace cia402::ethercat {
namespace {

using testing::bench;
using testing::station;

TEST(drive_slave, powers_up_in_init_and_its_sii_names_the_drive) {
  bench b;
  b.run(5);
  EXPECT_EQ(b.send(command::aprd, static_cast<std::uint32_t>(reg::al_status) << 16, {0, 0}).data[0], 1);
  std::vector<std::uint8_t> words;
  for (std::uint32_t w = 8; w < 16; w += 4) {
    b.send(command::apwr, static_cast<std::uint32_t>(reg::eeprom_address) << 16,
           {static_cast<std::uint8_t>(w), 0, 0, 0});
    b.send(command::apwr, static_cast<std::uint32_t>(reg::eeprom_control) << 16, {0x00, 0x01});
    const auto a = b.send(command::aprd, static_cast<std::uint32_t>(reg::eeprom_data) << 16, std::vector<std::uint8_t>(8, 0));
    words.insert(words.end(), a.data.begin(), a.data.end());
  }
  EXPECT_EQ(words[4] | (words[5] << 8), 0x0402) << "product code";
  EXPECT_EQ(words[12], 7) << "serial";
}

TEST(drive_slave, the_al_state_machine_refuses_what_its_configuration_cannot_run) {
  bench b;
  EXPECT_EQ(b.send(command::apwr, static_cast<std::uint32_t>(reg::station_address) << 16, {0x01, 0x10}).wkc, 1);
  EXPECT_EQ(b.request(2), 0x11) << "no mailbox sync managers yet: PRE-OP refused, INIT kept, error flag";
  EXPECT_EQ(b.read16(reg::al_status_code), al_code::invalid_mailbox_configuration);
  EXPECT_EQ(b.request(0x11), 1) << "INIT with the acknowledge clears the error";
  EXPECT_EQ(b.read16(reg::al_status_code), 0);
  b.sync_manager(0, b.slave.description().sync_managers[0]);
  b.sync_manager(1, b.slave.description().sync_managers[1]);
  EXPECT_EQ(b.request(3), 0x11) << "BOOT is refused";
  EXPECT_EQ(b.read16(reg::al_status_code), al_code::bootstrap_not_supported);
  EXPECT_EQ(b.request(0x12), 2);
  EXPECT_EQ(b.request(8), 0x12) << "OP from PRE-OP skips SAFE-OP";
  EXPECT_EQ(b.read16(reg::al_status_code), al_code::invalid_state_change);
  EXPECT_EQ(b.request(0x14), 0x12) << "SAFE-OP without process data sync managers";
  EXPECT_EQ(b.read16(reg::al_status_code), al_code::invalid_output_configuration);
}

TEST(drive_slave, coe_reads_and_writes_the_drive_and_guards_the_pdo_configuration) {
  bench b;
  b.to_pre_op();
  EXPECT_EQ(b.upload(0x1018, 2), 0x402);
  EXPECT_EQ(b.upload(0x1018, 4), 7);
  EXPECT_EQ(b.upload(0x6502, 0), 0x3AD);
  EXPECT_EQ(b.download(0x6060, 0, 8, 1), 0u);
  EXPECT_EQ(b.upload(0x6060, 0), 8);
  EXPECT_EQ(b.download(0x6060, 0, 2, 1), 0x06090030u) << "a mode the drive does not announce";
  EXPECT_EQ(b.download(0x1A00, 1, 0x60400010, 4), 0x06040041u) << "the control word is no input";
  EXPECT_EQ(b.download(0x1C12, 1, 0x1A00, 2), 0x06090030u) << "only RxPDOs go to 0x1C12";
  EXPECT_EQ(b.download(0x1601, 1, 0x60710010, 4), 0u) << "target torque into RxPDO 2";
  b.to_op();
  EXPECT_EQ(b.download(0x1601, 1, 0x60FF0020, 4), 0x08000022u) << "mappings are written in PRE-OP only";
}

TEST(drive_slave, in_op_the_process_data_enable_the_drive) {
  bench b;
  b.to_op();
  std::uint16_t sw = 0;
  for (std::uint16_t cw : {0x0006, 0x0007, 0x000F}) {
    for (int i = 0; i < 40; ++i) sw = b.cycle(cw);
  }
  EXPECT_EQ(sw & 0x6F, 0x27) << "OPERATION ENABLED";
  EXPECT_EQ(b.slave.device().drive().view().current(), state::operation_enabled);
}

TEST(drive_slave, a_silent_master_trips_the_watchdog_and_0x6007_acts) {
  bench b;
  b.to_op();
  for (std::uint16_t cw : {0x0006, 0x0007, 0x000F}) {
    for (int i = 0; i < 40; ++i) b.cycle(cw);
  }
  b.run(150);  // no outputs for 150 ms; the watchdog is 100 ms
  EXPECT_EQ(b.read16(reg::al_status), 0x14) << "SAFE-OP with the error flag";
  EXPECT_EQ(b.read16(reg::al_status_code), al_code::sync_manager_watchdog);
  b.run(10);
  // 0x6007 = 1 by default: a lost connection is a fault (S10), and the master hears an emergency.
  EXPECT_EQ(b.slave.device().drive().view().outputs().error_code, 0x8130);
  const auto mbx = b.send(command::fprd, b.fp(mailbox_in_start), std::vector<std::uint8_t>(mailbox_size, 0));
  ASSERT_EQ(mbx.wkc, 1);
  EXPECT_EQ(mbx.data[7] >> 4, 1) << "CoE emergency";
  EXPECT_EQ(mbx.data[8] | (mbx.data[9] << 8), 0x8130);
}

TEST(drive_slave, while_the_error_flag_is_up_only_init_or_an_acknowledged_request_is_taken) {
  // ETG.1000.6 §6.4.1.4: from SAFE-OP+ERR (the watchdog, 0x001B), OP without the acknowledge bit
  // and SAFE-OP again change nothing; INIT acknowledges by itself; with the bit the way up is open.
  bench b;
  b.to_op();
  for (int i = 0; i < 5; ++i) b.cycle(0x0006);
  b.run(150);
  ASSERT_EQ(b.read16(reg::al_status), 0x14);
  for (std::uint16_t request : {0x08, 0x04, 0x02, 0x03, 0x05}) {
    EXPECT_EQ(b.request(request), 0x14) << "request 0x" << std::hex << request << " without the acknowledge";
    EXPECT_EQ(b.read16(reg::al_status_code), al_code::sync_manager_watchdog);
  }
  EXPECT_EQ(b.request(0x18), 8) << "OP with the acknowledge";
  EXPECT_EQ(b.read16(reg::al_status_code), 0);
  for (int i = 0; i < 5; ++i) b.cycle(0x0006);  // outputs again, so the watchdog runs again
  b.run(150);
  ASSERT_EQ(b.read16(reg::al_status), 0x14);
  EXPECT_EQ(b.request(0x01), 1) << "INIT without the acknowledge is taken, and clears the flag";
  EXPECT_EQ(b.read16(reg::al_status_code), 0);
}

TEST(drive_slave, leaving_op_applies_0x6007_to_an_enabled_drive_only) {
  // The master's own request out of OP and the watchdog alike: a drive taken to READY TO SWITCH ON
  // first has nothing to protect and stays as it is; an enabled one applies 0x6007 (1: a fault).
  struct run {
    std::uint16_t last_control_word;
    bool watchdog;
    state expected;
    std::uint16_t code;
  };
  for (const run& r : {run{0x0006, false, state::ready_to_switch_on, 0}, run{0x0006, true, state::ready_to_switch_on, 0},
                       run{0x000F, false, state::fault, 0x8130}, run{0x000F, true, state::fault, 0x8130}}) {
    bench b;
    b.to_op();
    for (std::uint16_t cw : {std::uint16_t{0x0006}, r.last_control_word}) {
      for (int i = 0; i < 40; ++i) b.cycle(cw);
    }
    if (r.watchdog) {
      b.run(150);
      EXPECT_EQ(b.read16(reg::al_status), 0x14);
    } else {
      EXPECT_EQ(b.request(2), 2) << "PRE-OP as the master asks";
    }
    b.run(20);
    EXPECT_EQ(b.slave.device().drive().view().current(), r.expected) << "watchdog " << r.watchdog;
    EXPECT_EQ(b.slave.device().drive().view().outputs().error_code, r.code) << "watchdog " << r.watchdog;
  }
}

TEST(drive_slave, its_emergencies_are_kept_in_0x1003_newest_first) {
  // CiA 301 §7.5.2.5 over CoE: two faults injected and reset, then the field read by SDO uploads.
  bench b;
  b.to_pre_op();
  EXPECT_EQ(b.upload(0x1003, 0), 0);
  for (std::uint32_t code : {0x2310u, 0x3220u}) {
    EXPECT_EQ(b.download(0x2001, 0, code, 2), 0u);
    b.drain_mailbox();
    EXPECT_EQ(b.download(0x2001, 0, 0, 2), 0u);
    EXPECT_EQ(b.download(0x6040, 0, 0x80, 2), 0u);
    b.drain_mailbox();
    EXPECT_EQ(b.download(0x6040, 0, 0x00, 2), 0u);
    b.drain_mailbox();
  }
  ASSERT_EQ(b.upload(0x1003, 0), 2);
  EXPECT_EQ(b.upload(0x1003, 1) & 0xFFFF, 0x3220);
  EXPECT_EQ(b.upload(0x1003, 2) & 0xFFFF, 0x2310);
  EXPECT_EQ((b.upload(0x1003, 1) >> 16) & 0x08, 0x08) << "the status word at the emergency, fault bit set";
  EXPECT_EQ(b.download(0x1003, 0, 2, 1), 0x06090030u) << "only 0 may be written to sub 0";
  EXPECT_EQ(b.download(0x1003, 1, 0, 4), 0x06010002u);
  EXPECT_EQ(b.download(0x1003, 0, 0, 1), 0u);
  EXPECT_EQ(b.upload(0x1003, 0), 0);
}

TEST(drive_slave, a_mapping_entry_of_0_bits_is_refused_when_it_is_counted_in) {
  // 0x1600:1 = the control word, 0x1600:2 = 0, then 0x1600:0 = 2: the second entry maps nothing
  // of no length, which OP would have decoded with a shift by -1.
  bench b;
  b.to_pre_op();
  const auto count = static_cast<std::uint8_t>(b.upload(0x1600, 0));
  std::vector<std::uint32_t> entries;
  for (std::uint8_t k = 1; k <= count; ++k) entries.push_back(static_cast<std::uint32_t>(b.upload(0x1600, k)));
  EXPECT_EQ(b.download(0x1600, 0, 0, 1), 0u);
  EXPECT_EQ(b.download(0x1600, 1, 0x60400010, 4), 0u);
  EXPECT_EQ(b.download(0x1600, 2, 0, 4), 0u) << "an entry may be cleared while it is not counted";
  EXPECT_EQ(b.download(0x1600, 0, 2, 1), 0x06040041u);
  EXPECT_EQ(b.upload(0x1600, 0), 0) << "refused whole: the count stays";
  EXPECT_EQ(b.download(0x1600, 2, 0x60400000, 4), 0x06040041u) << "an object of 0 bits";
  // The default mapping back, which the SII's sync manager length is made for.
  for (std::uint8_t k = 1; k <= count; ++k) EXPECT_EQ(b.download(0x1600, k, entries[k - 1u], 4), 0u);
  EXPECT_EQ(b.download(0x1600, 0, count, 1), 0u);
  b.to_op();
  std::uint16_t sw = 0;
  for (std::uint16_t cw : {0x0006, 0x0007, 0x000F}) {
    for (int i = 0; i < 40; ++i) sw = b.cycle(cw);
  }
  EXPECT_EQ(sw & 0x6F, 0x27) << "the one entry left runs the drive";
}

TEST(drive_slave, a_sync_manager_moved_in_op_takes_the_slave_back_and_never_its_registers) {
  // In OP, one APRW of four zero bytes at 0x0816: SM2's activate and PDI control, and SM3's start
  // (low word) now 0x0000. The drive's inputs would have gone over the identity, the station
  // address and the alias. The slave leaves the state that checked them instead.
  bench b;
  b.to_op();
  for (int i = 0; i < 5; ++i) b.cycle(0x0006);
  const std::uint16_t alias = b.read16(reg::station_alias);
  const std::uint16_t type = b.read16(reg::type);
  EXPECT_EQ(b.send(command::aprw, static_cast<std::uint32_t>(reg::sync_manager0 + 0x16) << 16, {0, 0, 0, 0}).wkc, 3);
  b.run(5);
  EXPECT_EQ(b.read16(reg::station_address), station);
  EXPECT_EQ(b.read16(reg::station_alias), alias);
  EXPECT_EQ(b.read16(reg::type), type);
  EXPECT_EQ(b.read16(reg::al_status), 0x12) << "PRE-OP with the error flag";
  const std::uint16_t code = b.read16(reg::al_status_code);
  EXPECT_TRUE(code == al_code::invalid_output_configuration || code == al_code::invalid_input_configuration) << code;
  EXPECT_EQ(b.slave.controller().errors().pdi_refused, 0u) << "the application never tried a register";
  EXPECT_EQ(b.request(8), 0x12) << "OP is not taken back without the checks of SAFE-OP";
}

TEST(drive_slave, each_sync_manager_change_after_its_check_has_its_own_al_status_code) {
  struct change {
    int sm;
    std::uint16_t start_or_length;  // written to the start (SM0/SM3) or the length (SM2)
    std::uint16_t offset;
    std::uint16_t code;
    std::uint16_t status;  // where the slave goes, with the error flag
  };
  for (const change& c : {change{3, 0x1190, 0, al_code::invalid_input_configuration, 0x12},
                          change{2, 1, 2, al_code::invalid_output_configuration, 0x12},
                          change{0, 0x1010, 0, al_code::invalid_mailbox_configuration, 0x11}}) {
    bench b;
    b.to_op();
    for (int i = 0; i < 5; ++i) b.cycle(0x0006);
    b.write16(static_cast<std::uint16_t>(reg::sync_manager0 + 8 * c.sm + c.offset), c.start_or_length);
    b.run(2);
    EXPECT_EQ(b.read16(reg::al_status), c.status) << "SM" << c.sm;
    EXPECT_EQ(b.read16(reg::al_status_code), c.code) << "SM" << c.sm;
    // Acknowledged and set up again as it was checked, the way up is open again.
    if (c.status == 0x11) continue;
    const slave_description& d = b.slave.description();
    b.sync_manager(c.sm, d.sync_managers[static_cast<std::size_t>(c.sm)]);
    EXPECT_EQ(b.request(0x14), 4);
    EXPECT_EQ(b.request(8), 8);
  }
}

// Padding between objects (issue 44): an index-0 gap (KickCAT's 0x00000008), a CiA 301 UNSIGNED8
// dummy (0x00050008), a BOOLEAN dummy (1 bit) and a 3-bit gap, so the last object starts at bit 44.
// The outputs' padding bits are all set and land nowhere; the inputs' come out as zeros; the
// objects sit where the mapping puts them.
std::uint64_t bits_of(const std::vector<std::uint8_t>& b, unsigned offset, unsigned bits) {
  std::uint64_t v = 0;
  for (unsigned i = 0; i < bits; ++i) {
    const unsigned at = offset + i;
    v |= std::uint64_t{(b[at / 8] >> (at % 8)) & 1u} << i;
  }
  return v;
}

TEST(drive_slave, padding_between_objects_is_skipped_in_the_outputs_and_zeros_in_the_inputs) {
  bench b;
  b.to_pre_op();
  const std::vector<std::uint32_t> rx = {0x60400010, 0x00000008, 0x60600008, 0x00050008,
                                         0x00010001, 0x00000003, 0x607A0020};
  const std::vector<std::uint32_t> tx = {0x00000003, 0x00010001, 0x00050008, 0x60410010,
                                         0x00000008, 0x60610008, 0x60640020};
  for (const auto& [index, entries] : {std::pair{std::uint16_t{0x1600}, rx}, std::pair{std::uint16_t{0x1A00}, tx}}) {
    ASSERT_EQ(b.download(index, 0, 0, 1), 0u);
    for (std::size_t k = 0; k < entries.size(); ++k) {
      ASSERT_EQ(b.download(index, static_cast<std::uint8_t>(k + 1), entries[k], 4), 0u) << std::hex << entries[k];
    }
    ASSERT_EQ(b.download(index, 0, static_cast<std::uint32_t>(entries.size()), 1), 0u);
    for (std::size_t k = 0; k < entries.size(); ++k) {
      EXPECT_EQ(static_cast<std::uint32_t>(b.upload(index, static_cast<std::uint8_t>(k + 1))), entries[k])
          << "the entry reads as written";
    }
  }
  ASSERT_EQ(b.slave.output_bytes(), 10) << "76 bits";
  ASSERT_EQ(b.slave.input_bytes(), 10);
  slave_description d = b.slave.description();
  d.sync_managers[2].length = 10;
  d.sync_managers[3].length = 10;
  b.sync_manager(2, d.sync_managers[2]);
  b.sync_manager(3, d.sync_managers[3]);
  b.fmmu(0, 0x10000, 10, d.sync_managers[2].start, 2);
  b.fmmu(1, 0x10100, 10, d.sync_managers[3].start, 1);
  ASSERT_EQ(b.request(4), 4);
  ASSERT_EQ(b.request(8), 8);
  const auto target = static_cast<std::uint32_t>(-123456);
  std::vector<std::uint8_t> out(10, 0xFF);  // every padding bit set
  out[0] = 0x06;                             // Shutdown
  out[1] = 0x00;
  out[3] = 0x08;                             // 0x6060 = 8 at bit 24
  // 0x607A at bits 44..75: the low 4 bits of out[5], out[6..8], the high 4 bits of out[9] stay set.
  out[5] = static_cast<std::uint8_t>(0x0F | (target << 4));
  for (unsigned i = 0; i < 3; ++i) out[6 + i] = static_cast<std::uint8_t>(target >> (4 + 8 * i));
  out[9] = static_cast<std::uint8_t>(0xF0 | (target >> 28));
  std::vector<std::uint8_t> in;
  for (int i = 0; i < 40; ++i) {
    EXPECT_EQ(b.send(command::lwr, 0x10000, out).wkc, 1);
    b.run(1);
    const auto a = b.send(command::lrd, 0x10100, std::vector<std::uint8_t>(10, 0xAA));
    EXPECT_EQ(a.wkc, 1);
    in = a.data;
  }
  EXPECT_EQ(b.upload(0x6040, 0), 0x0006);
  EXPECT_EQ(b.upload(0x6060, 0), 8);
  EXPECT_EQ(static_cast<std::uint32_t>(b.upload(0x607A, 0)), target) << "0x607A from bit 44, sign kept";
  ASSERT_EQ(in.size(), 10u);
  EXPECT_EQ(bits_of(in, 0, 12), 0u) << "gap and dummies: zeros";
  EXPECT_EQ(bits_of(in, 12, 16) & 0x6F, 0x21u) << "0x6041 from bit 12: READY TO SWITCH ON";
  EXPECT_EQ(bits_of(in, 28, 8), 0u) << "the gap: zeros";
  EXPECT_EQ(bits_of(in, 36, 8), 8u) << "0x6061 from bit 36";
  EXPECT_EQ(bits_of(in, 44, 32), static_cast<std::uint32_t>(b.upload(0x6064, 0))) << "0x6064 from bit 44";
  EXPECT_EQ(bits_of(in, 76, 4), 0u) << "the byte's rest";
}

TEST(drive_slave, padding_of_a_wrong_length_or_sub_index_is_refused) {
  bench b;
  b.to_pre_op();
  ASSERT_EQ(b.download(0x1601, 0, 0, 1), 0u);
  EXPECT_EQ(b.download(0x1601, 1, 0x00050010, 4), 0x06040041u) << "UNSIGNED8 is 8 bits";
  EXPECT_EQ(b.download(0x1601, 1, 0x00010008, 4), 0x06040041u) << "a BOOLEAN dummy is 1 bit";
  EXPECT_EQ(b.download(0x1601, 1, 0x00060008, 4), 0x06040041u) << "UNSIGNED16 is 16 bits";
  EXPECT_EQ(b.download(0x1601, 1, 0x00050108, 4), 0x06040041u) << "sub-index 1";
  EXPECT_EQ(b.download(0x1601, 1, 0x00000041, 4), 0x06040041u) << "a gap of 65 bits";
  EXPECT_EQ(b.download(0x1601, 1, 0x00000108, 4), 0x06040041u) << "a gap with a sub-index";
  EXPECT_EQ(b.download(0x1A01, 1, 0x00000040, 4), 0u) << "a gap of 64 bits";
  EXPECT_EQ(b.download(0x1A01, 2, 0x00070020, 4), 0u) << "an UNSIGNED32 dummy in a TxPDO";
  EXPECT_EQ(b.download(0x1A01, 0, 2, 1), 0u);
}

}  // namespace
}  // namespace cia402::ethercat
