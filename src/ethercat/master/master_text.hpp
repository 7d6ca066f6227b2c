// What the master's sources share: how a slave and a number are named in an error, how long the
// master waits for a mailbox (link time: a slave that has not done it by then will not), the
// registers more than one of them writes, and little-endian bytes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/hex_text.hpp"

namespace cia402::ethercat::detail {

inline constexpr std::uint64_t mailbox_us = 1'000'000;
inline constexpr std::uint32_t poll_us = 200;

// Registers (ETG.1000.4 table 29 ff.), written out rather than taken from the emulated ESC: the
// master is for any slave controller.
inline constexpr std::uint16_t reg_fmmu0 = 0x0600;
inline constexpr std::uint16_t reg_sm0 = 0x0800;

// The most PDO entries a direction may bring (the learnt mapping stops there, whatever a slave says).
inline constexpr std::size_t max_mapped_entries = 512;

inline void put_le(std::vector<std::uint8_t>& v, std::uint64_t value, unsigned bytes) {
  for (unsigned i = 0; i < bytes; ++i) v.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

/// "0x0001": the core's to_hex as a string.
inline std::string hex(std::uint32_t v, int digits) { return to_hex(v, digits).c_str(); }

inline std::string slave_text(const ecat_slave& s) {
  return "slave " + std::to_string(s.position) + " (station " + hex(s.station, 4) + ")";
}

}  // namespace cia402::ethercat::detail
