// The CiA 402 objects of a drive, one table: index, sub-index, data type, access, PDO mapping,
// limits, default and name. Every layer reads it: the simulator's object access, the CANopen
// object dictionary and its EDS, the instrument page; the next fieldbus (EtherCAT CoE) takes it as
// it is. No heap, constexpr data in flash.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "cia402/data_type.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402 {

enum class object_access : std::uint8_t { read_only, write_only, read_write };

/// One entry of the table: a simple variable (sub-index 0), or one entry of an array or record, whose
/// sub-index 0 (read-only UNSIGNED8) holds the highest sub-index that follows (0x607D, 0x608F, ...).
struct object_description {
  std::uint16_t index;
  std::uint8_t sub;
  data_type type;
  object_access access;
  bool pdo_mappable;
  std::int64_t low;            ///< the lowest value a write may give (within the type)
  std::int64_t high;           ///< the highest
  std::int64_t default_value;
  const char* name;            ///< CiA 402's name, e.g. "Profile acceleration"
  const char* unit;            ///< "rpm", "rpm/s", or "" for none
};

/// The drive profile's objects, in index order.
std::size_t drive_object_count() noexcept;
const object_description& drive_object(std::size_t i) noexcept;
namespace detail {
/// The one object table (src/core/objects.cpp), and where each 0x60xx object's first entry sits in
/// it (0xFF: no such object), for the inline lookup below.
extern const object_description drive_object_table[];
extern const std::array<std::uint8_t, 256> drive_object_60xx;
const object_description* find_drive_object_by_search(std::uint16_t index, std::uint8_t sub) noexcept;
}  // namespace detail

/// The entry at index/sub, or nullptr. Inline for 0x60xx, where every cyclic set-point lives: one
/// table load and a short scan of the object's sub-indices (the table's last entry is not a 0x60xx
/// object, so the scan ends inside it).
inline const object_description* find_drive_object(std::uint16_t index, std::uint8_t sub = 0) noexcept {
  if ((index >> 8) == 0x60) {
    const std::uint8_t first = detail::drive_object_60xx[index & 0xFFu];
    if (first == 0xFF) return nullptr;
    for (const object_description* o = detail::drive_object_table + first; o->index == index; ++o) {
      if (o->sub == sub) return o;
    }
    return nullptr;
  }
  return detail::find_drive_object_by_search(index, sub);
}

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
inline constexpr std::uint16_t velocity_window = 0x606D;
inline constexpr std::uint16_t velocity_window_time = 0x606E;
inline constexpr std::uint16_t velocity_threshold = 0x606F;
inline constexpr std::uint16_t velocity_threshold_time = 0x6070;
inline constexpr std::uint16_t max_torque = 0x6072;
inline constexpr std::uint16_t max_profile_velocity = 0x607F;
inline constexpr std::uint16_t max_motor_speed = 0x6080;
inline constexpr std::uint16_t supported_homing_methods = 0x60E3;  ///< sub 0 count, 1.. one method each
inline constexpr std::uint16_t digital_inputs = 0x60FD;
inline constexpr std::uint16_t profile_acceleration = 0x6083;
inline constexpr std::uint16_t profile_deceleration = 0x6084;
inline constexpr std::uint16_t quick_stop_deceleration = 0x6085;
inline constexpr std::uint16_t target_velocity = 0x60FF;
inline constexpr std::uint16_t position_demand_value = 0x6062;
inline constexpr std::uint16_t position_actual_value = 0x6064;
inline constexpr std::uint16_t following_error_window = 0x6065;
inline constexpr std::uint16_t following_error_time_out = 0x6066;
inline constexpr std::uint16_t position_window = 0x6067;
inline constexpr std::uint16_t position_window_time = 0x6068;
inline constexpr std::uint16_t target_torque = 0x6071;
inline constexpr std::uint16_t torque_actual_value = 0x6077;
inline constexpr std::uint16_t target_position = 0x607A;
inline constexpr std::uint16_t home_offset = 0x607C;
inline constexpr std::uint16_t software_position_limit = 0x607D;  ///< sub 1 min, sub 2 max
inline constexpr std::uint16_t profile_velocity = 0x6081;
inline constexpr std::uint16_t end_velocity = 0x6082;
inline constexpr std::uint16_t torque_slope = 0x6087;
inline constexpr std::uint16_t position_encoder_resolution = 0x608F;  ///< sub 1 increments, 2 revolutions
inline constexpr std::uint16_t homing_method = 0x6098;
inline constexpr std::uint16_t homing_speeds = 0x6099;  ///< sub 1 switch search, 2 zero search
inline constexpr std::uint16_t homing_acceleration = 0x609A;
inline constexpr std::uint16_t position_offset = 0x60B0;
inline constexpr std::uint16_t velocity_offset = 0x60B1;
inline constexpr std::uint16_t torque_offset = 0x60B2;
inline constexpr std::uint16_t interpolation_time_period = 0x60C2;  ///< sub 1 value, 2 index
inline constexpr std::uint16_t following_error_actual_value = 0x60F4;
inline constexpr std::uint16_t supported_drive_modes = 0x6502;
}  // namespace object_index

/// Bits of 0x60FD digital inputs (CiA 402-2); 16..31 are the manufacturer's.
namespace digital_input {
inline constexpr std::uint32_t negative_limit_switch = 1u << 0;
inline constexpr std::uint32_t positive_limit_switch = 1u << 1;
inline constexpr std::uint32_t home_switch = 1u << 2;
}  // namespace digital_input

/// Modes of operation (0x6060 / 0x6061) and their bits in 0x6502 (CiA 402-2).
namespace mode {
inline constexpr std::int8_t profile_position = 1;
inline constexpr std::int8_t profile_velocity = 3;
inline constexpr std::int8_t profile_torque = 4;
inline constexpr std::int8_t homing = 6;
inline constexpr std::int8_t cyclic_synchronous_position = 8;
inline constexpr std::int8_t cyclic_synchronous_velocity = 9;
inline constexpr std::int8_t cyclic_synchronous_torque = 10;
/// The bit of 0x6502 that announces mode m (1..10), 0 for any other value.
constexpr std::uint32_t supported_bit(std::int64_t m) noexcept {
  return m >= 1 && m <= 10 ? std::uint32_t{1} << (m - 1) : 0u;
}
/// "pp", "pv", "tq", "hm", "csp", "csv", "cst", or "" for a mode without a short name.
const char* short_name(std::int64_t m) noexcept;
/// Accepts the short names above and the numbers; false for anything else.
bool parse(std::string_view text, std::int8_t& out) noexcept;
}  // namespace mode

}  // namespace cia402
