// The default process data of a CiA 402 drive, one table for every fieldbus:
// - CANopen: CiA 402's predefined connection set, RPDO1..4 and TPDO1..4 (CiA 402-3, as drive manuals
//   restate it, e.g. Kollmorgen S300 CANopen manual §5.3.1.3), with their transmission types (0x1400 /
//   0x1800 sub 2), inhibit times (0x1800 sub 3) and event timers (0x1800 sub 5);
// - EtherCAT (CoE): the default RxPDO 0x1600 and TxPDO 0x1A00 (ETG.6010's CiA 402 drive profile
//   over EtherCAT), enough for a cyclic synchronous position master and every other mode.
// The virtual drive's dictionaries take their defaults from here, the CANopen drive master sets a
// drive's predefined PDOs from here, and the EtherCAT slave's SII and ESI describe them from here.
// Constexpr data, no heap; `check_pdo_map` holds each map to the one object table (objects.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>

#include "cia402/sdo_abort.hpp"

namespace cia402 {

/// One entry of a PDO mapping (CiA 301 §7.4.8.2, ETG.1000.6 §5.6.7.4): an object's index and
/// sub-index and its length in bits.
struct pdo_mapping_entry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;
  /// The entry as a mapping object's sub-index holds it: index << 16 | sub << 8 | bits.
  constexpr std::uint32_t word() const noexcept {
    return (static_cast<std::uint32_t>(index) << 16) | (static_cast<std::uint32_t>(sub) << 8) | bits;
  }
};

/// Entries a default map holds at most (CANopen's 8 bytes of a frame take 8 entries at most).
inline constexpr std::size_t max_default_pdo_entries = 8;

/// A PDO's default mapping and, on CANopen, its communication parameters (unused on EtherCAT).
struct pdo_map {
  std::uint8_t count = 0;  ///< entries in use; 0: the PDO is not used (its COB-ID starts invalid)
  /// CANopen: the COB-ID starts valid (bit 31 clear, CiA 301 §7.5.2.35); false keeps the mapping for a
  /// master that enables the PDO, but the node neither sends nor takes it until one does.
  bool valid = true;
  std::array<pdo_mapping_entry, max_default_pdo_entries> entries{};
  std::uint8_t transmission_type = 255;  ///< 0x1400 / 0x1800 sub 2: 1 every SYNC, 255 on change
  std::uint16_t inhibit_100us = 0;       ///< 0x1800 sub 3 (TPDO)
  std::uint16_t event_timer_ms = 0;      ///< 0x1800 sub 5 (TPDO)

  constexpr unsigned bits() const noexcept {
    unsigned total = 0;
    for (std::size_t i = 0; i < count; ++i) total += entries[i].bits;
    return total;
  }
};

namespace detail {
constexpr pdo_map make_pdo_map(std::initializer_list<pdo_mapping_entry> entries, std::uint8_t type,
                               std::uint16_t inhibit_100us = 0, std::uint16_t event_timer_ms = 0) noexcept {
  pdo_map m{};
  for (const pdo_mapping_entry& e : entries) m.entries[m.count++] = e;
  m.transmission_type = type;
  m.inhibit_100us = inhibit_100us;
  m.event_timer_ms = event_timer_ms;
  return m;
}
constexpr pdo_map not_valid(pdo_map m) noexcept {
  m.valid = false;
  return m;
}
}  // namespace detail

namespace pdo_maps {

/// Transmission types (CiA 301 §7.5.2.35): on change (device profile event) and every SYNC.
inline constexpr std::uint8_t on_change = 255;
inline constexpr std::uint8_t every_sync = 1;
/// A master can rely on hearing each TPDO at least every second.
inline constexpr std::uint16_t tpdo_event_timer_ms = 1000;
/// The status word's TPDOs (TPDO1, and TPDO2 with 0x6061) repeat every 100 ms while nothing
/// changes: a master that waits for the next one (python-canopen's BaseNode402 waits 0.2 s once it
/// has seen two) hears one in time without SYNC (docs/canopen.md, "Default PDOs").
inline constexpr std::uint16_t status_event_timer_ms = 100;

/// RPDO1..4: 0x6040; 0x6040 + 0x6060; 0x6040 + 0x607A; 0x6040 + 0x60FF. RPDO3 carries a cyclic
/// synchronous position master's set-point and acts at the next SYNC; the others act on receipt.
/// RPDO2 keeps CiA 402's mapping but starts not valid: a master that writes 0x6060 through it hands
/// the drive a second control word it may not keep up to date (python-canopen's BaseNode402 sends
/// its own stale copy, 0 = Disable voltage); one that wants it sets its COB-ID valid.
inline constexpr std::array<pdo_map, 4> can_rpdo = {
    detail::make_pdo_map({{0x6040, 0, 16}}, on_change),
    detail::not_valid(detail::make_pdo_map({{0x6040, 0, 16}, {0x6060, 0, 8}}, on_change)),
    detail::make_pdo_map({{0x6040, 0, 16}, {0x607A, 0, 32}}, every_sync),
    detail::make_pdo_map({{0x6040, 0, 16}, {0x60FF, 0, 32}}, on_change)};

/// TPDO1..4: 0x6041; 0x6041 + 0x6061; 0x6041 + 0x6064; 0x6041 + 0x606C. TPDO3 goes out on every
/// SYNC; the others on change and at least every event timer (TPDO1, TPDO2: 100 ms; TPDO4: 1 s).
/// TPDO4, which carries the velocity, has an inhibit time of 10 ms, so a ramping drive sends it at
/// most 100 times a second (it sent about 850); TPDO1 has none, so every state change arrives.
inline constexpr std::array<pdo_map, 4> can_tpdo = {
    detail::make_pdo_map({{0x6041, 0, 16}}, on_change, 0, status_event_timer_ms),
    detail::make_pdo_map({{0x6041, 0, 16}, {0x6061, 0, 8}}, on_change, 0, status_event_timer_ms),
    detail::make_pdo_map({{0x6041, 0, 16}, {0x6064, 0, 32}}, every_sync, 0, tpdo_event_timer_ms),
    detail::make_pdo_map({{0x6041, 0, 16}, {0x606C, 0, 32}}, on_change, 100, tpdo_event_timer_ms)};

/// RxPDO 0x1600 (outputs, 13 bytes): control word, target position, target velocity, target torque,
/// modes of operation.
inline constexpr pdo_map ecat_rxpdo = detail::make_pdo_map(
    {{0x6040, 0, 16}, {0x607A, 0, 32}, {0x60FF, 0, 32}, {0x6071, 0, 16}, {0x6060, 0, 8}}, on_change);

/// TxPDO 0x1A00 (inputs, 19 bytes): status word, position, velocity and torque actual values, modes
/// of operation display, error code, following error actual value (a master sees a following error
/// growing).
inline constexpr pdo_map ecat_txpdo = detail::make_pdo_map({{0x6041, 0, 16},
                                                            {0x6064, 0, 32},
                                                            {0x606C, 0, 32},
                                                            {0x6077, 0, 16},
                                                            {0x6061, 0, 8},
                                                            {0x603F, 0, 16},
                                                            {0x60F4, 0, 32}},
                                                           on_change);

}  // namespace pdo_maps

/// Whether a map keeps the object table's rules (objects.hpp): every entry an object of the table,
/// PDO-mappable, writable when `receive` (the PDO writes it) or readable otherwise, and mapped with
/// its type's full length. sdo_abort::none, or the code a dictionary gives for such an entry
/// (object_does_not_exist, sub_index_does_not_exist, cannot_map_to_pdo).
sdo_abort check_pdo_map(const pdo_map& m, bool receive) noexcept;

}  // namespace cia402
