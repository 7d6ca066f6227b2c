// Little-endian fields of mailboxes (EtherCAT is little-endian throughout), for the codec's sources.
#pragma once

#include <cstdint>
#include <vector>

namespace cia402::ethercat::detail {

inline std::uint16_t le16(const std::uint8_t* p) noexcept { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
inline std::uint32_t le32(const std::uint8_t* p) noexcept {
  return le16(p) | (static_cast<std::uint32_t>(le16(p + 2)) << 16);
}
inline void put16(std::vector<std::uint8_t>& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v));
  b.push_back(static_cast<std::uint8_t>(v >> 8));
}
inline void put32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  put16(b, static_cast<std::uint16_t>(v));
  put16(b, static_cast<std::uint16_t>(v >> 16));
}

}  // namespace cia402::ethercat::detail
