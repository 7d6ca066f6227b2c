// The emulated ESC command by command (ETG.1000.4 §5.4): each command's working counter and what it
// does to the data, chains of slaves, FMMU and sync-manager rights, the AL event register, what the
// application side may write, and the watchdog's unit.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "cia402/ethercat/esc/esc.hpp"
#include "esc_bus.hpp"

namespace cia402::ethercat {
namespace {

using namespace esc_bus;

// ---- every command, its working counter, and what it does to the data --------------------------

// One slave at station 0x1001 with a 4-byte output FMMU at logical 0x8000 onto 0x1100 and a 4-byte
// input FMMU at the same logical address from 0x1180 (an LRW there writes the one and reads the other).
bus one_configured_slave() {
  bus b(1);
  b.write16(command::apwr, ap(0, reg::station_address), 0x1001);
  fmmu(b, 0, 0, 0x8000, 4, 0, 7, 0x1100, 0, 2);
  fmmu(b, 0, 1, 0x8000, 4, 0, 7, 0x1180, 0, 1);
  return b;
}

TEST(esc_commands, each_command_counts_as_etg_1000_4_says) {
  struct row {
    command cmd;
    std::uint32_t address;
    std::uint16_t wkc;
    bool reads;  // the datagram comes back with the slave's data
  };
  const row rows[] = {
      {command::nop, ap(0, 0x1000), 0, false},
      {command::aprd, ap(0, 0x1000), 1, true},   {command::apwr, ap(0, 0x1000), 1, false},
      {command::aprw, ap(0, 0x1000), 3, true},   {command::fprd, fp(0x1001, 0x1000), 1, true},
      {command::fpwr, fp(0x1001, 0x1000), 1, false}, {command::fprw, fp(0x1001, 0x1000), 3, true},
      {command::brd, 0x1000u << 16, 1, true},     {command::bwr, 0x1000u << 16, 1, false},
      {command::brw, 0x1000u << 16, 3, true},     {command::lrd, 0x8000, 1, true},
      {command::lwr, 0x8000, 1, false},           {command::lrw, 0x8000, 3, true},
      {command::armw, ap(0, 0x1000), 1, true},    {command::frmw, fp(0x1001, 0x1000), 1, true},
  };
  for (const row& r : rows) {
    bus b = one_configured_slave();
    b.escs[0].write16(0x1000, 0xBEEF);
    b.escs[0].write16(0x1180, 0xBEEF);
    const result got = b.send(r.cmd, r.address, {0x11, 0x22, 0, 0});
    SCOPED_TRACE(command_name(r.cmd));
    EXPECT_EQ(got.wkc, r.wkc);
    if (r.reads) {
      // BRW/BRD OR the slave's data into what came: 0x11 | 0xEF, 0x22 | 0xBE.
      const bool ors = r.cmd == command::brd || r.cmd == command::brw;
      EXPECT_EQ(got.data[0], ors ? 0xFF : 0xEF);
      EXPECT_EQ(got.data[1], ors ? 0xBE : 0xBE);
    } else {
      EXPECT_EQ(got.data[0], 0x11) << "a write leaves the data as it came";
    }
    const bool writes = r.cmd == command::apwr || r.cmd == command::aprw || r.cmd == command::fpwr ||
                        r.cmd == command::fprw || r.cmd == command::bwr || r.cmd == command::brw;
    EXPECT_EQ(b.escs[0].read16(0x1000), writes ? 0x2211 : 0xBEEF) << "read-write: the old value back, the new one in";
    const bool logical_writes = r.cmd == command::lwr || r.cmd == command::lrw;
    EXPECT_EQ(b.escs[0].read16(0x1100), logical_writes ? 0x2211 : 0);
    EXPECT_EQ(b.escs[0].refused_accesses(), 0u);
  }
}

TEST(esc_commands, a_chain_of_three_multiplies_the_broadcast_and_logical_counters) {
  bus b(3);
  for (int s = 0; s < 3; ++s) fmmu(b, s, 0, 0x100u + 2u * static_cast<std::uint32_t>(s), 2, 0, 7, 0x1100, 0, 3);
  EXPECT_EQ(b.send(command::brd, reg::type << 16, {0}).wkc, 3);
  EXPECT_EQ(b.send(command::bwr, 0x1000u << 16, {1}).wkc, 3);
  EXPECT_EQ(b.send(command::brw, 0x1000u << 16, {1}).wkc, 9);
  EXPECT_EQ(b.send(command::lrd, 0x100, std::vector<std::uint8_t>(6, 0)).wkc, 3);
  EXPECT_EQ(b.send(command::lwr, 0x100, std::vector<std::uint8_t>(6, 0)).wkc, 3);
  EXPECT_EQ(b.send(command::lrw, 0x100, std::vector<std::uint8_t>(6, 0)).wkc, 9) << "read-write FMMUs";
  EXPECT_EQ(b.send(command::lrw, 0x102, {0, 0}).wkc, 3) << "only the second slave's part";
}

TEST(esc_commands, nop_and_unknown_commands_pass_untouched) {
  bus b(2);
  const result nop = b.send(command::nop, ap(0, reg::type), {7, 7});
  EXPECT_EQ(nop.wkc, 0);
  EXPECT_EQ(nop.adp, 0) << "NOP leaves ADP";
  EXPECT_EQ(nop.data, (std::vector<std::uint8_t>{7, 7}));
  const result unknown = b.send(static_cast<command>(0x0F), ap(0, reg::type), {7, 7});
  EXPECT_EQ(unknown.wkc, 0);
  EXPECT_EQ(unknown.data, (std::vector<std::uint8_t>{7, 7}));
  for (const esc& e : b.escs) EXPECT_EQ(e.errors().unknown_command, 1u);
}

TEST(esc_commands, frmw_reads_at_the_station_and_writes_the_others) {
  bus b(3);
  for (std::uint16_t i = 0; i < 3; ++i) b.write16(command::apwr, ap(i, reg::station_address), 0x1001 + i);
  b.write16(command::apwr, ap(1, reg::fmmu0), 0x5150);
  const result r = b.send(command::frmw, fp(0x1002, reg::fmmu0), {0, 0});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(b.value16(r), 0x5150);
  EXPECT_EQ(b.escs[0].read16(reg::fmmu0), 0) << "before the reader: the master's data";
  EXPECT_EQ(b.escs[2].read16(reg::fmmu0), 0x5150);
}

TEST(esc_commands, a_write_past_the_memory_changes_nothing_and_is_counted_by_kind) {
  bus b = one_configured_slave();
  b.escs[0].write8(0x1FFF, 0x42);
  EXPECT_EQ(b.send(command::fpwr, fp(0x1001, 0x1FFF), {1, 2}).wkc, 0);
  EXPECT_EQ(b.send(command::bwr, 0xFFF0u << 16, {1, 2}).wkc, 0);
  EXPECT_EQ(b.escs[0].read8(0x1FFF), 0x42);
  // An FMMU whose physical end lies past the memory.
  fmmu(b, 0, 2, 0x9000, 4, 0, 7, 0x1FFE, 0, 2);
  EXPECT_EQ(b.send(command::lwr, 0x9000, {1, 2, 3, 4}).wkc, 0);
  EXPECT_EQ(b.escs[0].read8(0x1FFF), 0x42);
  EXPECT_EQ(b.escs[0].errors().past_memory, 3u);
  EXPECT_EQ(b.escs[0].errors().sync_manager, 0u);
}

TEST(esc_commands, an_fmmu_cannot_write_what_the_master_may_not) {
  bus b(1);
  const std::uint16_t status = b.escs[0].read16(reg::al_status);
  fmmu(b, 0, 0, 0x4000, 2, 0, 7, reg::al_status, 0, 2);
  EXPECT_EQ(b.send(command::lwr, 0x4000, {0x08, 0}).wkc, 1);
  EXPECT_EQ(b.escs[0].read16(reg::al_status), status);
  // A read FMMU on the status of sync manager 1 (the "mailbox full" bit), as masters map it.
  sync_manager(b, 1, 0x1080, 16, 0x22);
  fmmu(b, 0, 1, 0x4010, 1, 3, 3, reg::sync_manager0 + 8 + reg::sm_status, 3, 1);
  EXPECT_EQ(b.send(command::lrd, 0x4010, {0}).data[0], 0);
  ASSERT_TRUE(b.escs[0].write_mailbox(1, {1, 2, 3}));
  EXPECT_EQ(b.send(command::lrd, 0x4010, {0}).data[0], 0x08);
  // Nor can a datagram write a sync manager's status or PDI control bytes.
  EXPECT_EQ(b.send(command::apwr, ap(0, reg::sync_manager0 + 8 + reg::sm_status), {0}).wkc, 1);
  EXPECT_TRUE(b.escs[0].mailbox_full(1));
  EXPECT_NE(b.escs[0].read8(reg::sync_manager0 + 8 + reg::sm_status) & 0x08, 0);
}

TEST(esc_commands, al_control_and_sync_manager_events_show_in_the_al_event_register) {
  bus b(1);
  sync_manager(b, 0, 0x1000, 8, 0x26);
  b.write16(command::apwr, ap(0, reg::al_control), 2);
  EXPECT_EQ(b.escs[0].read16(reg::al_event_request) & 0x0001, 1);
  EXPECT_TRUE(b.escs[0].take_al_control_event());
  EXPECT_EQ(b.escs[0].read16(reg::al_event_request) & 0x0001, 0);
  b.send(command::apwr, ap(0, 0x1000), std::vector<std::uint8_t>(8, 1));
  EXPECT_EQ(b.escs[0].read16(reg::al_event_request), 0x0100) << "SM 0";
  EXPECT_TRUE(b.escs[0].take_sync_manager_event(0));
  EXPECT_EQ(b.escs[0].read16(reg::al_event_request), 0);
}

TEST(esc_commands, the_application_may_deactivate_a_sync_manager) {
  bus b(1);
  sync_manager(b, 0, 0x1000, 8, 0x26);
  EXPECT_TRUE(b.escs[0].sm(0).enabled);
  b.escs[0].write8(reg::sync_manager0 + reg::sm_pdi_control, 1);
  EXPECT_FALSE(b.escs[0].sm(0).enabled);
  b.escs[0].write8(reg::sync_manager0 + reg::sm_pdi_control, 0);
  EXPECT_TRUE(b.escs[0].sm(0).enabled);
}

TEST(esc_commands, a_sync_manager_set_over_the_registers_locks_no_master_out) {
  // One APWR of 128 bytes at 0x0810 sets SM2 to start 0x00FF, 0xFF41 bytes long, slave-writes,
  // activated: it would cover every register from 0x00FF up. A sync manager covers process RAM
  // only, so this one is not enabled and every register stays the master's.
  bus b(1);
  std::vector<std::uint8_t> block(128, 0);
  block[0] = 0xFF;  // SM2 start 0x00FF
  block[1] = 0x00;
  block[2] = 0x41;  // length 0xFF41
  block[3] = 0xFF;
  block[4] = 0x20;  // control: buffered, the slave writes (the master reads)
  block[6] = 0x01;  // activate
  EXPECT_EQ(b.send(command::apwr, ap(0, reg::sync_manager0 + 16), block).wkc, 1);
  EXPECT_FALSE(b.escs[0].sm(2).enabled);
  EXPECT_EQ(b.write16(command::apwr, ap(0, reg::al_control), 0x0002).wkc, 1) << "AL control";
  EXPECT_EQ(b.escs[0].read16(reg::al_control), 0x0002);
  EXPECT_EQ(b.send(command::apwr, ap(0, reg::fmmu0), std::vector<std::uint8_t>(16, 0)).wkc, 1) << "FMMUs";
  EXPECT_EQ(b.send(command::apwr, ap(0, reg::sync_manager0 + 16), std::vector<std::uint8_t>(8, 0)).wkc, 1)
      << "the sync manager itself";
  sync_manager(b, 0, 0x1000, 128, 0x26);
  EXPECT_TRUE(b.escs[0].sm(0).enabled) << "a mailbox in process RAM still works";
  // Past the memory's end is no better than the registers.
  sync_manager(b, 3, 0x1F00, 0x200, 0x20);
  EXPECT_FALSE(b.escs[0].sm(3).enabled);
}

TEST(esc_commands, the_application_writes_process_ram_and_its_own_registers_only) {
  bus b(1);
  b.write16(command::apwr, ap(0, reg::station_address), 0x1001);
  const std::uint8_t type = b.escs[0].read8(reg::type);
  b.escs[0].write16(reg::station_address, 0x0000);
  b.escs[0].write8(reg::type, 0x00);
  b.escs[0].write16(reg::sync_manager0, 0x0000);
  b.escs[0].write16(reg::fmmu0, 0x1234);
  EXPECT_EQ(b.escs[0].errors().pdi_refused, 7u) << "each byte refused and counted";
  EXPECT_EQ(b.escs[0].read16(reg::station_address), 0x1001);
  EXPECT_EQ(b.escs[0].read8(reg::type), type);
  EXPECT_EQ(b.escs[0].read16(reg::fmmu0), 0);
  b.escs[0].set_al_status(0x14, 0x001B);
  b.escs[0].write16(0x1800, 0xBEEF);
  EXPECT_EQ(b.escs[0].errors().pdi_refused, 7u) << "AL status, its code and process RAM are the application's";
  EXPECT_EQ(b.escs[0].read16(reg::al_status_code), 0x001B);
  EXPECT_EQ(b.escs[0].read16(0x1800), 0xBEEF);
}

TEST(esc, the_watchdog_counts_in_units_of_40_ns_times_divider_plus_2) {
  bus b(1);
  b.write16(command::apwr, ap(0, reg::watchdog_divider), 98);             // (98 + 2) x 40 ns = 4 us
  b.write16(command::apwr, ap(0, reg::watchdog_time_process_data), 250);  // 1 ms
  sync_manager(b, 2, 0x1100, 2, 0x64);
  b.send(command::apwr, ap(0, 0x1100), {1, 2});
  b.escs[0].advance(999'000);
  EXPECT_FALSE(b.escs[0].take_watchdog_event());
  b.escs[0].advance(2'000);
  EXPECT_TRUE(b.escs[0].take_watchdog_event());
  EXPECT_EQ(b.escs[0].read16(reg::watchdog_status_process_data) & 1, 0);
  b.escs[0].advance(10'000'000);
  EXPECT_FALSE(b.escs[0].take_watchdog_event()) << "expired once, until outputs come again";
  b.write16(command::apwr, ap(0, reg::watchdog_time_process_data), 0);  // 0: the watchdog is off
  b.send(command::apwr, ap(0, 0x1100), {1, 2});
  b.escs[0].advance(1'000'000'000);
  EXPECT_FALSE(b.escs[0].take_watchdog_event());
}


}  // namespace
}  // namespace cia402::ethercat
