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

#include "cia402/data_type.hpp"
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
  /// The entry a mapping object's sub-index holding `w` names.
  static constexpr pdo_mapping_entry of_word(std::uint32_t w) noexcept {
    return {static_cast<std::uint16_t>(w >> 16), static_cast<std::uint8_t>(w >> 8), static_cast<std::uint8_t>(w)};
  }
};

/// Padding: mapping entries that name no object and carry no value. A dummy entry (CiA 301
/// §7.4.8.2), index 0x0001..0x0007, one of the static data types BOOLEAN..UNSIGNED32, is padding on
/// either bus; a gap (ETG.1000.6 §5.6.7.4, the ETG's convention that KickCAT and SOES follow), index
/// 0, on EtherCAT only. A received PDO skips their bits, a transmitted one sends them as zeros; they
/// count in the PDO's length as any entry does. Both buses' mapping rules and packing take them from
/// here.
enum class pdo_padding : std::uint8_t {
  dummies,           ///< CANopen: dummy entries
  dummies_and_gaps,  ///< EtherCAT: dummy entries and index-0 gaps
};

/// Whether an entry of this index is padding (then it names no object, whatever its sub-index and
/// length say): 0x0001..0x0007, and 0 under dummies_and_gaps.
constexpr bool is_pdo_padding(std::uint16_t index, pdo_padding p) noexcept {
  return (index >= 0x0001 && index <= 0x0007) || (index == 0 && p == pdo_padding::dummies_and_gaps);
}

/// The bits a sound padding entry takes: a dummy with sub-index 0 and its type's length (1 bit for
/// BOOLEAN, else the type's size in bits); a gap with sub-index 0 and 1..64 bits. 0 for any other
/// entry: not padding, or padding with another sub-index or length, which a mapping refuses
/// (0x06040041).
constexpr unsigned pdo_padding_bits(pdo_mapping_entry e, pdo_padding p) noexcept {
  if (!is_pdo_padding(e.index, p) || e.sub != 0) return 0;
  if (e.index == 0) return e.bits >= 1 && e.bits <= 64 ? e.bits : 0;
  const auto type = static_cast<data_type>(e.index);
  const unsigned want = type == data_type::boolean ? 1 : type_size(type) * 8;
  return e.bits == want ? want : 0;
}

/// A mapped entry's value, `bits` (1..64) long from `bit_offset` of a little-endian PDO of `size`
/// bytes (CANopen's and EtherCAT's byte order), zero-extended; bits beyond `size` read as 0. At most
/// nine steps: a byte, or the part of one, each.
constexpr std::uint64_t pdo_get_bits(const std::uint8_t* data, std::size_t size, unsigned bit_offset,
                                     unsigned bits) noexcept {
  std::uint64_t v = 0;
  // Whole bytes, the rule of every object entry: a byte each, without the masks. The bit-wise way
  // made the 64-drive RPDO-to-TPDO cycle about 6 % slower.
  if (bit_offset % 8 == 0 && bits % 8 == 0) {
    for (unsigned i = 0; i < bits / 8 && i < 8 && bit_offset / 8 + i < size; ++i) {
      v |= std::uint64_t{data[bit_offset / 8 + i]} << (8 * i);
    }
    return v;
  }
  for (unsigned done = 0; done < bits && done < 64;) {
    const unsigned at = bit_offset + done;
    if (at / 8 >= size) break;
    const unsigned shift = at % 8;
    const unsigned take = (8 - shift) < (bits - done) ? 8 - shift : bits - done;
    v |= static_cast<std::uint64_t>((data[at / 8] >> shift) & ((1u << take) - 1u)) << done;
    done += take;
  }
  return v;
}

/// Puts the low `bits` (1..64) of `v` at `bit_offset` of a little-endian PDO of `size` bytes, the
/// bits around them kept; bits beyond `size` are dropped.
constexpr void pdo_put_bits(std::uint8_t* data, std::size_t size, unsigned bit_offset, unsigned bits,
                            std::uint64_t v) noexcept {
  if (bit_offset % 8 == 0 && bits % 8 == 0) {  // whole bytes, as pdo_get_bits
    for (unsigned i = 0; i < bits / 8 && i < 8 && bit_offset / 8 + i < size; ++i) {
      data[bit_offset / 8 + i] = static_cast<std::uint8_t>(v >> (8 * i));
    }
    return;
  }
  for (unsigned done = 0; done < bits && done < 64;) {
    const unsigned at = bit_offset + done;
    if (at / 8 >= size) break;
    const unsigned shift = at % 8;
    const unsigned take = (8 - shift) < (bits - done) ? 8 - shift : bits - done;
    const auto mask = static_cast<std::uint8_t>(((1u << take) - 1u) << shift);
    const auto part = static_cast<std::uint8_t>(static_cast<unsigned>(v >> done) << shift);
    data[at / 8] = static_cast<std::uint8_t>((data[at / 8] & ~mask) | (part & mask));
    done += take;
  }
}

/// A signed entry's value from its `bits` (1..64) as pdo_get_bits read them: sign-extended.
constexpr std::int64_t pdo_sign_extended(std::uint64_t raw, unsigned bits) noexcept {
  if (bits == 0 || bits >= 64) return static_cast<std::int64_t>(raw);
  const std::uint64_t sign = std::uint64_t{1} << (bits - 1);
  return static_cast<std::int64_t>((raw ^ sign) - sign);
}

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

/// Whether a map keeps the object table's rules (objects.hpp): every entry padding of sound form
/// (pdo_padding_bits, under `padding`) or an object of the table, PDO-mappable, writable when
/// `receive` (the PDO writes it) or readable otherwise, and mapped with its type's full length.
/// sdo_abort::none, or the code a dictionary gives for such an entry (object_does_not_exist,
/// sub_index_does_not_exist, cannot_map_to_pdo).
sdo_abort check_pdo_map(const pdo_map& m, bool receive, pdo_padding padding = pdo_padding::dummies) noexcept;

}  // namespace cia402
