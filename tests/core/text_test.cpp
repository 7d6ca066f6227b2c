// The core's allocation-free texts the layers share: a number in hexadecimal (to_hex, the "0x6040"
// of every message of the layers that see only the core) and an SDO abort as messages name it
// (sdo_abort_words). Each is checked against an independent printf spelling.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "cia402/hex_text.hpp"
#include "cia402/sdo_abort.hpp"

namespace {

using namespace cia402;

std::string printf_hex(unsigned long long v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%0*llX", digits, v);
  return buf;
}

TEST(core_text, hex_pads_to_the_digits_in_upper_case) {
  EXPECT_STREQ(to_hex(0x6040, 4).c_str(), "0x6040");
  EXPECT_STREQ(to_hex(0x3F, 4).c_str(), "0x003F");
  EXPECT_STREQ(to_hex(0x6, 2).c_str(), "0x06");
  EXPECT_STREQ(to_hex(0x06090011, 8).c_str(), "0x06090011");
  EXPECT_STREQ(to_hex(0xabcdef, 6).c_str(), "0xABCDEF");
  EXPECT_STREQ(to_hex(0, 1).c_str(), "0x0");
  EXPECT_STREQ(to_hex(0, 0).c_str(), "0x0") << "no digits asked: still one";
}

TEST(core_text, hex_widens_for_a_value_the_digits_do_not_hold) {
  EXPECT_STREQ(to_hex(0x12345, 4).c_str(), "0x12345");
  EXPECT_STREQ(to_hex(0x1FF, 1).c_str(), "0x1FF");
  EXPECT_STREQ(to_hex(0xFFFFFFFFFFFFFFFFull, 4).c_str(), "0xFFFFFFFFFFFFFFFF");
  EXPECT_STREQ(to_hex(0x1, 40).c_str(), "0x0000000000000001") << "16 digits at the most";
}

TEST(core_text, hex_is_the_printf_text_for_every_width) {
  const unsigned long long values[] = {0, 1, 0xF, 0x10, 0x605A, 0xFFFF, 0x10000, 0x06090030,
                                       0xFFFFFFFF, 0x123456789ABull, 0xFFFFFFFFFFFFFFFFull};
  for (const unsigned long long v : values) {
    for (int digits = 1; digits <= 16; ++digits) {
      EXPECT_EQ(to_hex(v, digits).c_str(), printf_hex(v, digits)) << v << " in " << digits;
    }
  }
}

TEST(core_text, hex_is_a_constant_expression) {
  constexpr hex_text t = to_hex(0x6041, 4);
  static_assert(t.chars[0] == '0' && t.chars[1] == 'x' && t.chars[2] == '6' && t.chars[5] == '1' &&
                t.chars[6] == '\0');
  EXPECT_STREQ(t.c_str(), "0x6041");
}

// Every code the enum names: each has a reason of its own, not the fallback.
constexpr sdo_abort every_abort[] = {
    sdo_abort::none, sdo_abort::toggle_bit_not_alternated, sdo_abort::sdo_protocol_timed_out,
    sdo_abort::command_specifier_invalid, sdo_abort::out_of_memory, sdo_abort::unsupported_access,
    sdo_abort::write_only_object, sdo_abort::read_only_object, sdo_abort::object_does_not_exist,
    sdo_abort::cannot_map_to_pdo, sdo_abort::pdo_length_exceeded,
    sdo_abort::general_parameter_incompatibility, sdo_abort::hardware_error,
    sdo_abort::data_type_length_mismatch, sdo_abort::data_type_length_too_high,
    sdo_abort::data_type_length_too_low, sdo_abort::sub_index_does_not_exist, sdo_abort::invalid_value,
    sdo_abort::value_too_high, sdo_abort::value_too_low, sdo_abort::general_error,
    sdo_abort::cannot_store_in_present_state, sdo_abort::no_data_available,
};

TEST(core_text, every_sdo_abort_code_has_a_text_of_its_own) {
  for (const sdo_abort a : every_abort) {
    const char* text = sdo_abort_text(a);
    ASSERT_NE(text, nullptr);
    EXPECT_STRNE(text, "unknown abort code") << printf_hex(static_cast<std::uint32_t>(a), 8);
    EXPECT_GT(std::strlen(text), 0u);
    for (const sdo_abort b : every_abort) {
      if (a != b) EXPECT_STRNE(text, sdo_abort_text(b));
    }
  }
  EXPECT_STREQ(sdo_abort_text(static_cast<sdo_abort>(0x12345678)), "unknown abort code");
}

TEST(core_text, an_abort_reads_with_its_eight_digits_and_its_whole_reason) {
  EXPECT_STREQ(sdo_abort_words(sdo_abort::sub_index_does_not_exist).c_str(),
               "SDO abort 0x06090011 (sub-index does not exist)");
  EXPECT_STREQ(sdo_abort_words(sdo_abort::none).c_str(), "SDO abort 0x00000000 (no error)");
  EXPECT_STREQ(sdo_abort_words(static_cast<sdo_abort>(0xFFFFFFFF)).c_str(),
               "SDO abort 0xFFFFFFFF (unknown abort code)");
  for (const sdo_abort a : every_abort) {
    const std::string expected = "SDO abort " + printf_hex(static_cast<std::uint32_t>(a), 8) + " (" +
                                 sdo_abort_text(a) + ")";
    EXPECT_EQ(sdo_abort_words(a).c_str(), expected) << "the buffer holds the longest reason whole";
  }
}

}  // namespace
