// The emergency error code table (include/cia402/error_codes.hpp): the texts of CiA 301 table 21 and
// of CiA 402's device-profile codes, written out here from the standards, and the fallback to a
// code's class and group.
#include <gtest/gtest.h>

#include <cstring>
#include <initializer_list>
#include <string>

#include "cia402/drive.hpp"
#include "cia402/error_codes.hpp"

namespace cia402 {
namespace {

struct code_text {
  std::uint16_t code;
  const char* text;
};

// Each code has its text.
void expect_texts(std::initializer_list<code_text> expected) {
  for (const code_text& e : expected) {
    EXPECT_STREQ(error_code_text(e.code), e.text) << std::hex << e.code;
  }
}

TEST(error_codes, the_generic_codes_of_cia_301_table_21_have_their_texts) {
  expect_texts({
      {0x0000, "error reset or no error"},   {0x1000, "generic error"},
      {0x2000, "current"},                   {0x3000, "voltage"},
      {0x3210, "DC link over-voltage"},      {0x3220, "DC link under-voltage"},
      {0x4000, "temperature"},               {0x5000, "device hardware"},
      {0x6000, "device software"},           {0x7000, "additional modules"},
      {0x8000, "monitoring"},                {0x8110, "CAN overrun (objects lost)"},
      {0x8120, "CAN in error passive mode"}, {0x8130, "life guard error or heartbeat error"},
      {0x8140, "recovered from bus off"},    {0x8210, "PDO not processed due to length error"},
      {0x9000, "external error"},            {0xFF00, "device specific"},
  });
}

TEST(error_codes, the_cia_402_codes_a_drive_reports_have_their_texts) {
  expect_texts({
      {0x2310, "continuous over-current"},
      {0x4310, "excess drive temperature"},
      {0x8611, "following error"},
      {0x7121, "motor blocked"},
  });
}

TEST(error_codes, every_code_the_projects_drive_raises_has_an_entry_of_its_own) {
  // drive.hpp's codes, the plant's following error (0x8611) and the node's PDO length error (0x8210).
  for (std::uint16_t code : {error_code::generic, error_code::dc_link_undervoltage,
                             error_code::safe_torque_off, error_code::heartbeat,
                             std::uint16_t{0x8611}, std::uint16_t{0x8210}}) {
    bool found = false;
    for (std::size_t i = 0; i < error_code_count(); ++i) found |= error_code_entry(i).code == code;
    EXPECT_TRUE(found) << std::hex << code;
  }
  EXPECT_NE(std::string(error_code_text(error_code::safe_torque_off)).find("safe torque off"),
            std::string::npos);
}

TEST(error_codes, a_code_without_an_entry_takes_the_text_of_its_class_then_of_its_group) {
  expect_texts({
      {0x2315, "current, device output side"},  // class 0x2300
      {0x8131, "communication"},                // class 0x8100
      {0x8FFF, "monitoring"},                   // group 0x8000
      {0x2A17, "current"},                      // group 0x2000
      {0xFF42, "device specific"},              // class 0xFF00
      {0xF0AB, "additional functions"},         // class 0xF000
  });
}

TEST(error_codes, a_code_in_no_class_is_unknown_not_no_error) {
  expect_texts({
      {0x0001, "unknown error code"},
      {0x0FFF, "unknown error code"},
      {0xA000, "unknown error code"},
      {0xE123, "unknown error code"},
  });
}

TEST(error_codes, the_table_is_ascending_and_every_code_finds_its_own_entry) {
  ASSERT_GT(error_code_count(), 100u);
  for (std::size_t i = 0; i < error_code_count(); ++i) {
    const error_code_description& e = error_code_entry(i);
    ASSERT_NE(e.text, nullptr);
    EXPECT_GT(std::strlen(e.text), 0u);
    if (i > 0) {
      EXPECT_LT(error_code_entry(i - 1).code, e.code);
    }
    EXPECT_EQ(error_code_text(e.code), e.text) << std::hex << e.code;
  }
}

TEST(error_codes, every_16_bit_code_has_a_text) {
  for (unsigned code = 0; code <= 0xFFFF; ++code) {
    const char* text = error_code_text(static_cast<std::uint16_t>(code));
    ASSERT_NE(text, nullptr);
    ASSERT_NE(text[0], '\0');
  }
}

}  // namespace
}  // namespace cia402
