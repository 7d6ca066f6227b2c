// The one CiA 402 object table (include/cia402/objects.hpp): its entries as CiA 402 and CiA 301
// give them, and the write check every layer uses.
#include <gtest/gtest.h>

#include "cia402/objects.hpp"
#include "cia402/profile.hpp"

#include <limits>
#include <vector>

namespace cia402 {
namespace {

// CiA 301 §7.1.6: an integer type's range is all its size and sign allow (UNSIGNED64 up to what an
// int64 holds); BOOLEAN is 0..1 in one byte; VISIBLE_STRING has no fixed size.
TEST(data_types, each_integer_type_ranges_over_what_its_size_and_sign_allow) {
  for (const data_type t : {data_type::integer8, data_type::integer16, data_type::integer32, data_type::unsigned8,
                            data_type::unsigned16, data_type::unsigned32}) {
    const unsigned bits = 8 * type_size(t);
    if (type_is_signed(t)) {
      EXPECT_EQ(type_min(t), -(std::int64_t{1} << (bits - 1))) << type_name(t);
      EXPECT_EQ(type_max(t), (std::int64_t{1} << (bits - 1)) - 1) << type_name(t);
    } else {
      EXPECT_EQ(type_min(t), 0) << type_name(t);
      EXPECT_EQ(type_max(t), (std::int64_t{1} << bits) - 1) << type_name(t);
    }
  }
  EXPECT_EQ(type_size(data_type::integer64), 8u);
  EXPECT_EQ(type_min(data_type::integer64), std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(type_max(data_type::unsigned64), std::numeric_limits<std::int64_t>::max());
  EXPECT_FALSE(type_is_signed(data_type::unsigned64));
  EXPECT_EQ(type_size(data_type::boolean), 1u);
  EXPECT_EQ(type_max(data_type::boolean), 1);
  EXPECT_EQ(type_size(data_type::visible_string), 0u);
  EXPECT_STREQ(type_name(data_type::unsigned16), "UNSIGNED16");
  EXPECT_STREQ(type_name(data_type::visible_string), "VISIBLE_STRING");
}

TEST(objects, every_option_code_is_an_integer16_the_profile_decides_the_values_of) {
  for (int i = 0; i < option_count; ++i) {
    const std::uint16_t index = option_index(static_cast<option>(i));
    const object_description* o = find_drive_object(index);
    ASSERT_NE(o, nullptr) << std::hex << index;
    EXPECT_EQ(o->type, data_type::integer16);
    EXPECT_EQ(o->access, object_access::read_write);
    EXPECT_FALSE(o->pdo_mappable);
  }
}

TEST(objects, the_table_holds_the_drive_objects_with_their_types_and_access) {
  struct expected {
    std::uint16_t index;
    data_type type;
    object_access access;
  };
  // CiA 402-2: controlword UNSIGNED16 rw, statusword UNSIGNED16 ro, error code UNSIGNED16 ro,
  // modes INTEGER8, velocity actual and target velocity INTEGER32, ramps UNSIGNED32.
  const expected table[] = {
      {0x603F, data_type::unsigned16, object_access::read_only},
      {0x6040, data_type::unsigned16, object_access::read_write},
      {0x6041, data_type::unsigned16, object_access::read_only},
      {0x6060, data_type::integer8, object_access::read_write},
      {0x6061, data_type::integer8, object_access::read_only},
      {0x606C, data_type::integer32, object_access::read_only},
      {0x6083, data_type::unsigned32, object_access::read_write},
      {0x6084, data_type::unsigned32, object_access::read_write},
      {0x6085, data_type::unsigned32, object_access::read_write},
      {0x60FF, data_type::integer32, object_access::read_write},
      {0x6502, data_type::unsigned32, object_access::read_only},
      {0x6062, data_type::integer32, object_access::read_only},
      {0x6064, data_type::integer32, object_access::read_only},
      {0x6065, data_type::unsigned32, object_access::read_write},
      {0x6066, data_type::unsigned16, object_access::read_write},
      {0x6067, data_type::unsigned32, object_access::read_write},
      {0x6068, data_type::unsigned16, object_access::read_write},
      {0x6071, data_type::integer16, object_access::read_write},
      {0x6077, data_type::integer16, object_access::read_only},
      {0x607A, data_type::integer32, object_access::read_write},
      {0x607C, data_type::integer32, object_access::read_write},
      {0x6081, data_type::unsigned32, object_access::read_write},
      {0x6082, data_type::unsigned32, object_access::read_write},
      {0x6087, data_type::unsigned32, object_access::read_write},
      {0x6098, data_type::integer8, object_access::read_write},
      {0x609A, data_type::unsigned32, object_access::read_write},
      {0x60B0, data_type::integer32, object_access::read_write},
      {0x60B1, data_type::integer32, object_access::read_write},
      {0x60B2, data_type::integer16, object_access::read_write},
      {0x60F4, data_type::integer32, object_access::read_only},
  };
  for (const expected& e : table) {
    const object_description* o = find_drive_object(e.index);
    ASSERT_NE(o, nullptr) << std::hex << e.index;
    EXPECT_EQ(o->type, e.type) << std::hex << e.index;
    EXPECT_EQ(o->access, e.access) << std::hex << e.index;
    EXPECT_GE(o->low, type_min(o->type));
    EXPECT_LE(o->high, type_max(o->type));
    EXPECT_GE(o->default_value, o->low);
    EXPECT_LE(o->default_value, o->high);
    EXPECT_NE(o->name[0], '\0');
  }
  EXPECT_EQ(find_drive_object(0x6040, 1), nullptr) << "sub-index 1 does not exist";
  EXPECT_EQ(find_drive_object(0x6000), nullptr);
  for (std::size_t i = 1; i < drive_object_count(); ++i) {
    const object_description& a = drive_object(i - 1);
    const object_description& b = drive_object(i);
    EXPECT_TRUE(a.index < b.index || (a.index == b.index && a.sub < b.sub))
        << "kept in index and sub-index order: " << std::hex << b.index;
  }
  // An array's sub-index 0 is read-only and counts the entries that follow it.
  for (std::uint16_t index : {0x607D, 0x608F, 0x6099, 0x60C2}) {
    const object_description* count = find_drive_object(index, 0);
    ASSERT_NE(count, nullptr) << std::hex << index;
    EXPECT_EQ(count->access, object_access::read_only);
    EXPECT_EQ(count->default_value, 2);
    EXPECT_NE(find_drive_object(index, 2), nullptr);
    EXPECT_EQ(find_drive_object(index, 3), nullptr);
  }
}

TEST(objects, a_write_is_checked_against_access_type_and_limits) {
  const object_description& ramp = *find_drive_object(0x6083);
  EXPECT_EQ(check_write(ramp, 0), sdo_abort::value_too_low) << "a ramp of 0 would never end";
  EXPECT_EQ(check_write(ramp, 1), sdo_abort::none);
  EXPECT_EQ(check_write(ramp, 4294967295LL), sdo_abort::none);
  EXPECT_EQ(check_write(ramp, 4294967296LL), sdo_abort::value_too_high);
  EXPECT_EQ(check_write(*find_drive_object(0x6041), 0), sdo_abort::read_only_object);
  EXPECT_EQ(check_write(*find_drive_object(0x60FF), -2147483648LL), sdo_abort::none);
  EXPECT_EQ(check_write(*find_drive_object(0x60FF), -2147483649LL), sdo_abort::value_too_low);
  EXPECT_EQ(check_write(*find_drive_object(0x605A), 32768), sdo_abort::value_too_high);
}

TEST(objects, lookup_finds_exactly_what_a_scan_of_the_table_finds_for_every_index_and_sub) {
  // Every (index, sub) of 0x60xx (looked up by a table) and of each index beside a table entry
  // (binary search), against a plain linear scan.
  std::vector<std::uint32_t> indices;
  for (std::uint32_t index = 0x6000; index <= 0x60FF; ++index) indices.push_back(index);
  for (std::size_t i = 0; i < drive_object_count(); ++i) {
    for (int d = -1; d <= 1; ++d) indices.push_back(static_cast<std::uint32_t>(drive_object(i).index + d));
  }
  for (const std::uint32_t index : indices) {
    for (std::uint32_t sub = 0; sub <= 0xFF; ++sub) {
      const object_description* scanned = nullptr;
      for (std::size_t i = 0; i < drive_object_count(); ++i) {
        if (drive_object(i).index == index && drive_object(i).sub == sub) scanned = &drive_object(i);
      }
      ASSERT_EQ(find_drive_object(static_cast<std::uint16_t>(index), static_cast<std::uint8_t>(sub)), scanned)
          << std::hex << index << ":" << sub;
    }
  }
}

}  // namespace
}  // namespace cia402
