// The CiA 402 objects of a drive, one table: index, sub-index, data type, access, PDO mapping,
// limits, default and name. Every layer reads it: the simulator's object access, the CANopen
// object dictionary and its EDS, the instrument page; the next fieldbus (EtherCAT CoE) takes it as
// it is. No heap, constexpr data in flash.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cia402/sdo_abort.hpp"

namespace cia402 {

/// CiA 301 data types, by their codes (they are the EDS's DataType values).
enum class object_type : std::uint8_t {
  integer8 = 0x02,
  integer16 = 0x03,
  integer32 = 0x04,
  unsigned8 = 0x05,
  unsigned16 = 0x06,
  unsigned32 = 0x07,
};

enum class object_access : std::uint8_t { read_only, write_only, read_write };

/// One object (sub-index 0: the drive profile's objects are all simple variables today).
struct object_description {
  std::uint16_t index;
  std::uint8_t sub;
  object_type type;
  object_access access;
  bool pdo_mappable;
  std::int64_t low;            ///< the lowest value a write may give (within the type)
  std::int64_t high;           ///< the highest
  std::int64_t default_value;
  const char* name;            ///< CiA 402's name, e.g. "Profile acceleration"
  const char* unit;            ///< "rpm", "rpm/s", or "" for none
};

/// The lowest and highest value of a data type.
constexpr std::int64_t type_low(object_type t) noexcept {
  switch (t) {
    case object_type::integer8: return -128;
    case object_type::integer16: return -32768;
    case object_type::integer32: return -2147483647LL - 1;
    default: return 0;
  }
}
constexpr std::int64_t type_high(object_type t) noexcept {
  switch (t) {
    case object_type::integer8: return 127;
    case object_type::integer16: return 32767;
    case object_type::integer32: return 2147483647LL;
    case object_type::unsigned8: return 255;
    case object_type::unsigned16: return 65535;
    case object_type::unsigned32: return 4294967295LL;
  }
  return 0;
}
/// Bytes of a data type on the bus.
constexpr std::size_t type_size(object_type t) noexcept {
  switch (t) {
    case object_type::integer8:
    case object_type::unsigned8: return 1;
    case object_type::integer16:
    case object_type::unsigned16: return 2;
    default: return 4;
  }
}
constexpr bool type_signed(object_type t) noexcept {
  return t == object_type::integer8 || t == object_type::integer16 || t == object_type::integer32;
}

/// The drive profile's objects, in index order.
std::size_t drive_object_count() noexcept;
const object_description& drive_object(std::size_t i) noexcept;
/// The object at index/sub, or nullptr.
const object_description* find_drive_object(std::uint16_t index, std::uint8_t sub = 0) noexcept;

/// Whether a write of `value` is allowed: read_only_object, value_too_low / value_too_high (outside
/// the type or the object's limits), or none. Whether the profile supports the value (an option
/// code, a mode) is for the owner of the object to say.
constexpr sdo_abort check_write(const object_description& o, std::int64_t value) noexcept {
  if (o.access == object_access::read_only) return sdo_abort::read_only_object;
  if (value < o.low) return sdo_abort::value_too_low;
  if (value > o.high) return sdo_abort::value_too_high;
  return sdo_abort::none;
}

/// Indices of the objects a drive-side machine owns beside its option codes (option_index()).
namespace object_index {
inline constexpr std::uint16_t error_code = 0x603F;
inline constexpr std::uint16_t control_word = 0x6040;
inline constexpr std::uint16_t status_word = 0x6041;
inline constexpr std::uint16_t modes_of_operation = 0x6060;
inline constexpr std::uint16_t modes_of_operation_display = 0x6061;
inline constexpr std::uint16_t velocity_actual_value = 0x606C;
inline constexpr std::uint16_t profile_acceleration = 0x6083;
inline constexpr std::uint16_t profile_deceleration = 0x6084;
inline constexpr std::uint16_t quick_stop_deceleration = 0x6085;
inline constexpr std::uint16_t target_velocity = 0x60FF;
inline constexpr std::uint16_t supported_drive_modes = 0x6502;
}  // namespace object_index

}  // namespace cia402
