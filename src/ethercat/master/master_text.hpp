// What the master's sources share: how a slave and a number are named in an error, and how long the
// master waits for a mailbox (link time: a slave that has not done it by then will not).
#pragma once

#include <cstdint>
#include <string>

#include "cia402/ethercat/master/ecat_master.hpp"

namespace cia402::ethercat::detail {

inline constexpr std::uint64_t mailbox_us = 1'000'000;
inline constexpr std::uint32_t poll_us = 200;

inline std::string hex(std::uint32_t v, int digits) {
  static const char* d = "0123456789ABCDEF";
  std::string s = "0x";
  for (int i = digits - 1; i >= 0; --i) s += d[(v >> (4 * i)) & 0xF];
  return s;
}

inline std::string slave_text(const ecat_slave& s) {
  return "slave " + std::to_string(s.position) + " (station " + hex(s.station, 4) + ")";
}

}  // namespace cia402::ethercat::detail
