// Process data objects (CiA 301 §7.2.2): the communication and mapping parameters of one PDO as the
// slave uses them, and the transmission types.
#pragma once

#include <array>
#include <cstdint>

#include "cia402/dictionary/object_dictionary.hpp"

namespace cia402::canopen {

/// Transmission types (0x1400/0x1800 sub-index 2): 0 synchronous acyclic, 1..240 every n-th SYNC,
/// 252/253 RTR-only (not offered here), 254 manufacturer event, 255 device-profile event.
constexpr bool synchronous_type(unsigned t) noexcept { return t <= 240; }
constexpr bool event_type(unsigned t) noexcept { return t == 254 || t == 255; }

/// Bit 31 of a PDO COB-ID: the PDO does not exist (is not valid).
inline constexpr std::uint32_t pdo_cob_invalid = 0x80000000u;

/// CAN-IDs a PDO may not use (CiA 301 §7.3.5, as CANopenNode checks them): NMT, SYNC/EMCY range,
/// TIME, SDO, heartbeat and LSS identifiers.
constexpr bool restricted_can_id(std::uint32_t id) noexcept {
  return id <= 0x7F || (id >= 0x101 && id <= 0x180) || (id >= 0x581 && id <= 0x5FF) ||
         (id >= 0x601 && id <= 0x67F) || (id >= 0x6E0 && id <= 0x6FF) || id >= 0x701;
}

/// One mapped object, resolved when the mapping is configured (the node starts, or a PDO parameter
/// is written) and bound to its dictionary slot, as CANopenNode binds an OD_IO_t per mapped entry: a
/// PDO then reads and writes the slot with the dictionary's rules and looks nothing up. A dummy
/// entry (pdo_maps.hpp, pdo_padding) has no slot: a received PDO skips its bits, a transmitted one
/// sends them as zeros.
struct mapped_object {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  data_type type = data_type::unsigned8;
  std::uint8_t bits = 0;
  dictionary::object_dictionary::slot* slot = nullptr;  ///< nullptr: a dummy entry
};

/// One PDO as configured by its two parameter objects.
struct pdo_config {
  bool valid = false;
  std::uint32_t can_id = 0;
  std::uint8_t transmission_type = 255;
  std::uint16_t inhibit_100us = 0;  ///< TPDO only
  std::uint16_t event_timer_ms = 0; ///< TPDO only
  std::uint8_t count = 0;
  std::uint8_t length = 0;          ///< bytes (the mapped bits rounded up)
  std::array<mapped_object, 8> map{};
};

/// A mapping entry (index << 16 | sub << 8 | bits).
constexpr std::uint16_t map_index(std::uint32_t m) noexcept { return static_cast<std::uint16_t>(m >> 16); }
constexpr std::uint8_t map_sub(std::uint32_t m) noexcept { return static_cast<std::uint8_t>(m >> 8); }
constexpr std::uint8_t map_bits(std::uint32_t m) noexcept { return static_cast<std::uint8_t>(m); }

}  // namespace cia402::canopen
