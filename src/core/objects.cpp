#include "cia402/objects.hpp"

#include <array>

namespace cia402 {
namespace {

using T = data_type;
using A = object_access;

constexpr object_description var(std::uint16_t index, T type, A access, bool mappable,
                                 const char* name, const char* unit = "",
                                 std::int64_t default_value = 0) noexcept {
  return {index, 0, type, access, mappable, type_min(type), type_max(type), default_value, name, unit};
}

// A ramp of 0 rpm/s would never end: 1 is the lowest value.
constexpr object_description ramp(std::uint16_t index, const char* name,
                                  std::int64_t default_value) noexcept {
  object_description o = var(index, T::unsigned32, A::read_write, true, name, "rpm/s", default_value);
  o.low = 1;
  return o;
}

constexpr const char* permille = "permille";

constexpr object_description at_least_1(object_description o) noexcept {
  o.low = 1;
  return o;
}

constexpr object_description limited(object_description o, std::int64_t low, std::int64_t high) noexcept {
  o.low = low;
  o.high = high;
  return o;
}

constexpr object_description read_only(object_description o) noexcept {
  o.access = A::read_only;
  return o;
}

// Sub-index 0 of an array or record: how many entries follow.
constexpr object_description highest_sub(std::uint16_t index, std::uint8_t count, const char* name) noexcept {
  return {index, 0, T::unsigned8, A::read_only, false, count, count, count, name, ""};
}

constexpr object_description sub(std::uint16_t index, std::uint8_t sub_index, T type, const char* name,
                                 const char* unit, std::int64_t default_value) noexcept {
  return {index, sub_index, type, A::read_write, false, type_min(type), type_max(type), default_value,
          name, unit};
}

// The option codes are INTEGER16 on the bus; which values a drive takes is its profile's (S5..S10).
constexpr object_description option_code(std::uint16_t index, const char* name) noexcept {
  return var(index, T::integer16, A::read_write, false, name);
}

}  // namespace

namespace detail {
// In index order, sub-indices ascending within an index.
constexpr object_description drive_object_table[] = {
    option_code(0x6007, "Abort connection option code"),
    var(0x603F, T::unsigned16, A::read_only, true, "Error code"),
    var(0x6040, T::unsigned16, A::read_write, true, "Controlword"),
    var(0x6041, T::unsigned16, A::read_only, true, "Statusword"),
    option_code(0x605A, "Quick stop option code"),
    option_code(0x605B, "Shutdown option code"),
    option_code(0x605C, "Disable operation option code"),
    option_code(0x605D, "Halt option code"),
    option_code(0x605E, "Fault reaction option code"),
    // Which modes a drive runs is its own (0x6502); profile velocity is the power-on mode.
    var(0x6060, T::integer8, A::read_write, true, "Modes of operation", "", 3),
    var(0x6061, T::integer8, A::read_only, true, "Modes of operation display", "", 3),
    var(0x6062, T::integer32, A::read_only, true, "Position demand value", "inc"),
    var(0x6064, T::integer32, A::read_only, true, "Position actual value", "inc"),
    // 0xFFFFFFFF switches the following-error check off (CiA 402-2).
    var(0x6065, T::unsigned32, A::read_write, true, "Following error window", "inc", 10000),
    var(0x6066, T::unsigned16, A::read_write, true, "Following error time out", "ms", 10),
    var(0x6067, T::unsigned32, A::read_write, true, "Position window", "inc", 10),
    var(0x6068, T::unsigned16, A::read_write, true, "Position window time", "ms", 0),
    var(0x606C, T::integer32, A::read_only, true, "Velocity actual value", "rpm"),
    // Profile velocity's status bits: 10 when |velocity - set-point| <= 0x606D for longer than
    // 0x606E; 12 ("speed") cleared once |velocity| > 0x606F for longer than 0x6070 (CiA 402-2).
    // The plant's target and standstill windows give their power-on values.
    var(0x606D, T::unsigned16, A::read_write, true, "Velocity window", "rpm", 10),
    var(0x606E, T::unsigned16, A::read_write, true, "Velocity window time", "ms", 0),
    var(0x606F, T::unsigned16, A::read_write, true, "Velocity threshold", "rpm", 1),
    var(0x6070, T::unsigned16, A::read_write, true, "Velocity threshold time", "ms", 0),
    var(0x6071, T::integer16, A::read_write, true, "Target torque", permille),
    // The torque modes' demand is cut to +-0x6072 (status bit 11 then).
    var(0x6072, T::unsigned16, A::read_write, true, "Max torque", permille, 3000),
    var(0x6077, T::integer16, A::read_only, true, "Torque actual value", permille),
    var(0x607A, T::integer32, A::read_write, true, "Target position", "inc"),
    var(0x607C, T::integer32, A::read_write, true, "Home offset", "inc"),
    highest_sub(0x607D, 2, "Software position limit"),
    sub(0x607D, 1, T::integer32, "Min position limit", "inc", -2147483647LL - 1),
    sub(0x607D, 2, T::integer32, "Max position limit", "inc", 2147483647LL),
    // The lower of the two is the drive's speed limit in every mode (status bit 11 while it cuts);
    // 0x6080's power-on value is the plant's top speed.
    var(0x607F, T::unsigned32, A::read_write, true, "Max profile velocity", "rpm", 6000),
    var(0x6080, T::unsigned32, A::read_write, true, "Max motor speed", "rpm", 6000),
    var(0x6081, T::unsigned32, A::read_write, true, "Profile velocity", "rpm", 1000),
    var(0x6082, T::unsigned32, A::read_write, true, "End velocity", "rpm"),
    ramp(0x6083, "Profile acceleration", 1000),
    ramp(0x6084, "Profile deceleration", 1000),
    ramp(0x6085, "Quick stop deceleration", 10000),
    at_least_1(var(0x6087, T::unsigned32, A::read_write, true, "Torque slope", "permille/s", 10000)),
    // Increments per revolution = sub 1 / sub 2; the virtual drive's motor revolutions stay 1, and
    // an encoder has at most 2^24 increments a revolution (so every product stays in range).
    highest_sub(0x608F, 2, "Position encoder resolution"),
    limited(sub(0x608F, 1, T::unsigned32, "Encoder increments", "inc", 10000), 1, 1 << 24),
    limited(sub(0x608F, 2, T::unsigned32, "Motor revolutions", "", 1), 1, 1),
    var(0x6098, T::integer8, A::read_write, true, "Homing method", "", 35),
    highest_sub(0x6099, 2, "Homing speeds"),
    // A default method 3 run on the default plant (home switch 5 revolutions out) takes under 2 s.
    sub(0x6099, 1, T::unsigned32, "Speed during search for switch", "rpm", 1000),
    sub(0x6099, 2, T::unsigned32, "Speed during search for zero", "rpm", 100),
    at_least_1(var(0x609A, T::unsigned32, A::read_write, true, "Homing acceleration", "rpm/s", 10000)),
    var(0x60B0, T::integer32, A::read_write, true, "Position offset", "inc"),
    var(0x60B1, T::integer32, A::read_write, true, "Velocity offset", "rpm"),
    var(0x60B2, T::integer16, A::read_write, true, "Torque offset", permille),
    // Period = value x 10^index s. Information for the master: the drive takes a set-point every
    // cycle (every SYNC on CANopen).
    highest_sub(0x60C2, 2, "Interpolation time period"),
    sub(0x60C2, 1, T::unsigned8, "Interpolation time period value", "", 1),
    limited(sub(0x60C2, 2, T::integer8, "Interpolation time index", "", -3), -6, 0),
    // The homing methods motion::homing runs (tests/sim check the two agree), one a sub-index.
    // 1, 2 limit switch and index pulse; 3..14 home switch (and limit switch) and index pulse; 17..30
    // the same without the index pulse; 33, 34 index pulse; 35, 37 the present position.
    highest_sub(0x60E3, 32, "Supported homing methods"),
    read_only(sub(0x60E3, 1, T::integer8, "Supported homing method 1", "", 1)),
    read_only(sub(0x60E3, 2, T::integer8, "Supported homing method 2", "", 2)),
    read_only(sub(0x60E3, 3, T::integer8, "Supported homing method 3", "", 3)),
    read_only(sub(0x60E3, 4, T::integer8, "Supported homing method 4", "", 4)),
    read_only(sub(0x60E3, 5, T::integer8, "Supported homing method 5", "", 5)),
    read_only(sub(0x60E3, 6, T::integer8, "Supported homing method 6", "", 6)),
    read_only(sub(0x60E3, 7, T::integer8, "Supported homing method 7", "", 7)),
    read_only(sub(0x60E3, 8, T::integer8, "Supported homing method 8", "", 8)),
    read_only(sub(0x60E3, 9, T::integer8, "Supported homing method 9", "", 9)),
    read_only(sub(0x60E3, 10, T::integer8, "Supported homing method 10", "", 10)),
    read_only(sub(0x60E3, 11, T::integer8, "Supported homing method 11", "", 11)),
    read_only(sub(0x60E3, 12, T::integer8, "Supported homing method 12", "", 12)),
    read_only(sub(0x60E3, 13, T::integer8, "Supported homing method 13", "", 13)),
    read_only(sub(0x60E3, 14, T::integer8, "Supported homing method 14", "", 14)),
    read_only(sub(0x60E3, 15, T::integer8, "Supported homing method 15", "", 17)),
    read_only(sub(0x60E3, 16, T::integer8, "Supported homing method 16", "", 18)),
    read_only(sub(0x60E3, 17, T::integer8, "Supported homing method 17", "", 19)),
    read_only(sub(0x60E3, 18, T::integer8, "Supported homing method 18", "", 20)),
    read_only(sub(0x60E3, 19, T::integer8, "Supported homing method 19", "", 21)),
    read_only(sub(0x60E3, 20, T::integer8, "Supported homing method 20", "", 22)),
    read_only(sub(0x60E3, 21, T::integer8, "Supported homing method 21", "", 23)),
    read_only(sub(0x60E3, 22, T::integer8, "Supported homing method 22", "", 24)),
    read_only(sub(0x60E3, 23, T::integer8, "Supported homing method 23", "", 25)),
    read_only(sub(0x60E3, 24, T::integer8, "Supported homing method 24", "", 26)),
    read_only(sub(0x60E3, 25, T::integer8, "Supported homing method 25", "", 27)),
    read_only(sub(0x60E3, 26, T::integer8, "Supported homing method 26", "", 28)),
    read_only(sub(0x60E3, 27, T::integer8, "Supported homing method 27", "", 29)),
    read_only(sub(0x60E3, 28, T::integer8, "Supported homing method 28", "", 30)),
    read_only(sub(0x60E3, 29, T::integer8, "Supported homing method 29", "", 33)),
    read_only(sub(0x60E3, 30, T::integer8, "Supported homing method 30", "", 34)),
    read_only(sub(0x60E3, 31, T::integer8, "Supported homing method 31", "", 35)),
    read_only(sub(0x60E3, 32, T::integer8, "Supported homing method 32", "", 37)),
    var(0x60F4, T::integer32, A::read_only, true, "Following error actual value", "inc"),
    // Bit 0 negative limit switch, 1 positive limit switch, 2 home switch (CiA 402-2); bit 16
    // (manufacturer-specific) an index pulse passed in the last cycle.
    var(0x60FD, T::unsigned32, A::read_only, true, "Digital inputs"),
    var(0x60FF, T::integer32, A::read_write, true, "Target velocity", "rpm"),
    // pp (bit 0), pv (2), tq (3), hm (5), csp (7), csv (8), cst (9).
    var(0x6502, T::unsigned32, A::read_only, false, "Supported drive modes", "", 0x3AD),
};
}  // namespace detail

namespace {
constexpr const auto& objects = detail::drive_object_table;
constexpr std::size_t count = sizeof(objects) / sizeof(objects[0]);

constexpr bool in_index_order() noexcept {
  for (std::size_t i = 1; i < count; ++i) {
    const bool after = objects[i - 1].index < objects[i].index ||
                       (objects[i - 1].index == objects[i].index && objects[i - 1].sub < objects[i].sub);
    if (!after) return false;
  }
  return true;
}
static_assert(in_index_order(), "the object table is kept in index and sub-index order");

}  // namespace

std::size_t drive_object_count() noexcept { return count; }

const object_description& drive_object(std::size_t i) noexcept { return objects[i < count ? i : 0]; }

// Where each 0x60xx object starts in the table (its lowest sub-index), or none: the set-points
// a master writes every cycle are all 0x60xx, so they are found by one load, not a search.
constexpr std::uint8_t not_in_table = 0xFF;
namespace detail {
constexpr std::array<std::uint8_t, 256> drive_object_60xx = [] {
  std::array<std::uint8_t, 256> t{};
  for (auto& e : t) e = not_in_table;
  for (std::size_t i = count; i-- > 0;) {
    if ((objects[i].index >> 8) == 0x60) t[objects[i].index & 0xFFu] = static_cast<std::uint8_t>(i);
  }
  return t;
}();
}  // namespace detail
static_assert(count < not_in_table, "table positions fit a byte");

static_assert((objects[count - 1].index >> 8) != 0x60,
              "the last entry is not a 0x60xx object: find_drive_object's scan ends inside the table");

namespace detail {
// Binary search, for the objects outside 0x60xx.
const object_description* find_drive_object_by_search(std::uint16_t index, std::uint8_t sub) noexcept {
  const std::uint32_t key = (std::uint32_t{index} << 8) | sub;
  std::size_t lo = 0;
  std::size_t hi = count;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    const std::uint32_t at = (std::uint32_t{objects[mid].index} << 8) | objects[mid].sub;
    if (at == key) return &objects[mid];
    if (at < key) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return nullptr;
}
}  // namespace detail

namespace {
struct mode_name {
  std::int8_t number;
  const char* name;
};
constexpr mode_name mode_names[] = {{mode::profile_position, "pp"}, {mode::profile_velocity, "pv"},
                                    {mode::profile_torque, "tq"}, {mode::homing, "hm"},
                                    {mode::cyclic_synchronous_position, "csp"},
                                    {mode::cyclic_synchronous_velocity, "csv"},
                                    {mode::cyclic_synchronous_torque, "cst"}};
}  // namespace

const char* mode::short_name(std::int64_t m) noexcept {
  for (const mode_name& n : mode_names) {
    if (n.number == m) return n.name;
  }
  return "";
}

bool mode::parse(std::string_view text, std::int8_t& out) noexcept {
  for (const mode_name& n : mode_names) {
    if (text == n.name) {
      out = n.number;
      return true;
    }
  }
  if (text.empty() || text.size() > 4) return false;
  int value = 0;
  bool negative = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (i == 0 && c == '-' && text.size() > 1) {
      negative = true;
    } else if (c >= '0' && c <= '9') {
      value = value * 10 + (c - '0');
    } else {
      return false;
    }
  }
  value = negative ? -value : value;
  if (value < -128 || value > 127) return false;
  out = static_cast<std::int8_t>(value);
  return true;
}

}  // namespace cia402
