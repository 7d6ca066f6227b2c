// The shared text helpers: hexadecimal as every message writes it, and integers as a person types
// them, with the bounds and the refusals the command line and the file formats rely on.
#include <gtest/gtest.h>

#include <limits>

#include "cia402/support/text.hpp"

namespace {

using cia402::support::hex;
using cia402::support::parse_integer;

TEST(support_text, hex_pads_to_the_digits_and_widens_for_larger_values) {
  EXPECT_EQ(hex(0x6041, 4), "0x6041");
  EXPECT_EQ(hex(0x3F, 4), "0x003F");
  EXPECT_EQ(hex(0x06090030, 8), "0x06090030");
  EXPECT_EQ(hex(0xABCDE, 4), "0xABCDE");
  EXPECT_EQ(hex(0, 2), "0x00");
  EXPECT_EQ(hex(0xFFFFFFFFFFFFFFFFull, 16), "0xFFFFFFFFFFFFFFFF");
}

TEST(support_text, hex_takes_another_prefix_or_none) {
  EXPECT_EQ(hex(0x1A00, 4, ""), "1A00") << "an EDS section name";
  EXPECT_EQ(hex(0x1, 4, "#x"), "#x0001") << "an ESI number";
  EXPECT_EQ(hex(0x12345678, 8, "#x"), "#x12345678");
  EXPECT_EQ(hex(0x1ABCD, 4, ""), "1ABCD");
  EXPECT_EQ(hex(0x7FF, 1), "0x7FF") << "one digit asked: as many as the value needs";
}

TEST(support_text, integers_in_decimal_and_hex_with_a_sign) {
  constexpr std::int64_t lo = std::numeric_limits<std::int32_t>::min();
  constexpr std::int64_t hi = std::numeric_limits<std::uint32_t>::max();
  EXPECT_EQ(parse_integer("0", lo, hi), 0);
  EXPECT_EQ(parse_integer("1500", lo, hi), 1500);
  EXPECT_EQ(parse_integer("+7", lo, hi), 7);
  EXPECT_EQ(parse_integer("-1500", lo, hi), -1500);
  EXPECT_EQ(parse_integer("0x605A", lo, hi), 0x605A);
  EXPECT_EQ(parse_integer("0X605a", lo, hi), 0x605A);
  EXPECT_EQ(parse_integer("-0x80000000", lo, hi), lo);
  EXPECT_EQ(parse_integer("0xFFFFFFFF", lo, hi), hi);
  EXPECT_EQ(parse_integer("-9223372036854775808", std::numeric_limits<std::int64_t>::min(), 0),
            std::numeric_limits<std::int64_t>::min());
}

TEST(support_text, anything_else_is_refused) {
  for (const char* bad : {"", "-", "+", "0x", "--5", "+-5", "0x-5", "0x+5", "12a", "1.5", " 5",
                          "5 ", "0b101", "0xG", "99999999999999999999999"}) {
    EXPECT_FALSE(parse_integer(bad, std::numeric_limits<std::int64_t>::min(),
                               std::numeric_limits<std::int64_t>::max()))
        << '"' << bad << '"';
  }
  EXPECT_FALSE(parse_integer("0x10000", 0, 0xFFFF));
  EXPECT_FALSE(parse_integer("-1", 0, 0xFFFF));
  EXPECT_FALSE(parse_integer("-0x80000001", std::numeric_limits<std::int32_t>::min(), 0));
  EXPECT_FALSE(parse_integer("9223372036854775808", 0, std::numeric_limits<std::int64_t>::max()));
}

}  // namespace
