// A chain of emulated ESCs for the ESC tests (esc_test.cpp, esc_commands_test.cpp): datagrams sent
// through it as a master sends them, and the FMMU and sync-manager registers written as ETG.1000.4
// lays them out.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "one_datagram.hpp"
#include "register_bytes.hpp"

namespace cia402::ethercat::esc_bus {

using testing::broadcast;
using testing::master_mac;

inline std::vector<std::uint8_t> eeprom() {
  slave_description d;
  d.vendor_id = 0x1234;
  d.product_code = 0x402;
  d.station_alias = 0x77;
  return sii_image(d);
}

inline std::uint32_t ap(std::uint16_t position, std::uint16_t offset) {
  return static_cast<std::uint16_t>(-position) | (static_cast<std::uint32_t>(offset) << 16);
}
inline std::uint32_t fp(std::uint16_t station, std::uint16_t offset) {
  return station | (static_cast<std::uint32_t>(offset) << 16);
}

// One datagram through the chain: its data, working counter and ADP as they came back.
using result = testing::datagram_answer;

struct bus {
  std::vector<esc> escs;
  chain wire;
  explicit bus(int n) {
    escs.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) escs.emplace_back(eeprom());
    for (esc& e : escs) wire.add(e);
  }
  result send(command c, std::uint32_t address, std::vector<std::uint8_t> data) {
    return testing::one_datagram(wire, c, 1, address, data);
  }
  result write16(command c, std::uint32_t address, std::uint16_t v) {
    return send(c, address, {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8)});
  }
  std::uint16_t value16(const result& r) { return static_cast<std::uint16_t>(r.data[0] | (r.data[1] << 8)); }
};


// FMMU i: logical start, length, start bit, end bit, physical start, physical bit, type, active.
inline void fmmu(bus& b, int slave, int i, std::uint32_t log, std::uint16_t len, std::uint8_t sbit, std::uint8_t ebit,
          std::uint16_t phys, std::uint8_t pbit, std::uint8_t type) {
  const std::vector<std::uint8_t> f = register_bytes::fmmu(log, len, phys, type, sbit, ebit, pbit);
  EXPECT_EQ(b.send(command::apwr, ap(static_cast<std::uint16_t>(slave), static_cast<std::uint16_t>(reg::fmmu0 + 16 * i)), f).wkc, 1);
}

// SM n: start, length, control, enabled.
inline void sync_manager(bus& b, int n, std::uint16_t start, std::uint16_t len, std::uint8_t control) {
  EXPECT_EQ(b.send(command::apwr, ap(0, static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n)),
                   register_bytes::sync_manager(start, len, control)).wkc, 1);
}

}  // namespace cia402::ethercat::esc_bus
