// The emulated ESC against the datagram semantics of ETG.1000.4: every command and its working
// counter, auto-increment and configured addressing, FMMUs at bit offsets, sync-manager hand-over,
// the watchdog, the SII EEPROM interface, and frames that are not sound.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"

namespace cia402::ethercat {
namespace {

constexpr std::array<std::uint8_t, 6> broadcast{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
constexpr std::array<std::uint8_t, 6> master_mac{0x02, 0, 0, 0, 0, 1};

std::vector<std::uint8_t> eeprom() {
  slave_description d;
  d.vendor_id = 0x1234;
  d.product_code = 0x402;
  d.station_alias = 0x77;
  return sii_image(d);
}

std::uint32_t ap(std::uint16_t position, std::uint16_t offset) {
  return static_cast<std::uint16_t>(-position) | (static_cast<std::uint32_t>(offset) << 16);
}
std::uint32_t fp(std::uint16_t station, std::uint16_t offset) {
  return station | (static_cast<std::uint32_t>(offset) << 16);
}

// One datagram through the chain: its data and working counter as they came back.
struct result {
  std::vector<std::uint8_t> data;
  std::uint16_t wkc = 0;
  std::uint16_t adp = 0;
};

struct bus {
  std::vector<esc> escs;
  chain wire;
  explicit bus(int n) {
    escs.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) escs.emplace_back(eeprom());
    for (esc& e : escs) wire.add(e);
  }
  result send(command c, std::uint32_t address, std::vector<std::uint8_t> data) {
    frame_builder b(broadcast, master_mac);
    const long at = b.add(c, 1, address, data, static_cast<std::uint16_t>(data.size()));
    std::vector<std::uint8_t> f = b.finish();
    EXPECT_EQ(wire.pass(f), frame_error::none);
    result r;
    const auto* p = f.data() + at;
    r.data.assign(p, p + data.size());
    r.wkc = static_cast<std::uint16_t>(p[data.size()] | (p[data.size() + 1] << 8));
    r.adp = static_cast<std::uint16_t>(f[static_cast<std::size_t>(at) - 8] | (f[static_cast<std::size_t>(at) - 7] << 8));
    return r;
  }
  result write16(command c, std::uint32_t address, std::uint16_t v) {
    return send(c, address, {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8)});
  }
  std::uint16_t value16(const result& r) { return static_cast<std::uint16_t>(r.data[0] | (r.data[1] << 8)); }
};

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

TEST(esc, read_only_registers_keep_their_value) {
  bus b(1);
  const std::uint16_t before = b.escs[0].read16(reg::al_status);
  EXPECT_EQ(b.write16(command::apwr, ap(0, reg::al_status), 0x0008).wkc, 1) << "served, as an ESC does";
  EXPECT_EQ(b.escs[0].read16(reg::al_status), before);
  EXPECT_EQ(b.escs[0].read8(reg::type), 0xC0);
}

TEST(esc, armw_reads_at_one_slave_and_writes_the_rest) {
  bus b(3);
  b.escs[0].write16(reg::dc_receive_time, 0x4242);
  const result r = b.send(command::armw, ap(0, reg::dc_receive_time), {0, 0});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(b.value16(r), 0x4242);
  EXPECT_EQ(b.escs[1].read16(reg::dc_receive_time), 0x4242);
  EXPECT_EQ(b.escs[2].read16(reg::dc_receive_time), 0x4242);
}

TEST(esc, an_access_past_the_memory_is_not_served_and_counted) {
  bus b(1);
  const result r = b.send(command::aprd, ap(0, 0x1FFE), {0, 0, 0, 0});
  EXPECT_EQ(r.wkc, 0);
  EXPECT_EQ(b.escs[0].refused_accesses(), 1u);
}

// FMMU i: logical start, length, start bit, end bit, physical start, physical bit, type, active.
void fmmu(bus& b, int slave, int i, std::uint32_t log, std::uint16_t len, std::uint8_t sbit, std::uint8_t ebit,
          std::uint16_t phys, std::uint8_t pbit, std::uint8_t type) {
  std::vector<std::uint8_t> f(16, 0);
  f[0] = static_cast<std::uint8_t>(log);
  f[1] = static_cast<std::uint8_t>(log >> 8);
  f[2] = static_cast<std::uint8_t>(log >> 16);
  f[3] = static_cast<std::uint8_t>(log >> 24);
  f[4] = static_cast<std::uint8_t>(len);
  f[5] = static_cast<std::uint8_t>(len >> 8);
  f[6] = sbit;
  f[7] = ebit;
  f[8] = static_cast<std::uint8_t>(phys);
  f[9] = static_cast<std::uint8_t>(phys >> 8);
  f[10] = pbit;
  f[11] = type;
  f[12] = 1;
  EXPECT_EQ(b.send(command::apwr, ap(static_cast<std::uint16_t>(slave), static_cast<std::uint16_t>(reg::fmmu0 + 16 * i)), f).wkc, 1);
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

// SM n: start, length, control, enabled.
void sync_manager(bus& b, int n, std::uint16_t start, std::uint16_t len, std::uint8_t control) {
  std::vector<std::uint8_t> s{static_cast<std::uint8_t>(start), static_cast<std::uint8_t>(start >> 8),
                              static_cast<std::uint8_t>(len), static_cast<std::uint8_t>(len >> 8), control, 0, 1, 0};
  EXPECT_EQ(b.send(command::apwr, ap(0, static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n)), s).wkc, 1);
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
  b.escs[0].write16(reg::watchdog_time_process_data, 100);  // 100 x 100 us = 10 ms
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

}  // namespace
}  // namespace cia402::ethercat
