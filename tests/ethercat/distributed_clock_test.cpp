// The distributed clocks unit of the emulated ESC (ET1100 datasheet 0x0900..0x09FF, ETG.1000.4 §9.1),
// driven as a master drives it: the feature bits a master checks, receive times latched by a BWR to
// 0x0900 on a chain whose hops take time, the offset and delay a master computes from them, the
// drift distribution write (FRMW of 0x0910) leaving no difference when they are right, and SYNC0.
// Then the virtual drive on it (ETG.1020 §5.3): 0x1C32 / 0x1C33, DC SYNC0 mode chosen on the way to
// SAFE-OP, and the drive taking its outputs on SYNC0.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "cia402/ethercat/slave/coe_slave.hpp"
#include "drive_bench.hpp"

namespace cia402::ethercat {
namespace {

struct line {
  std::vector<esc> escs;
  chain wire;
  explicit line(int n) {
    escs.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) escs.emplace_back(sii_image(slave_description{}));
    for (esc& e : escs) wire.add(e);
    for (int i = 0; i < n; ++i) {
      std::vector<std::uint8_t> a{static_cast<std::uint8_t>(0x01 + i), 0x10};
      send(command::apwr, static_cast<std::uint16_t>(-i), reg::station_address, a);
    }
  }
  // One datagram; its data and working counter as they came back.
  std::vector<std::uint8_t> send(command c, std::uint16_t adp, std::uint16_t ado, std::vector<std::uint8_t>& data,
                                 std::uint16_t* wkc = nullptr) {
    frame_builder fb({0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}, {0x02, 0, 0, 0, 0, 1});
    const long at = fb.add(c, 0, adp | (static_cast<std::uint32_t>(ado) << 16), data, static_cast<std::uint16_t>(data.size()));
    std::vector<std::uint8_t> f = fb.finish();
    EXPECT_EQ(wire.pass(f), frame_error::none);
    data.assign(f.begin() + at, f.begin() + at + static_cast<long>(data.size()));
    if (wkc != nullptr) *wkc = static_cast<std::uint16_t>(f[static_cast<std::size_t>(at) + data.size()]);
    return data;
  }
  static std::uint16_t station(int i) { return static_cast<std::uint16_t>(0x1001 + i); }
  std::uint64_t read(int i, std::uint16_t ado, std::size_t bytes) {
    std::vector<std::uint8_t> d(bytes, 0);
    send(command::fprd, station(i), ado, d);
    std::uint64_t v = 0;
    for (std::size_t k = bytes; k-- > 0;) v = (v << 8) | d[k];
    return v;
  }
  void write(int i, std::uint16_t ado, std::uint64_t v, std::size_t bytes) {
    std::vector<std::uint8_t> d(bytes);
    for (std::size_t k = 0; k < bytes; ++k) d[k] = static_cast<std::uint8_t>(v >> (8 * k));
    send(command::fpwr, station(i), ado, d);
  }
  void advance(std::uint64_t ns) {
    for (esc& e : escs) e.advance(ns);
  }
};

TEST(distributed_clocks, the_controller_offers_64_bit_dc) {
  line l(1);
  EXPECT_EQ(l.read(0, reg::features, 2) & 0x000C, 0x000Cu) << "0x0008 bit 2 DC available, bit 3 64-bit";
}

TEST(distributed_clocks, a_bwr_to_0x0900_latches_each_port_when_the_frame_passes_it) {
  line l(3);
  l.escs[1].advance(1'000'000);  // powered on 1 ms before the others
  std::vector<std::uint8_t> any(4, 0xAB);
  l.send(command::bwr, 0, reg::dc_receive_time, any);
  const std::uint32_t hop = l.wire.hop_delay_ns;
  for (int i = 0; i < 3; ++i) {
    const std::uint64_t local = l.escs[static_cast<std::size_t>(i)].local_time();
    const std::uint64_t arrival = local + static_cast<std::uint64_t>(i) * hop;
    EXPECT_EQ(l.read(i, reg::dc_receive_time, 4), arrival & 0xFFFFFFFFu) << "port 0 of " << i;
    EXPECT_EQ(l.read(i, reg::dc_receive_time_unit, 8), arrival) << "processing unit of " << i;
    const std::uint64_t back = i < 2 ? arrival + 2u * static_cast<std::uint64_t>(2 - i) * hop : 0;
    EXPECT_EQ(l.read(i, reg::dc_receive_time_port1, 4), back & 0xFFFFFFFFu) << "port 1 of " << i;
  }
}

TEST(distributed_clocks, offsets_and_delays_from_the_receive_times_leave_no_difference) {
  line l(3);
  l.escs[1].advance(3'000'000);
  l.escs[2].advance(7'250'000);
  std::vector<std::uint8_t> any(4, 0);
  l.send(command::bwr, 0, reg::dc_receive_time, any);
  // As a master computes them: the delay from the port time differences, the offset from the
  // processing units' receive times, the first controller the reference clock.
  std::uint64_t span[3];
  std::uint64_t unit[3];
  for (int i = 0; i < 3; ++i) {
    const std::uint64_t p0 = l.read(i, reg::dc_receive_time, 4);
    const std::uint64_t p1 = l.read(i, reg::dc_receive_time_port1, 4);
    span[i] = i < 2 ? p1 - p0 : 0;
    unit[i] = l.read(i, reg::dc_receive_time_unit, 8);
  }
  for (int i = 1; i < 3; ++i) {
    const std::uint64_t delay = (span[0] - span[i]) / 2;
    EXPECT_EQ(delay, static_cast<std::uint64_t>(i) * l.wire.hop_delay_ns);
    l.write(i, reg::dc_system_time_delay, delay, 4);
    l.write(i, reg::dc_system_time_offset, unit[0] - unit[i] + delay, 8);
  }
  l.advance(100'000);
  // Drift distribution: FRMW of the reference's system time to every other.
  std::vector<std::uint8_t> time(8, 0);
  std::uint16_t wkc = 0;
  l.send(command::frmw, line::station(0), reg::dc_system_time, time, &wkc);
  EXPECT_EQ(wkc, 3);
  for (int i = 1; i < 3; ++i) EXPECT_EQ(l.read(i, reg::dc_system_time_difference, 4), 0u) << i;
  EXPECT_EQ(l.escs[1].system_time(), l.escs[0].system_time()) << "one system time";
  EXPECT_EQ(l.escs[2].system_time(), l.escs[0].system_time());
  // Without the delay the difference shows the hops (bit 31 clear: the local copy is ahead).
  l.write(2, reg::dc_system_time_delay, 0, 4);
  l.send(command::frmw, line::station(0), reg::dc_system_time, time, &wkc);
  EXPECT_EQ(l.read(2, reg::dc_system_time_difference, 4), 2u * l.wire.hop_delay_ns);
}

// A master whose offsets leave out the hop delay (0x092C then shows the delay on every slave, as
// SOEM's ec_configdc leaves it here): the drift distribution's writes steer each clock until the
// difference is 0 and every controller has the reference's system time (the time control loop).
TEST(distributed_clocks, the_time_control_loop_steers_the_difference_the_offsets_left_to_zero) {
  constexpr int n = 16;
  line l(n);
  for (int i = 1; i < n; ++i) l.escs[static_cast<std::size_t>(i)].advance(static_cast<std::uint64_t>(i) * 1'000'003);
  std::vector<std::uint8_t> any(4, 0);
  l.send(command::bwr, 0, reg::dc_receive_time, any);
  const std::uint64_t unit0 = l.read(0, reg::dc_receive_time_unit, 8);
  for (int i = 1; i < n; ++i) {
    l.write(i, reg::dc_system_time_delay, static_cast<std::uint64_t>(i) * l.wire.hop_delay_ns, 4);
    l.write(i, reg::dc_system_time_offset, unit0 - l.read(i, reg::dc_receive_time_unit, 8), 8);
  }
  const auto difference_ns = [&](int i) {
    const auto d = static_cast<std::uint32_t>(l.read(i, reg::dc_system_time_difference, 4));
    return (d & 0x80000000u) ? -static_cast<std::int64_t>(d & 0x7FFFFFFFu) : static_cast<std::int64_t>(d);
  };
  std::vector<std::uint8_t> time(8, 0);
  l.send(command::frmw, line::station(0), reg::dc_system_time, time);
  for (int i = 1; i < n; ++i) {
    EXPECT_EQ(difference_ns(i), -static_cast<std::int64_t>(i) * l.wire.hop_delay_ns) << "the first write finds the delay, " << i;
  }
  int writes = 1;
  const auto all_zero = [&] {
    for (int i = 1; i < n; ++i) {
      if (difference_ns(i) != 0) return false;
    }
    return true;
  };
  std::int64_t last_of_15 = difference_ns(15);
  while (!all_zero() && writes < 1000) {
    l.advance(1'000'000);
    time.assign(8, 0);
    l.send(command::frmw, line::station(0), reg::dc_system_time, time);
    ++writes;
    const std::int64_t d = difference_ns(15);
    ASSERT_LE(d, 0) << "no overshoot, write " << writes;
    ASSERT_GE(d, last_of_15) << "it only shrinks, write " << writes;
    ASSERT_LE(d - last_of_15, 1000) << "at most 1 us a write";
    last_of_15 = d;
  }
  EXPECT_TRUE(all_zero());
  EXPECT_LT(writes, 200) << "a few hundred cycles of drift distribution at most";
  for (int i = 1; i < n; ++i) EXPECT_EQ(l.escs[static_cast<std::size_t>(i)].system_time(), l.escs[0].system_time()) << i;
  for (int k = 0; k < 10; ++k) {  // and it stays there
    l.advance(1'000'000);
    time.assign(8, 0);
    l.send(command::frmw, line::station(0), reg::dc_system_time, time);
  }
  EXPECT_TRUE(all_zero());
}

TEST(distributed_clocks, sync0_pulses_at_the_start_time_and_every_cycle_after) {
  line l(1);
  esc& e = l.escs[0];
  e.advance(10'000'000);
  const std::uint64_t start = e.system_time() + 2'500'000;
  l.write(0, reg::dc_sync0_cycle_time, 1'000'000, 4);
  l.write(0, reg::dc_start_time, start, 8);
  l.write(0, reg::dc_activation, 0x03, 1);
  EXPECT_TRUE(e.sync0_active());
  std::vector<int> pulses;
  for (int ms = 1; ms <= 6; ++ms) {
    e.advance(1'000'000);
    if (e.take_sync0_event()) pulses.push_back(ms);
  }
  EXPECT_EQ(pulses, (std::vector<int>{3, 4, 5, 6})) << "at 2.5 ms, then each 1 ms";
  EXPECT_EQ(l.read(0, reg::dc_start_time, 8), start + 4'000'000) << "0x0990 reads as the next pulse";
  // Missed time is one pulse, not a burst.
  e.advance(5'000'000);
  EXPECT_TRUE(e.take_sync0_event());
  EXPECT_FALSE(e.take_sync0_event());
  l.write(0, reg::dc_activation, 0x00, 1);
  e.advance(3'000'000);
  EXPECT_FALSE(e.take_sync0_event()) << "deactivated";
}

using testing::bench;

// SYNC0 as a master starts it: cycle, start time `start_in_ns` after the slave's system time, activation.
void start_sync0(bench& b, std::uint32_t cycle_ns, std::uint64_t start_in_ns) {
  std::vector<std::uint8_t> now(8, 0);
  now = b.send(command::fprd, b.fp(reg::dc_system_time), now).data;
  std::uint64_t st = 0;
  for (std::size_t k = 8; k-- > 0;) st = (st << 8) | now[k];
  const std::uint64_t start = st + start_in_ns;
  std::vector<std::uint8_t> c(4), t(8);
  for (std::size_t k = 0; k < 4; ++k) c[k] = static_cast<std::uint8_t>(cycle_ns >> (8 * k));
  for (std::size_t k = 0; k < 8; ++k) t[k] = static_cast<std::uint8_t>(start >> (8 * k));
  EXPECT_EQ(b.send(command::fpwr, b.fp(reg::dc_sync0_cycle_time), c).wkc, 1);
  EXPECT_EQ(b.send(command::fpwr, b.fp(reg::dc_start_time), t).wkc, 1);
  EXPECT_EQ(b.send(command::fpwr, b.fp(reg::dc_activation), {0x03}).wkc, 1);
}

// PRE-OP to the request for SAFE-OP with the process data set up; the AL status after it.
std::uint16_t to_safe_op(bench& b) {
  const slave_description& d = b.slave.description();
  b.sync_manager(2, d.sync_managers[2]);
  b.sync_manager(3, d.sync_managers[3]);
  b.fmmu(0, 0x10000, d.sync_managers[2].length, d.sync_managers[2].start, 2);
  b.fmmu(1, 0x10100, d.sync_managers[3].length, d.sync_managers[3].start, 1);
  return b.request(4);
}

TEST(drive_slave_dc, sync0_started_by_the_master_is_dc_mode_and_the_drive_takes_its_outputs_on_it) {
  bench b;
  b.to_pre_op();
  EXPECT_EQ(b.upload(sync_parameter::outputs, sync_parameter::mode), sync_mode::free_run);
  EXPECT_EQ(b.upload(sync_parameter::outputs, sync_parameter::supported), 0x0007) << "free run, SM, DC SYNC0";
  start_sync0(b, 4'000'000, 10'000'000);  // a pulse 10 ms from now, then every 4 ms
  EXPECT_EQ(to_safe_op(b), 4);
  EXPECT_EQ(b.request(8), 4) << "OP waits for the first pulse";
  b.drain_mailbox();
  EXPECT_EQ(b.upload(sync_parameter::outputs, sync_parameter::mode), sync_mode::dc_sync0);
  EXPECT_EQ(b.upload(sync_parameter::inputs, sync_parameter::mode), sync_mode::dc_sync0);
  EXPECT_EQ(b.upload(sync_parameter::outputs, sync_parameter::sync0_cycle_time), 4'000'000);
  // Shutdown (0x0006) from SWITCH ON DISABLED: the drive sees it at the first pulse, not before.
  const std::uint64_t pulse = b.slave.controller().read32(reg::dc_start_time) |
                              (std::uint64_t{b.slave.controller().read32(reg::dc_start_time + 4)} << 32);
  int cycles = 0;
  std::uint16_t sw = b.cycle(0x0006);
  while ((sw & 0x6F) != 0x21 && cycles < 30) {
    EXPECT_LE(b.slave.controller().system_time(), pulse + 2'000'000) << "no change long after the pulse";
    sw = b.cycle(0x0006);
    ++cycles;
  }
  EXPECT_EQ(sw & 0x6F, 0x21) << "READY TO SWITCH ON";
  EXPECT_GE(b.slave.controller().system_time(), pulse) << "not before the pulse";
}

// Until its first SYNC0 pulse a drive in DC SYNC0 mode takes no outputs, so it does not say OP before
// it: the request waits in SAFE-OP without an error, the pulse enters OP and applies that pulse's
// outputs; a pulse that never comes refuses OP with 0x002D after first_pulse_wait_us.
TEST(drive_slave_dc, an_op_request_waits_for_the_first_pulse_and_is_refused_when_none_comes) {
  {
    bench b;
    b.to_pre_op();
    start_sync0(b, 1'000'000, 20'000'000);  // the first pulse 20 ms from now
    const std::uint64_t pulse = b.slave.controller().read32(reg::dc_start_time) |
                                (std::uint64_t{b.slave.controller().read32(reg::dc_start_time + 4)} << 32);
    EXPECT_EQ(to_safe_op(b), 4);
    EXPECT_EQ(b.request(8), 4) << "SAFE-OP, no error flag";
    EXPECT_EQ(b.read16(reg::al_status_code), al_code::none);
    std::uint16_t sw = 0;
    int cycles = 0;
    while (b.read16(reg::al_status) != 8 && cycles < 100) {
      EXPECT_EQ(b.read16(reg::al_status), 4) << "no error while it waits";
      sw = b.cycle(0x0006);  // Shutdown, waiting in the outputs
      ++cycles;
    }
    ASSERT_EQ(b.read16(reg::al_status), 8) << "OP at the pulse";
    EXPECT_GE(b.slave.controller().system_time(), pulse);
    EXPECT_LE(b.slave.controller().system_time(), pulse + 2'000'000) << "not later than the cycle after it";
    EXPECT_EQ(sw & 0x6F, 0x21) << "READY TO SWITCH ON: the pulse that entered OP applied the outputs";
  }
  {
    bench b;
    b.to_pre_op();
    start_sync0(b, 1'000'000, 30'000'000'000);  // a pulse far beyond the wait
    EXPECT_EQ(to_safe_op(b), 4);
    EXPECT_EQ(b.request(8), 4);
    b.run(static_cast<int>(first_pulse_wait_us / 1000));
    EXPECT_EQ(b.read16(reg::al_status), 0x14) << "SAFE-OP with the error flag";
    EXPECT_EQ(b.read16(reg::al_status_code), al_code::no_sync);
    EXPECT_EQ(b.cycle(0x0006) & 0x6F, 0x40) << "the outputs were never applied: SWITCH ON DISABLED";
  }
}

// SOEM's slaveinfo -sdo reads every sub-index up to sub 0's count: 0x1C32 and 0x1C33 have no gap
// (ETG.1020 §5.3 names subs 7 and 8 too), and the one command sub is read-only here.
TEST(drive_slave_dc, the_sync_manager_parameters_have_every_sub_index_up_to_their_count) {
  bench b;
  b.to_pre_op();
  for (const std::uint16_t index : {sync_parameter::outputs, sync_parameter::inputs}) {
    const std::int64_t count = b.upload(index, 0);
    EXPECT_EQ(count, sync_parameter::sync_error_count);
    for (std::int64_t sub = 1; sub <= count; ++sub) {
      SCOPED_TRACE("0x" + std::to_string(index) + " sub " + std::to_string(sub));
      b.upload(index, static_cast<std::uint8_t>(sub));  // fails on an abort
    }
    EXPECT_EQ(b.download(index, 8, 1, 2), 0x06010002u) << "the get-cycle-time command is not offered";
  }
}

TEST(drive_slave_dc, pulses_that_find_no_new_outputs_are_counted_in_0x1c32_0b) {
  bench b;
  b.to_pre_op();
  start_sync0(b, 1'000'000, 1'000'000);
  EXPECT_EQ(to_safe_op(b), 4);
  EXPECT_EQ(b.request(8), 8);
  for (int i = 0; i < 5; ++i) b.cycle(0x0000);
  b.drain_mailbox();
  const std::int64_t fed = b.upload(sync_parameter::outputs, sync_parameter::sync_error_count);
  b.run(6);  // no outputs for six pulses
  EXPECT_GE(b.upload(sync_parameter::outputs, sync_parameter::sync_error_count), fed + 5);
}

TEST(drive_slave_dc, dc_mode_without_sync0_or_with_too_short_a_cycle_is_refused) {
  {
    bench b;
    b.to_pre_op();
    EXPECT_EQ(b.download(sync_parameter::outputs, sync_parameter::mode, 3, 2), 0x06090030u) << "SYNC1 not offered";
    EXPECT_EQ(b.download(sync_parameter::outputs, sync_parameter::mode, 2, 2), 0u);
    EXPECT_EQ(to_safe_op(b), 0x12);
    EXPECT_EQ(b.read16(reg::al_status_code), al_code::invalid_dc_sync_configuration);
  }
  {
    bench b;
    b.to_pre_op();
    start_sync0(b, 500'000, 1'000'000);
    EXPECT_EQ(to_safe_op(b), 0x12);
    EXPECT_EQ(b.read16(reg::al_status_code), al_code::invalid_dc_sync_cycle_time);
  }
  {
    bench b;
    b.to_pre_op();
    EXPECT_EQ(to_safe_op(b), 4);
    b.drain_mailbox();
    EXPECT_EQ(b.download(sync_parameter::outputs, sync_parameter::mode, 1, 2), 0x08000022u) << "PRE-OP only";
  }
}

TEST(drive_slave_dc, its_esi_offers_dc_sync0) {
  bench b;
  const std::string x = esi_xml(b.slave.description());
  EXPECT_NE(x.find("<Dc>"), std::string::npos);
  EXPECT_NE(x.find("<AssignActivate>#x0300</AssignActivate>"), std::string::npos);
}

}  // namespace
}  // namespace cia402::ethercat
