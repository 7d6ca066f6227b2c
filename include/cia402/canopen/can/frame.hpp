// A classic CAN frame (CiA 301 runs on CAN 2.0: at most 8 data bytes) and the predefined connection
// set's identifiers (CiA 301 §7.3.5: function code in bits 7..10, node-ID in bits 0..6).
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>

#include "cia402/data_type.hpp"

namespace cia402::canopen {

struct frame {
  std::uint32_t id = 0;  ///< 11-bit identifier, or 29-bit with `extended`
  std::uint8_t len = 0;  ///< data length code 0..8
  bool extended = false;
  bool rtr = false;      ///< remote transmission request: no data, `len` is the requested length
  std::array<std::uint8_t, 8> data{};

  bool operator==(const frame&) const = default;
};

/// Largest 11-bit and 29-bit identifiers.
inline constexpr std::uint32_t max_base_id = 0x7FF;
inline constexpr std::uint32_t max_extended_id = 0x1FFFFFFF;

/// Node-IDs 1..127 (CiA 301 §7.3.2.1).
inline constexpr std::uint8_t max_node_id = 127;
constexpr bool valid_node_id(unsigned id) noexcept { return id >= 1 && id <= max_node_id; }

/// COB-IDs of the predefined connection set.
namespace cob {
inline constexpr std::uint32_t nmt = 0x000;
inline constexpr std::uint32_t sync = 0x080;
inline constexpr std::uint32_t emcy = 0x080;        ///< + node-ID
inline constexpr std::uint32_t tpdo1 = 0x180;       ///< + node-ID; TPDO n: 0x180 + 0x100 (n-1)
inline constexpr std::uint32_t rpdo1 = 0x200;       ///< + node-ID; RPDO n: 0x200 + 0x100 (n-1)
inline constexpr std::uint32_t sdo_tx = 0x580;      ///< server -> client, + node-ID
inline constexpr std::uint32_t sdo_rx = 0x600;      ///< client -> server, + node-ID
inline constexpr std::uint32_t heartbeat = 0x700;   ///< + node-ID (also boot-up)
}  // namespace cob

/// A frame with `len` bytes taken from `bytes`.
inline frame make_frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) noexcept {
  frame f;
  f.id = id;
  for (std::uint8_t b : bytes) {
    if (f.len == 8) break;
    f.data[f.len++] = b;
  }
  return f;
}

}  // namespace cia402::canopen
