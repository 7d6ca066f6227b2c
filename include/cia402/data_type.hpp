// The static data types of CiA 301 §7.1.6, one enum for every layer: the core's object table
// (objects.hpp), the CANopen object dictionary and its EDS (CiA 306 DataType), EtherCAT's CoE object
// descriptions (ETG.1000.6 uses CiA 301's data type indices). Constexpr, no heap: part of the core.
#pragma once

#include <cstdint>
#include <limits>

namespace cia402 {

/// CiA 301 §7.1.6 data types, valued as their data type indices (0x0001..), which are also the
/// EDS's DataType values and CoE's.
enum class data_type : std::uint16_t {
  boolean = 0x0001,
  integer8 = 0x0002,
  integer16 = 0x0003,
  integer32 = 0x0004,
  unsigned8 = 0x0005,
  unsigned16 = 0x0006,
  unsigned32 = 0x0007,
  visible_string = 0x0009,
  integer64 = 0x0015,
  unsigned64 = 0x001B,
};

/// Bytes a value of the type takes on the bus; 0 for VISIBLE_STRING (its length varies).
constexpr unsigned type_size(data_type t) noexcept {
  switch (t) {
    case data_type::boolean:
    case data_type::integer8:
    case data_type::unsigned8: return 1;
    case data_type::integer16:
    case data_type::unsigned16: return 2;
    case data_type::integer32:
    case data_type::unsigned32: return 4;
    case data_type::integer64:
    case data_type::unsigned64: return 8;
    case data_type::visible_string: return 0;
  }
  return 0;
}

constexpr bool type_is_signed(data_type t) noexcept {
  return t == data_type::integer8 || t == data_type::integer16 || t == data_type::integer32 ||
         t == data_type::integer64;
}

/// The smallest value of a numeric type (0 for the unsigned ones and VISIBLE_STRING).
constexpr std::int64_t type_min(data_type t) noexcept {
  switch (t) {
    case data_type::integer8: return std::numeric_limits<std::int8_t>::min();
    case data_type::integer16: return std::numeric_limits<std::int16_t>::min();
    case data_type::integer32: return std::numeric_limits<std::int32_t>::min();
    case data_type::integer64: return std::numeric_limits<std::int64_t>::min();
    default: return 0;
  }
}

/// The largest value of a numeric type (0 for VISIBLE_STRING).
constexpr std::int64_t type_max(data_type t) noexcept {
  switch (t) {
    case data_type::boolean: return 1;
    case data_type::integer8: return std::numeric_limits<std::int8_t>::max();
    case data_type::unsigned8: return std::numeric_limits<std::uint8_t>::max();
    case data_type::integer16: return std::numeric_limits<std::int16_t>::max();
    case data_type::unsigned16: return std::numeric_limits<std::uint16_t>::max();
    case data_type::integer32: return std::numeric_limits<std::int32_t>::max();
    case data_type::unsigned32: return std::numeric_limits<std::uint32_t>::max();
    // UNSIGNED64 above 2^63-1 does not fit the int64 every value travels in; no object uses it.
    case data_type::integer64:
    case data_type::unsigned64: return std::numeric_limits<std::int64_t>::max();
    case data_type::visible_string: return 0;
  }
  return 0;
}

/// CiA 301's name of the type: "INTEGER16", "VISIBLE_STRING". Never null.
constexpr const char* type_name(data_type t) noexcept {
  switch (t) {
    case data_type::boolean: return "BOOLEAN";
    case data_type::integer8: return "INTEGER8";
    case data_type::integer16: return "INTEGER16";
    case data_type::integer32: return "INTEGER32";
    case data_type::unsigned8: return "UNSIGNED8";
    case data_type::unsigned16: return "UNSIGNED16";
    case data_type::unsigned32: return "UNSIGNED32";
    case data_type::visible_string: return "VISIBLE_STRING";
    case data_type::integer64: return "INTEGER64";
    case data_type::unsigned64: return "UNSIGNED64";
  }
  return "?";
}

/// Little-endian helpers: CiA 301 puts every multi-byte value least significant byte first, on
/// CAN and in CoE alike.
inline void put_le(std::uint8_t* p, std::uint64_t v, unsigned bytes) noexcept {
  for (unsigned i = 0; i < bytes; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline std::uint64_t get_le(const std::uint8_t* p, unsigned bytes) noexcept {
  std::uint64_t v = 0;
  for (unsigned i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}

}  // namespace cia402
