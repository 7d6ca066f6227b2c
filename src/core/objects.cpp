#include "cia402/objects.hpp"

namespace cia402 {
namespace {

using T = object_type;
using A = object_access;

constexpr object_description var(std::uint16_t index, T type, A access, bool mappable,
                                 const char* name, const char* unit = "",
                                 std::int64_t default_value = 0) noexcept {
  return {index, 0, type, access, mappable, type_low(type), type_high(type), default_value, name, unit};
}

// A ramp of 0 rpm/s would never end: 1 is the lowest value.
constexpr object_description ramp(std::uint16_t index, const char* name,
                                  std::int64_t default_value) noexcept {
  object_description o = var(index, T::unsigned32, A::read_write, true, name, "rpm/s", default_value);
  o.low = 1;
  return o;
}

// The option codes are INTEGER16 on the bus; which values a drive takes is its profile's (S5..S10).
constexpr object_description option_code(std::uint16_t index, const char* name) noexcept {
  return var(index, T::integer16, A::read_write, false, name);
}

// In index order. Profile velocity (mode 3) is the one mode today; 0x6502 bit 2 says so.
constexpr object_description objects[] = {
    option_code(0x6007, "Abort connection option code"),
    var(0x603F, T::unsigned16, A::read_only, true, "Error code"),
    var(0x6040, T::unsigned16, A::read_write, true, "Controlword"),
    var(0x6041, T::unsigned16, A::read_only, true, "Statusword"),
    option_code(0x605A, "Quick stop option code"),
    option_code(0x605B, "Shutdown option code"),
    option_code(0x605C, "Disable operation option code"),
    option_code(0x605D, "Halt option code"),
    option_code(0x605E, "Fault reaction option code"),
    var(0x6060, T::integer8, A::read_write, true, "Modes of operation", "", 3),
    var(0x6061, T::integer8, A::read_only, true, "Modes of operation display", "", 3),
    var(0x606C, T::integer32, A::read_only, true, "Velocity actual value", "rpm"),
    ramp(0x6083, "Profile acceleration", 1000),
    ramp(0x6084, "Profile deceleration", 1000),
    ramp(0x6085, "Quick stop deceleration", 10000),
    var(0x60FF, T::integer32, A::read_write, true, "Target velocity", "rpm"),
    var(0x6502, T::unsigned32, A::read_only, false, "Supported drive modes", "", 1 << 2),
};
constexpr std::size_t count = sizeof(objects) / sizeof(objects[0]);

constexpr bool in_index_order() noexcept {
  for (std::size_t i = 1; i < count; ++i) {
    if (objects[i - 1].index >= objects[i].index) return false;
  }
  return true;
}
static_assert(in_index_order(), "the object table is kept in index order");

}  // namespace

std::size_t drive_object_count() noexcept { return count; }

const object_description& drive_object(std::size_t i) noexcept { return objects[i < count ? i : 0]; }

const object_description* find_drive_object(std::uint16_t index, std::uint8_t sub) noexcept {
  for (const object_description& o : objects) {
    if (o.index == index && o.sub == sub) return &o;
  }
  return nullptr;
}

}  // namespace cia402
