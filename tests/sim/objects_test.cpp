// The object interface the CANopen layer will sit on: write()/read() with CiA 301 SDO abort codes.
// Expected codes come from CiA 301 (object dictionary access) and the object types of CiA 402
// (0x6040 UINT16, 0x60FF INT32, 0x6083..0x6085 UINT32, option codes INT16, 0x6060 INT8).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "sim_support.hpp"

namespace {

using namespace sim_test;

TEST(objects, writes_to_read_only_objects_abort_with_0x06010002_and_change_nothing) {
  virtual_drive d(standard_profile());
  for (std::uint16_t index : {0x6041, 0x606C, 0x603F, 0x1001, 0x6061}) {
    std::int64_t before = -1;
    ASSERT_EQ(d.read(index, 0, before), sdo_abort::none) << std::hex << index;
    EXPECT_EQ(d.write(index, 0, 1), sdo_abort::read_only_object) << std::hex << index;
    std::int64_t after = -2;
    ASSERT_EQ(d.read(index, 0, after), sdo_abort::none);
    EXPECT_EQ(before, after);
  }
}

TEST(objects, unknown_indices_abort_with_0x06020000_for_read_and_write) {
  virtual_drive d(standard_profile());
  std::int64_t v = 0;
  for (std::uint16_t index : {0x0000, 0x1000, 0x2000, 0x6042, 0x6063, 0xFFFF}) {
    EXPECT_EQ(d.write(index, 0, 0), sdo_abort::object_does_not_exist) << std::hex << index;
    EXPECT_EQ(d.write(index, 3, 0), sdo_abort::object_does_not_exist) << std::hex << index;
    EXPECT_EQ(d.read(index, 0, v), sdo_abort::object_does_not_exist) << std::hex << index;
  }
}

TEST(objects, a_sub_index_other_than_0_aborts_with_0x06090011) {
  virtual_drive d(standard_profile());
  std::int64_t v = 0;
  for (std::uint16_t index : {0x6040, 0x6041, 0x60FF, 0x6083, 0x605A, 0x6007, 0x1001}) {
    EXPECT_EQ(d.write(index, 1, 0), sdo_abort::sub_index_does_not_exist) << std::hex << index;
    EXPECT_EQ(d.read(index, 1, v), sdo_abort::sub_index_does_not_exist) << std::hex << index;
  }
}

struct range_case {
  std::uint16_t index;
  std::int64_t value;
  sdo_abort expected;
};

void PrintTo(const range_case& c, std::ostream* os) {
  *os << std::hex << "0x" << c.index << std::dec << " = " << c.value;
}

class object_range : public ::testing::TestWithParam<range_case> {};

TEST_P(object_range, values_outside_the_type_abort_and_inside_are_taken) {
  const range_case c = GetParam();
  virtual_drive d(standard_profile());
  std::int64_t before = 0;
  ASSERT_EQ(d.read(c.index, 0, before), sdo_abort::none);
  EXPECT_EQ(d.write(c.index, 0, c.value), c.expected)
      << std::hex << c.index << " = " << std::dec << c.value;
  std::int64_t after = 0;
  ASSERT_EQ(d.read(c.index, 0, after), sdo_abort::none);
  if (c.expected == sdo_abort::none) {
    EXPECT_EQ(after, c.value);
  } else {
    EXPECT_EQ(after, before) << "a refused write changed the object";
  }
}

constexpr std::int64_t i32_min = std::numeric_limits<std::int32_t>::min();
constexpr std::int64_t i32_max = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t u32_max = std::numeric_limits<std::uint32_t>::max();

INSTANTIATE_TEST_SUITE_P(
    types, object_range,
    ::testing::Values(
        range_case{0x6040, 0, sdo_abort::none}, range_case{0x6040, 0xFFFF, sdo_abort::none},
        range_case{0x6040, 0x10000, sdo_abort::value_too_high},
        range_case{0x6040, -1, sdo_abort::value_too_low},
        range_case{0x60FF, i32_min, sdo_abort::none}, range_case{0x60FF, i32_max, sdo_abort::none},
        range_case{0x60FF, i32_max + 1, sdo_abort::value_too_high},
        range_case{0x60FF, i32_min - 1, sdo_abort::value_too_low},
        range_case{0x6083, 1, sdo_abort::none}, range_case{0x6083, u32_max, sdo_abort::none},
        range_case{0x6083, 0, sdo_abort::value_too_low},
        range_case{0x6084, 0, sdo_abort::value_too_low},
        range_case{0x6085, 0, sdo_abort::value_too_low},
        range_case{0x6085, u32_max + 1, sdo_abort::value_too_high},
        range_case{0x605A, 6, sdo_abort::none}, range_case{0x605A, 9, sdo_abort::invalid_value},
        range_case{0x605A, -1, sdo_abort::invalid_value},
        range_case{0x605A, 40000, sdo_abort::value_too_high},
        range_case{0x605A, -40000, sdo_abort::value_too_low},
        range_case{0x605D, 0, sdo_abort::invalid_value}, range_case{0x605E, 4, sdo_abort::none},
        range_case{0x6007, 3, sdo_abort::none}, range_case{0x6007, 4, sdo_abort::invalid_value},
        range_case{0x6060, 3, sdo_abort::none}, range_case{0x6060, 1, sdo_abort::none},
        range_case{0x6060, 2, sdo_abort::invalid_value}, range_case{0x6060, 7, sdo_abort::invalid_value},
        range_case{0x6060, 0, sdo_abort::invalid_value}, range_case{0x6098, 37, sdo_abort::none},
        range_case{0x6098, 15, sdo_abort::invalid_value}, range_case{0x6098, 36, sdo_abort::invalid_value},
        range_case{0x6060, 128, sdo_abort::value_too_high}),
    [](const auto& info) {
      const auto& c = info.param;
      std::string v = c.value < 0 ? "minus_" + std::to_string(-c.value) : std::to_string(c.value);
      static constexpr char d[] = "0123456789ABCDEF";
      std::string idx;
      for (int i = 3; i >= 0; --i) idx += d[(c.index >> (4 * i)) & 0xF];
      return "x" + idx + "_" + v;
    });

TEST(objects, option_codes_a_profile_lacks_do_not_exist) {
  virtual_drive d(*find_builtin_profile("no-quick-stop"));  // seed 000: no quick stop
  std::int64_t v = 0;
  EXPECT_EQ(d.write(0x605A, 0, 2), sdo_abort::object_does_not_exist);
  EXPECT_EQ(d.read(0x605A, 0, v), sdo_abort::object_does_not_exist);
  EXPECT_EQ(d.write(0x605E, 0, 2), sdo_abort::none);
}

TEST(objects, reads_report_the_drive_as_it_is) {
  virtual_drive d(standard_profile());
  run_at(d, 0);
  ASSERT_EQ(d.write(0x60FF, 0, -1234), sdo_abort::none);
  ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().velocity_rpm() == -1234; }), 0);
  std::int64_t v = 0;
  ASSERT_EQ(d.read(0x606C, 0, v), sdo_abort::none);
  EXPECT_EQ(v, -1234);
  ASSERT_EQ(d.read(0x6041, 0, v), sdo_abort::none);
  EXPECT_EQ(v, d.view().outputs().status_word);
  EXPECT_EQ(v & 0x6F, 0x27);  // OPERATION ENABLED
  ASSERT_EQ(d.read(0x6040, 0, v), sdo_abort::none);
  EXPECT_EQ(v, 0x000F);
  ASSERT_EQ(d.read(0x6061, 0, v), sdo_abort::none);
  EXPECT_EQ(v, 3);  // profile velocity mode
  d.view().inject_fault(0x2310);
  d.step();
  ASSERT_EQ(d.read(0x603F, 0, v), sdo_abort::none);
  EXPECT_EQ(v, 0x2310);
  ASSERT_EQ(d.read(0x1001, 0, v), sdo_abort::none);
  EXPECT_EQ(v, 0x03);  // CiA 301: generic + current
}

TEST(objects, actual_velocity_rounds_towards_zero) {
  virtual_drive d(standard_profile());
  ASSERT_EQ(d.write(0x6083, 0, 1500), sdo_abort::none);  // 1.5 rpm per cycle
  enable(d);
  ASSERT_EQ(d.write(0x60FF, 0, -100), sdo_abort::none);
  ASSERT_GT(step_until(d, [&](const drive_outputs&) {
              return d.view().velocity_micro_rpm() == -1500000 * 3;  // -4.5 rpm
            }),
            0);
  std::int64_t v = 0;
  ASSERT_EQ(d.read(0x606C, 0, v), sdo_abort::none);
  EXPECT_EQ(v, -4);
}

TEST(objects, a_control_word_write_acts_in_the_next_cycle) {
  virtual_drive d(standard_profile());
  for (int i = 0; i < 3; ++i) d.step();
  ASSERT_EQ(d.view().current(), state::switch_on_disabled);
  ASSERT_EQ(d.write(0x6040, 0, 0x0006), sdo_abort::none);
  EXPECT_EQ(d.view().current(), state::switch_on_disabled);
  EXPECT_EQ(d.step().transition, 2);
}

}  // namespace

namespace {

// Every object of the one table (cia402/objects.hpp) is the virtual drive's: readable where the
// table says so, refused as read-only where it says so, and writable at its limits.
TEST(objects, the_virtual_drive_answers_every_object_of_the_one_table) {
  virtual_drive d(standard_profile());
  for (std::size_t i = 0; i < cia402::drive_object_count(); ++i) {
    const cia402::object_description& o = cia402::drive_object(i);
    SCOPED_TRACE(o.name);
    std::int64_t value = 0;
    ASSERT_EQ(d.read(o.index, o.sub, value), sdo_abort::none);
    EXPECT_GE(value, cia402::type_min(o.type));
    EXPECT_LE(value, cia402::type_max(o.type));
    if (o.access == cia402::object_access::read_only) {
      EXPECT_EQ(d.write(o.index, o.sub, value), sdo_abort::read_only_object);
      continue;
    }
    if (o.index == 0x6060 || o.index == 0x6098 || (o.index >= 0x605A && o.index <= 0x605E) ||
        o.index == 0x6007) {
      continue;  // which values these take is the profile's (S5..S10), the modes' and the methods
    }
    EXPECT_EQ(d.write(o.index, o.sub, o.low - 1), sdo_abort::value_too_low);
    EXPECT_EQ(d.write(o.index, o.sub, o.high + 1), sdo_abort::value_too_high);
    EXPECT_EQ(d.write(o.index, o.sub, o.high), sdo_abort::none);
    ASSERT_EQ(d.read(o.index, o.sub, value), sdo_abort::none);
    EXPECT_EQ(value, o.high);
  }
}

// Each writable object holds its value in a place of its own: values written to all of them, each
// different, read back unchanged (two objects sharing a field would show the later write twice).
TEST(objects, every_writable_object_keeps_a_value_of_its_own) {
  virtual_drive d(standard_profile());
  std::vector<std::pair<const cia402::object_description*, std::int64_t>> written;
  for (std::size_t i = 0; i < cia402::drive_object_count(); ++i) {
    const cia402::object_description& o = cia402::drive_object(i);
    if (o.access == cia402::object_access::read_only || o.index == 0x6040 || o.index == 0x6060 ||
        o.index == 0x6098 || (o.index >= 0x605A && o.index <= 0x605E) || o.index == 0x6007 || o.low == o.high) {
      continue;  // the control word acts; these take the profile's or the modes' values only
    }
    // A value inside the limits that no other object gets: the high limit less the object's rank.
    const std::int64_t value = std::max<std::int64_t>(o.low, o.high - static_cast<std::int64_t>(written.size()));
    ASSERT_EQ(d.write(o.index, o.sub, value), sdo_abort::none) << o.name;
    written.emplace_back(&o, value);
  }
  ASSERT_GT(written.size(), 20u);
  for (const auto& [o, value] : written) {
    std::int64_t read_back = 0;
    ASSERT_EQ(d.read(o->index, o->sub, read_back), sdo_abort::none) << o->name;
    EXPECT_EQ(read_back, value) << o->name;
  }
}

}  // namespace
