// The emulated ESC against the datagram semantics of ETG.1000.4: every command and its working
// counter, auto-increment and configured addressing, FMMUs at bit offsets, sync-manager hand-over,
// the watchdog, the SII EEPROM interface, and frames that are not sound.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "cia402/ethercat/esc/esc.hpp"
#include "esc_bus.hpp"

namespace cia402::ethercat {
namespace {

using namespace esc_bus;

TEST(esc, auto_increment_addresses_by_position_and_counts_each_slave_once) {
  bus b(3);
  // Position 1 is the second slave: ADP -1 reaches 0 there.
  const result r = b.write16(command::apwr, ap(1, reg::station_address), 0x1002);
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(r.adp, static_cast<std::uint16_t>(-1 + 3)) << "every slave incremented ADP";
  EXPECT_EQ(b.escs[1].read16(reg::station_address), 0x1002);
  EXPECT_EQ(b.escs[0].read16(reg::station_address), 0);
  EXPECT_EQ(b.escs[2].read16(reg::station_address), 0);
  // Beyond the last slave nobody answers.
  EXPECT_EQ(b.write16(command::aprd, ap(3, reg::type), 0).wkc, 0);
}

TEST(esc, configured_address_reaches_one_slave) {
  bus b(3);
  for (std::uint16_t i = 0; i < 3; ++i) b.write16(command::apwr, ap(i, reg::station_address), 0x1001 + i);
  const result r = b.send(command::fprd, fp(0x1003, reg::station_alias), {0, 0});
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(b.value16(r), 0x77) << "the alias loaded from SII word 4";
  EXPECT_EQ(b.write16(command::fpwr, fp(0x1002, reg::al_control), 2).wkc, 1);
  EXPECT_TRUE(b.escs[1].take_al_control_event());
  EXPECT_FALSE(b.escs[0].take_al_control_event());
  EXPECT_EQ(b.write16(command::fprw, fp(0x1001, reg::event_mask), 0x0004).wkc, 3) << "read + write";
  EXPECT_EQ(b.write16(command::fprd, fp(0x2000, reg::type), 0).wkc, 0) << "no such station";
}

TEST(esc, broadcast_reads_or_the_slaves_and_writes_all) {
  bus b(3);
  b.escs[0].write16(reg::al_status_code, 0x0001);
  b.escs[2].write16(reg::al_status_code, 0x0010);
  const result r = b.send(command::brd, reg::al_status_code << 16, {0, 0});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(b.value16(r), 0x0011);
  EXPECT_EQ(b.write16(command::bwr, reg::dl_control << 16, 0x0001).wkc, 3);
  for (esc& e : b.escs) EXPECT_EQ(e.read16(reg::dl_control), 0x0001);
  EXPECT_EQ(b.write16(command::brw, reg::event_mask << 16, 0x0002).wkc, 9);
}

// DL status (0x0110, ETG.1000.4): the PDI is operational and its watchdog reloaded (bit 1: SOEM and
// KickCAT read 0 there as an expired PDI watchdog), port 0 has link and communication on every
// slave, port 1 on all but the last, which closes the loop.
TEST(esc, dl_status_shows_the_pdi_running_and_the_ports_of_the_line) {
  bus b(3);
  for (std::uint16_t i = 0; i < 3; ++i) {
    const result r = b.send(command::aprd, ap(i, reg::dl_status), {0, 0});
    ASSERT_EQ(r.wkc, 1);
    const std::uint16_t dl = b.value16(r);
    EXPECT_EQ(dl & 0x0003, 0x0003) << "slave " << i << ": PDI operational, its watchdog reloaded";
    EXPECT_EQ(dl & 0x0210, 0x0210) << "slave " << i << ": port 0 link and communication";
    EXPECT_EQ((dl & 0x0400) != 0, i == 2) << "slave " << i << ": port 1 closed (loop) at the end only";
  }
}

TEST(esc, read_only_registers_keep_their_value) {
  bus b(1);
  const std::uint16_t before = b.escs[0].read16(reg::al_status);
  EXPECT_EQ(b.write16(command::apwr, ap(0, reg::al_status), 0x0008).wkc, 1) << "served, as an ESC does";
  EXPECT_EQ(b.escs[0].read16(reg::al_status), before);
  EXPECT_EQ(b.escs[0].read8(reg::type), 0xC0);
}

TEST(esc, armw_reads_at_one_slave_and_writes_the_rest) {
  // A plain register (FMMU 0's logical start): 0x0900, used before, latches receive times now.
  bus b(3);
  b.write16(command::apwr, ap(0, reg::fmmu0), 0x4242);
  const result r = b.send(command::armw, ap(0, reg::fmmu0), {0, 0});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(b.value16(r), 0x4242);
  EXPECT_EQ(b.escs[1].read16(reg::fmmu0), 0x4242);
  EXPECT_EQ(b.escs[2].read16(reg::fmmu0), 0x4242);
}

TEST(esc, an_access_past_the_memory_is_not_served_and_counted) {
  bus b(1);
  const result r = b.send(command::aprd, ap(0, 0x1FFE), {0, 0, 0, 0});
  EXPECT_EQ(r.wkc, 0);
  EXPECT_EQ(b.escs[0].refused_accesses(), 1u);
}


TEST(esc, fmmus_map_logical_to_physical_memory_and_lrw_counts_three) {
  bus b(2);
  // Each slave: outputs 2 bytes at 0x1100 from logical 0x10000 + 4 n, inputs 2 bytes at 0x1180 to
  // logical 0x10000 + 4 n + 2.
  for (int s = 0; s < 2; ++s) {
    const auto log = static_cast<std::uint32_t>(0x10000 + 4 * s);
    fmmu(b, s, 0, log, 2, 0, 7, 0x1100, 0, 2);
    fmmu(b, s, 1, log + 2, 2, 0, 7, 0x1180, 0, 1);
    b.escs[static_cast<std::size_t>(s)].write16(0x1180, static_cast<std::uint16_t>(0xA0A0 + s));
  }
  const result r = b.send(command::lrw, 0x10000, {0x11, 0x22, 0, 0, 0x33, 0x44, 0, 0});
  EXPECT_EQ(r.wkc, 6) << "two slaves, each read (1) and write (2)";
  EXPECT_EQ(b.escs[0].read16(0x1100), 0x2211);
  EXPECT_EQ(b.escs[1].read16(0x1100), 0x4433);
  EXPECT_EQ(r.data[2] | (r.data[3] << 8), 0xA0A0);
  EXPECT_EQ(r.data[6] | (r.data[7] << 8), 0xA0A1);
  EXPECT_EQ(b.send(command::lrd, 0x10002, {0, 0}).wkc, 1);
  EXPECT_EQ(b.send(command::lwr, 0x10000, {1, 2, 3, 4, 5, 6, 7, 8}).wkc, 2);
  EXPECT_EQ(b.send(command::lrd, 0x20000, {0, 0}).wkc, 0) << "no FMMU there";
}

TEST(esc, an_fmmu_maps_bits_at_any_offset) {
  bus b(1);
  // A 3-bit field at logical bit 5 of 0x3000 goes to physical bits 2..4 of 0x1100.
  fmmu(b, 0, 0, 0x3000, 1, 5, 7, 0x1100, 2, 2);
  EXPECT_EQ(b.send(command::lwr, 0x3000, {0xFF}).wkc, 1);
  EXPECT_EQ(b.escs[0].read8(0x1100), 0x1C);
  EXPECT_EQ(b.send(command::lwr, 0x3000, {0x40}).wkc, 1);  // bits 5..7 = 010
  EXPECT_EQ(b.escs[0].read8(0x1100), 0x08);
  // A field across a byte boundary: logical bits 6..9 to physical bits 0..3 of 0x1101.
  fmmu(b, 0, 1, 0x3010, 2, 6, 1, 0x1101, 0, 2);
  EXPECT_EQ(b.send(command::lwr, 0x3010, {0xC0, 0x01}).wkc, 1);
  EXPECT_EQ(b.escs[0].read8(0x1101), 0x07);
}


TEST(esc, a_mailbox_is_handed_over_whole_and_a_full_one_takes_nothing) {
  bus b(1);
  sync_manager(b, 0, 0x1000, 16, 0x26);  // master -> slave
  sync_manager(b, 1, 0x1080, 16, 0x22);  // slave -> master
  std::vector<std::uint8_t> m(16, 0x5A);
  EXPECT_EQ(b.send(command::apwr, ap(0, 0x1000), m).wkc, 1);
  EXPECT_TRUE(b.escs[0].take_sync_manager_event(0));
  EXPECT_TRUE(b.escs[0].mailbox_full(0));
  EXPECT_NE(b.escs[0].read8(reg::sync_manager0 + 5) & 0x08, 0) << "status: mailbox full";
  EXPECT_EQ(b.send(command::apwr, ap(0, 0x1000), std::vector<std::uint8_t>(16, 0x11)).wkc, 0)
      << "a full mailbox takes nothing";
  std::vector<std::uint8_t> got;
  ASSERT_TRUE(b.escs[0].read_mailbox(0, got));
  EXPECT_EQ(got, m) << "the first mailbox, not overwritten";
  EXPECT_FALSE(b.escs[0].mailbox_full(0));

  EXPECT_EQ(b.send(command::aprd, ap(0, 0x1080), std::vector<std::uint8_t>(16, 0)).wkc, 0)
      << "an empty send mailbox is not read";
  ASSERT_TRUE(b.escs[0].write_mailbox(1, std::vector<std::uint8_t>(10, 0x77)));
  EXPECT_FALSE(b.escs[0].write_mailbox(1, {1})) << "still full";
  const result r = b.send(command::aprd, ap(0, 0x1080), std::vector<std::uint8_t>(16, 0));
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(r.data[0], 0x77);
  EXPECT_EQ(r.data[15], 0);
  EXPECT_FALSE(b.escs[0].mailbox_full(1)) << "read to its last byte: empty again";
  EXPECT_EQ(b.send(command::apwr, ap(0, 0x1080), {1}).wkc, 0) << "the master does not write the slave's mailbox";
}

TEST(esc, outputs_arrive_whole_and_feed_the_watchdog) {
  bus b(1);
  b.write16(command::apwr, ap(0, reg::watchdog_time_process_data), 100);  // 100 x 100 us = 10 ms
  sync_manager(b, 2, 0x1100, 4, 0x64);  // buffered, ECAT writes, watchdog trigger
  EXPECT_EQ(b.send(command::apwr, ap(0, 0x1100), {1, 2}).wkc, 1);
  EXPECT_FALSE(b.escs[0].take_sync_manager_event(2)) << "half a buffer is no new data";
  EXPECT_EQ(b.send(command::apwr, ap(0, 0x1102), {3, 4}).wkc, 1);
  EXPECT_TRUE(b.escs[0].take_sync_manager_event(2));
  b.escs[0].advance(9'000'000);
  EXPECT_FALSE(b.escs[0].take_watchdog_event());
  EXPECT_EQ(b.escs[0].read16(reg::watchdog_status_process_data), 1);
  b.escs[0].advance(2'000'000);
  EXPECT_TRUE(b.escs[0].take_watchdog_event()) << "no outputs for 11 ms";
  EXPECT_EQ(b.escs[0].read16(reg::watchdog_status_process_data), 0);
  EXPECT_EQ(b.escs[0].read16(reg::watchdog_counter_process_data), 1);
  EXPECT_EQ(b.send(command::apwr, ap(0, 0x1100), {1, 2, 3, 4}).wkc, 1);
  EXPECT_EQ(b.escs[0].read16(reg::watchdog_status_process_data), 1) << "outputs again: active";
}

TEST(esc, the_sii_eeprom_reads_through_its_registers) {
  bus b(1);
  const std::vector<std::uint8_t> image = eeprom();
  EXPECT_NE(b.escs[0].read16(reg::eeprom_control) & 0x0040, 0) << "8-byte reads";
  for (std::uint32_t word : {0u, 8u, 0x40u, 0x3FFu}) {
    b.send(command::apwr, ap(0, reg::eeprom_address),
           {static_cast<std::uint8_t>(word), static_cast<std::uint8_t>(word >> 8), 0, 0});
    b.write16(command::apwr, ap(0, reg::eeprom_control), 0x0100);  // read
    const result r = b.send(command::aprd, ap(0, reg::eeprom_data), std::vector<std::uint8_t>(8, 0));
    for (std::size_t i = 0; i < 8; ++i) {
      const std::size_t at = word * 2 + i;
      EXPECT_EQ(r.data[i], at < image.size() ? image[at] : 0xFF) << word << " " << i;
    }
  }
  b.write16(command::apwr, ap(0, reg::eeprom_control), 0x0200);  // write: not offered
  EXPECT_NE(b.escs[0].read16(reg::eeprom_control) & 0x2000, 0) << "command error";
}

TEST(frames, unsound_frames_are_refused_and_change_nothing) {
  bus b(2);
  frame_builder fb(broadcast, master_mac);
  fb.add(command::bwr, 0, reg::dl_control << 16, std::vector<std::uint8_t>{9, 9}, 2);
  const std::vector<std::uint8_t> good = fb.finish();
  // Every truncation of a sound frame inside its datagrams is refused as a whole.
  for (std::size_t n = 0; n < 14 + 2 + 10 + 2 + 2; ++n) {
    std::vector<std::uint8_t> cut(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_NE(b.wire.pass(cut), frame_error::none) << n;
  }
  std::vector<std::uint8_t> other = good;
  other[12] = 0x08;
  other[13] = 0x00;  // IPv4
  EXPECT_EQ(b.wire.pass(other), frame_error::not_ethercat);
  std::vector<std::uint8_t> type = good;
  type[15] = 0x40;  // EtherCAT header type 4
  EXPECT_EQ(b.wire.pass(type), frame_error::not_commands);
  std::vector<std::uint8_t> longer = good;
  longer[14] = 0xFF;
  longer[15] = 0x17;  // length 0x7FF: past the frame
  EXPECT_EQ(b.wire.pass(longer), frame_error::length_mismatch);
  for (const esc& e : b.escs) EXPECT_EQ(e.read16(reg::dl_control), 0) << "nothing half-applied";
  EXPECT_GT(b.wire.refused_frames(), 30u);
}

TEST(frames, random_bytes_never_crash_and_never_touch_a_refused_frame) {
  bus b(3);
  std::mt19937 random(402);
  int sound = 0;
  for (int i = 0; i < 20000; ++i) {
    std::vector<std::uint8_t> f(14 + random() % 200);
    for (auto& byte : f) byte = static_cast<std::uint8_t>(random());
    if (i % 2 == 0 && f.size() >= 16) {  // half of them look like EtherCAT
      f[12] = 0x88;
      f[13] = 0xA4;
      const std::size_t len = (f.size() - 16) - random() % 4;
      f[14] = static_cast<std::uint8_t>(len);
      f[15] = static_cast<std::uint8_t>(0x10 | ((len >> 8) & 7));
    }
    const std::vector<std::uint8_t> before = f;
    if (b.wire.pass(f) == frame_error::none) {
      ++sound;
    } else {
      EXPECT_EQ(f, before);
    }
  }
  EXPECT_GT(sound, 0);
  EXPECT_EQ(b.wire.frames() + b.wire.refused_frames(), 20000u);
}

// ---- three-buffer process data ------------------------------------------------------------------

std::vector<std::uint8_t> pdi_bytes(const esc& e, std::uint16_t at, std::size_t n) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = e.read8(static_cast<std::uint16_t>(at + i));
  return v;
}

TEST(three_buffers, the_application_sees_whole_output_buffers_only) {
  bus b(1);
  sync_manager(b, 2, 0x1100, 4, 0x64);
  esc& e = b.escs[0];
  EXPECT_EQ(e.read8(reg::sync_manager0 + 16 + reg::sm_status) >> 4, 3) << "no buffer written yet";
  EXPECT_EQ(b.send(command::apwr, ap(0, 0x1100), {1, 2, 3, 4}).wkc, 1);
  EXPECT_TRUE(e.take_sync_manager_event(2));
  EXPECT_EQ(pdi_bytes(e, 0x1100, 4), (std::vector<std::uint8_t>{1, 2, 3, 4}));
  EXPECT_NE(e.read8(reg::sync_manager0 + 16 + reg::sm_status) >> 4, 3);
  // The master writes a second buffer whole and begins a third: the application, taking the event,
  // gets the second, never half of the third.
  b.send(command::apwr, ap(0, 0x1100), {5, 6, 7, 8});
  b.send(command::apwr, ap(0, 0x1100), {9, 9});
  EXPECT_EQ(pdi_bytes(e, 0x1100, 4), (std::vector<std::uint8_t>{1, 2, 3, 4})) << "held until taken";
  EXPECT_TRUE(e.take_sync_manager_event(2));
  EXPECT_EQ(pdi_bytes(e, 0x1100, 4), (std::vector<std::uint8_t>{5, 6, 7, 8}));
  b.send(command::apwr, ap(0, 0x1102), {10, 11});  // the third buffer's last byte: complete
  std::vector<std::uint8_t> got(4);
  ASSERT_TRUE(e.read_buffer(2, got));
  EXPECT_EQ(got, (std::vector<std::uint8_t>{9, 9, 10, 11}));
  EXPECT_FALSE(e.read_buffer(3, got)) << "no such sync manager";
  std::vector<std::uint8_t> wrong(3);
  EXPECT_FALSE(e.read_buffer(2, wrong)) << "not its length";
}

TEST(three_buffers, the_master_reads_one_whole_input_buffer_across_datagrams) {
  bus b(1);
  sync_manager(b, 3, 0x1180, 4, 0x20);
  esc& e = b.escs[0];
  ASSERT_TRUE(e.write_buffer(3, std::vector<std::uint8_t>{1, 2, 3, 4}));
  const result first = b.send(command::aprd, ap(0, 0x1180), {0, 0});
  EXPECT_EQ(first.data, (std::vector<std::uint8_t>{1, 2}));
  ASSERT_TRUE(e.write_buffer(3, std::vector<std::uint8_t>{5, 6, 7, 8}));
  const result second = b.send(command::aprd, ap(0, 0x1182), {0, 0});
  EXPECT_EQ(second.data, (std::vector<std::uint8_t>{3, 4})) << "the buffer it opened, not the newer one";
  EXPECT_EQ(b.send(command::aprd, ap(0, 0x1180), {0, 0, 0, 0}).data, (std::vector<std::uint8_t>{5, 6, 7, 8}));
  // Bytes the application writes one by one reach the master at its next read, and the bytes it
  // did not write keep their values.
  e.write8(0x1181, 0x66);
  EXPECT_EQ(e.read8(0x1181), 0x66) << "the application reads back what it wrote";
  EXPECT_EQ(b.send(command::aprd, ap(0, 0x1180), {0, 0, 0, 0}).data, (std::vector<std::uint8_t>{5, 0x66, 7, 8}));
  // The master does not write the slave's inputs.
  EXPECT_EQ(b.send(command::apwr, ap(0, 0x1180), {0, 0, 0, 0}).wkc, 0);
  EXPECT_EQ(e.errors().sync_manager, 1u);
  std::vector<std::uint8_t> out(4);
  EXPECT_FALSE(e.read_buffer(3, out)) << "inputs are written, not read, by the application";
  EXPECT_FALSE(e.write_buffer(3, std::vector<std::uint8_t>{1})) << "not its length";
}

TEST(three_buffers, sync_managers_packed_without_room_for_three_buffers_work) {
  bus b(1);
  // A master placing SM3 right after SM2's length (a real ESC would need 3 x 4 bytes for SM2).
  sync_manager(b, 2, 0x1100, 4, 0x64);
  sync_manager(b, 3, 0x1104, 4, 0x20);
  fmmu(b, 0, 0, 0x10000, 4, 0, 7, 0x1100, 0, 2);
  fmmu(b, 0, 1, 0x10004, 4, 0, 7, 0x1104, 0, 1);
  esc& e = b.escs[0];
  for (std::uint8_t cycle = 1; cycle <= 3; ++cycle) {
    ASSERT_TRUE(e.write_buffer(3, std::vector<std::uint8_t>{cycle, 0, 0, 0xAA}));
    const result r = b.send(command::lrw, 0x10000, {cycle, 1, 2, 3, 0, 0, 0, 0});
    EXPECT_EQ(r.wkc, 3);
    EXPECT_EQ(r.data[4], cycle);
    EXPECT_EQ(r.data[7], 0xAA);
    EXPECT_TRUE(e.take_sync_manager_event(2));
    EXPECT_EQ(pdi_bytes(e, 0x1100, 4), (std::vector<std::uint8_t>{cycle, 1, 2, 3}));
  }
}

TEST(three_buffers, outputs_at_bit_offsets_through_an_fmmu_land_in_the_buffer) {
  bus b(1);
  sync_manager(b, 2, 0x1100, 1, 0x64);
  // A 3-bit field at logical bit 5 to physical bits 2..4 of the output buffer (its only byte).
  fmmu(b, 0, 0, 0x3000, 1, 5, 7, 0x1100, 2, 2);
  EXPECT_EQ(b.send(command::lwr, 0x3000, {0xA0}).wkc, 1);  // bits 5..7 = 101
  EXPECT_TRUE(b.escs[0].take_sync_manager_event(2));
  EXPECT_EQ(b.escs[0].read8(0x1100), 0x14);
}

// ---- frames ---------------------------------------------------------------------------------------

TEST(frames, vlan_tags_and_a_broken_more_follows_chain_are_refused_by_kind) {
  bus b(1);
  frame_builder fb(broadcast, master_mac);
  fb.add(command::bwr, 0, reg::dl_control << 16, std::vector<std::uint8_t>{9, 9}, 2);
  const std::vector<std::uint8_t> good = fb.finish();
  std::vector<std::uint8_t> vlan = good;
  vlan[12] = 0x81;
  vlan[13] = 0x00;
  EXPECT_EQ(b.wire.pass(vlan), frame_error::vlan_tagged);
  std::vector<std::uint8_t> more = good;
  more[ethernet_header_size + ethercat_header_size + 7] |= 0x80;  // "more follows", and nothing does
  EXPECT_EQ(b.wire.pass(more), frame_error::more_follows_past_end);
  EXPECT_EQ(more[ethernet_header_size + ethercat_header_size + 10], 9) << "untouched";
  std::vector<std::uint8_t> empty = good;
  empty[14] = 0;
  empty[15] = 0x10;  // length 0: not even one datagram
  EXPECT_EQ(b.wire.pass(empty), frame_error::datagram_truncated);
  std::vector<std::uint8_t> data_too_long = good;
  data_too_long[ethernet_header_size + ethercat_header_size + 6] = 0x40;  // 64 data bytes in a 14-byte datagram
  EXPECT_EQ(b.wire.pass(data_too_long), frame_error::datagram_truncated);
  EXPECT_EQ(b.wire.refused_frames(frame_error::vlan_tagged), 1u);
  EXPECT_EQ(b.wire.refused_frames(frame_error::more_follows_past_end), 1u);
  EXPECT_EQ(b.wire.refused_frames(frame_error::datagram_truncated), 2u);
  EXPECT_EQ(b.escs[0].read16(reg::dl_control), 0);
  EXPECT_STRNE(frame_error_text(frame_error::more_follows_past_end), "?");
  EXPECT_STRNE(frame_error_text(frame_error::vlan_tagged), "?");
}

TEST(frames, the_builder_chains_datagrams_and_pads_to_the_ethernet_minimum) {
  frame_builder fb(broadcast, master_mac);
  fb.add(command::aprd, 1, ap(0, reg::type), {}, 1);
  fb.add(command::fprd, 2, fp(0x1001, reg::al_status), {}, 2);
  std::vector<std::uint8_t> f = fb.finish();
  EXPECT_EQ(f.size(), minimum_frame_size);
  parsed_frame p;
  ASSERT_EQ(parse_frame(f, p), frame_error::none);
  ASSERT_EQ(p.count, 2u);
  EXPECT_TRUE(p.datagrams[0].more);
  EXPECT_FALSE(p.datagrams[1].more);
  EXPECT_EQ(p.datagrams[1].cmd, command::fprd);
  EXPECT_EQ(p.datagrams[1].index, 2);
  EXPECT_EQ(p.datagrams[1].position(), 0x1001);
  EXPECT_EQ(p.datagrams[1].offset(), reg::al_status);
  EXPECT_EQ(p.datagrams[1].length, 2);
  EXPECT_EQ(std::string(command_name(command::frmw)), "FRMW");
  frame_builder big(broadcast, master_mac);
  EXPECT_GE(big.add(command::lrw, 0, 0, {}, 1400), 0);
  EXPECT_EQ(big.add(command::lrw, 0, 0, {}, 200), -1) << "past 1514 bytes";
}

// Snapshot of everything the application can see.
std::vector<std::uint8_t> snapshot(const esc& e) { return pdi_bytes(e, 0, esc::memory_size); }

TEST(frames, random_sound_frames_never_crash_and_refused_ones_change_nothing) {
  bus b(3);
  // Something for the datagrams to hit: station addresses, mailboxes, buffered SMs, FMMUs.
  for (std::uint16_t i = 0; i < 3; ++i) {
    b.write16(command::apwr, ap(i, reg::station_address), 0x1001 + i);
    fmmu(b, i, 0, 0x10000u + 4u * i, 4, 3, 2, 0x1100, 1, 3);
  }
  const auto every_sync_manager = [&](int n, std::uint16_t start, std::uint16_t len, std::uint8_t control) {
    std::vector<std::uint8_t> sm{static_cast<std::uint8_t>(start), static_cast<std::uint8_t>(start >> 8),
                                 static_cast<std::uint8_t>(len), 0, control, 0, 1, 0};
    EXPECT_EQ(b.send(command::bwr, static_cast<std::uint32_t>(reg::sync_manager0 + 8 * n) << 16, sm).wkc, 3);
  };
  every_sync_manager(0, 0x1000, 32, 0x26);
  every_sync_manager(1, 0x1040, 32, 0x22);
  every_sync_manager(2, 0x1100, 4, 0x64);
  every_sync_manager(3, 0x1180, 4, 0x20);
  std::mt19937 random(4020);
  const auto pick = [&](std::uint32_t n) { return static_cast<std::uint32_t>(random() % n); };
  const std::uint16_t addresses[] = {0x0000, 0x0010, 0x0120, 0x0500, 0x0502, 0x0600, 0x0800, 0x0806,
                                     0x1000, 0x1040, 0x1100, 0x1180, 0x1FF0, 0x0FFE};
  int refused = 0;
  for (int i = 0; i < 4000; ++i) {
    frame_builder fb(broadcast, master_mac);
    const std::uint32_t n = 1 + pick(4);
    for (std::uint32_t k = 0; k < n; ++k) {
      const auto cmd = static_cast<command>(pick(16));
      const std::uint16_t offset = static_cast<std::uint16_t>(addresses[pick(14)] + pick(8));
      const std::uint16_t adp = pick(2) ? static_cast<std::uint16_t>(-static_cast<int>(pick(4)))
                                        : static_cast<std::uint16_t>(0x1000 + pick(4));
      const std::uint32_t address = pick(4) == 0 ? 0x10000u + pick(16) : adp | (std::uint32_t{offset} << 16);
      std::vector<std::uint8_t> data(pick(40));
      for (auto& byte : data) byte = static_cast<std::uint8_t>(random());
      fb.add(cmd, 0, address, data, static_cast<std::uint16_t>(data.size()));
    }
    std::vector<std::uint8_t> f = fb.finish();
    // One in four is damaged: a byte of its headers changed, or cut short.
    const bool damage = pick(4) == 0;
    if (damage) {
      if (pick(2)) {
        f[12 + pick(static_cast<std::uint32_t>(std::min<std::size_t>(f.size() - 12, 30)))] ^=
            static_cast<std::uint8_t>(1u << pick(8));
      } else {
        f.resize(pick(static_cast<std::uint32_t>(f.size())));
      }
    }
    std::array<std::vector<std::uint8_t>, 3> before;
    const bool check = damage;
    if (check) {
      for (std::size_t s = 0; s < 3; ++s) before[s] = snapshot(b.escs[s]);
    }
    const std::vector<std::uint8_t> sent = f;
    const frame_error e = b.wire.pass(f);
    if (!damage) {
      EXPECT_EQ(e, frame_error::none);
    }
    if (e != frame_error::none) {
      ++refused;
      EXPECT_EQ(f, sent) << "a refused frame comes back untouched";
      for (std::size_t s = 0; s < 3; ++s) EXPECT_EQ(snapshot(b.escs[s]), before[s]) << "refused frame " << i;
    }
    // The application runs between frames.
    for (esc& s : b.escs) {
      std::vector<std::uint8_t> m;
      if (s.read_mailbox(0, m) && !s.mailbox_full(1)) (void)s.write_mailbox(1, m);
      (void)s.take_sync_manager_event(2);
      (void)s.write_buffer(3, std::vector<std::uint8_t>{static_cast<std::uint8_t>(i), 0, 0, 0});
      (void)s.take_al_control_event();
      s.advance(pick(1'000'000));
    }
  }
  EXPECT_GT(refused, 100);
  for (const esc& s : b.escs) {
    EXPECT_EQ(s.read8(reg::type), 0xC0) << "identity never written";
    EXPECT_EQ(s.read8(reg::fmmus_supported), esc::fmmu_count);
    EXPECT_GT(s.refused_accesses(), 0u) << "some datagrams hit the end of memory or a mailbox";
  }
}

}  // namespace
}  // namespace cia402::ethercat
