// The bytes a master writes into an FMMU (16 bytes at 0x0600 + 16 i) and a sync manager (8 bytes at
// 0x0800 + 8 n), laid out as ETG.1000.4 lays them out. Shared by the ESC tests (esc_bus.hpp), the
// drive slave's bench (drive_bench.hpp) and the fuzz target tests/fuzz/ethercat_slave_fuzz.cpp.
#pragma once

#include <cstdint>
#include <vector>

#include "cia402/ethercat/sii/slave_information.hpp"

namespace cia402::ethercat::register_bytes {

// FMMU: logical start, length, start bit, end bit, physical start, physical bit, type, active.
inline std::vector<std::uint8_t> fmmu(std::uint32_t log, std::uint16_t len, std::uint16_t phys, std::uint8_t type,
                                      std::uint8_t sbit = 0, std::uint8_t ebit = 7, std::uint8_t pbit = 0) {
  std::vector<std::uint8_t> f(16, 0);
  for (int k = 0; k < 4; ++k) f[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(log >> (8 * k));
  f[4] = static_cast<std::uint8_t>(len);
  f[5] = static_cast<std::uint8_t>(len >> 8);
  f[6] = sbit;
  f[7] = ebit;
  f[8] = static_cast<std::uint8_t>(phys);
  f[9] = static_cast<std::uint8_t>(phys >> 8);
  f[10] = pbit;
  f[11] = type;
  f[12] = 1;
  return f;
}

// Sync manager: start, length, control, enabled.
inline std::vector<std::uint8_t> sync_manager(std::uint16_t start, std::uint16_t len, std::uint8_t control) {
  return {static_cast<std::uint8_t>(start), static_cast<std::uint8_t>(start >> 8), static_cast<std::uint8_t>(len),
          static_cast<std::uint8_t>(len >> 8), control, 0, 1, 0};
}
inline std::vector<std::uint8_t> sync_manager(const sync_manager_description& d) {
  return sync_manager(d.start, d.length, d.control);
}

}  // namespace cia402::ethercat::register_bytes
