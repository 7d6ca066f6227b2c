// The virtual drive as one EtherCAT slave on the in-process wire, and a master's datagrams by hand:
// registers, AL requests, sync managers, CoE SDO through the mailboxes, process data in OP. Shared
// by the slave's tests (drive_slave_test.cpp, mailbox_repeat_test.cpp, distributed_clock_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/coe/mailbox.hpp"
#include "one_datagram.hpp"
#include "register_bytes.hpp"

namespace cia402::ethercat::testing {

using drive_slave = apps::virtual_drive_slave;

constexpr std::uint16_t station = 0x1001;

struct bench {
  drive_slave slave{standard_profile(), 7};
  chain wire;
  std::uint8_t counter = 0;
  bench() { wire.add(slave.controller()); }

  using answer = datagram_answer;
  answer send(command c, std::uint32_t address, std::vector<std::uint8_t> data) {
    return one_datagram(wire, c, 0, address, data);
  }
  std::uint32_t fp(std::uint16_t offset) const { return station | (static_cast<std::uint32_t>(offset) << 16); }
  std::uint16_t read16(std::uint16_t offset) {
    const answer a = send(command::fprd, fp(offset), {0, 0});
    return static_cast<std::uint16_t>(a.data[0] | (a.data[1] << 8));
  }
  void write16(std::uint16_t offset, std::uint16_t v) {
    EXPECT_EQ(send(command::fpwr, fp(offset), {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8)}).wkc, 1);
  }
  void run(int cycles) {
    for (int i = 0; i < cycles; ++i) slave.step(1000);
  }
  // Requests an AL state and returns the AL status after the slave's next cycle.
  std::uint16_t request(std::uint16_t state) {
    write16(reg::al_control, state);
    run(1);
    return read16(reg::al_status);
  }
  void sync_manager(int n, const sync_manager_description& d) {
    const std::vector<std::uint8_t> s = register_bytes::sync_manager(d);
    EXPECT_EQ(send(command::fpwr, fp(static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n)), s).wkc, 1);
  }
  void to_pre_op() {
    EXPECT_EQ(send(command::apwr, 0 | (static_cast<std::uint32_t>(reg::station_address) << 16), {0x01, 0x10}).wkc, 1);
    sync_manager(0, slave.description().sync_managers[0]);
    sync_manager(1, slave.description().sync_managers[1]);
    EXPECT_EQ(request(2), 2);
  }
  // A CoE SDO request through the mailbox; the slave's reply mailbox.
  std::vector<std::uint8_t> sdo(std::vector<std::uint8_t> body) {
    std::vector<std::uint8_t> m(mailbox_size, 0);
    mailbox_header h;
    h.length = static_cast<std::uint16_t>(2 + body.size());
    h.type = mailbox_type::coe;
    h.counter = static_cast<std::uint8_t>(++counter % 7 + 1);
    write_mailbox_header(h, m.data());
    m[7] = 0x20;  // SDO request
    std::copy(body.begin(), body.end(), m.begin() + 8);
    EXPECT_EQ(send(command::fpwr, fp(mailbox_out_start), m).wkc, 1);
    run(1);
    const answer a = send(command::fprd, fp(mailbox_in_start), std::vector<std::uint8_t>(mailbox_size, 0));
    EXPECT_EQ(a.wkc, 1) << "a reply is waiting";
    return a.data;
  }
  // Reads every mailbox the slave has queued (emergencies), so the next SDO's answer comes first.
  void drain_mailbox() {
    for (int i = 0; i < 32; ++i) {
      run(1);
      if (send(command::fprd, fp(mailbox_in_start), std::vector<std::uint8_t>(mailbox_size, 0)).wkc == 0) return;
    }
  }
  std::int64_t upload(std::uint16_t index, std::uint8_t sub) {
    const std::vector<std::uint8_t> r = sdo({0x40, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub, 0, 0, 0, 0});
    EXPECT_EQ(r[8] & 0xE0, 0x40) << "SDO abort " << std::hex << (r[12] | (r[13] << 8) | (r[14] << 16) | (r[15] << 24));
    return r[12] | (r[13] << 8) | (r[14] << 16) | (static_cast<std::int64_t>(r[15]) << 24);
  }
  std::uint32_t download(std::uint16_t index, std::uint8_t sub, std::uint32_t v, int bytes) {
    const std::uint8_t cmd = bytes == 1 ? 0x2F : bytes == 2 ? 0x2B : 0x23;
    const std::vector<std::uint8_t> r = sdo({cmd, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub,
                                             static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8),
                                             static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 24)});
    return r[8] == 0x60 ? 0 : static_cast<std::uint32_t>(r[12] | (r[13] << 8) | (r[14] << 16) | (r[15] << 24));
  }
  void fmmu(int i, std::uint32_t log, std::uint16_t len, std::uint16_t phys, std::uint8_t type) {
    const std::vector<std::uint8_t> f = register_bytes::fmmu(log, len, phys, type);
    EXPECT_EQ(send(command::fpwr, fp(static_cast<std::uint16_t>(reg::fmmu0 + 16 * i)), f).wkc, 1);
  }
  void to_op() {
    to_pre_op();
    const slave_description& d = slave.description();
    sync_manager(2, d.sync_managers[2]);
    sync_manager(3, d.sync_managers[3]);
    fmmu(0, 0x10000, d.sync_managers[2].length, d.sync_managers[2].start, 2);
    fmmu(1, 0x10100, d.sync_managers[3].length, d.sync_managers[3].start, 1);
    EXPECT_EQ(request(4), 4);
    EXPECT_EQ(request(8), 8);
  }
  // One process data cycle: the control word out, the status word back.
  std::uint16_t cycle(std::uint16_t control_word) {
    std::vector<std::uint8_t> out(slave.output_bytes(), 0);
    out[0] = static_cast<std::uint8_t>(control_word);
    out[1] = static_cast<std::uint8_t>(control_word >> 8);
    EXPECT_EQ(send(command::lwr, 0x10000, out).wkc, 1);
    run(1);
    const answer in = send(command::lrd, 0x10100, std::vector<std::uint8_t>(slave.input_bytes(), 0));
    EXPECT_EQ(in.wkc, 1);
    return static_cast<std::uint16_t>(in.data[0] | (in.data[1] << 8));
  }
};

}  // namespace cia402::ethercat::testing
