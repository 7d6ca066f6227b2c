// Typed values: command-line text to a value, a value to the bytes of its type and back, JSON and
// words; and the session's object reads and writes with the type from the core's table, the link's
// describe(), or none (then the drive's answers decide a number's size).
#include <gtest/gtest.h>

#include "bench.hpp"
#include "cia402/axis/object_value.hpp"

namespace cia402::axes::test {
namespace {

TEST(object_value, every_cia301_data_type_travels_as_text_or_an_integer_of_its_size_and_sign) {
  EXPECT_EQ(format_of(data_type::visible_string), value_format::text());
  EXPECT_EQ(format_of(data_type::boolean), value_format::integer(1, false));
  EXPECT_EQ(format_of(data_type::integer8), value_format::integer(1, true));
  EXPECT_EQ(format_of(data_type::unsigned16), value_format::integer(2, false));
  EXPECT_EQ(format_of(data_type::integer32), value_format::integer(4, true));
  EXPECT_EQ(format_of(data_type::unsigned64), value_format::integer(8, false));
}

TEST(object_value, command_line_text_is_read_as_its_type_says) {
  std::string why;
  EXPECT_EQ(parse_value("100", std::nullopt, why), object_value::of_integer(100));
  EXPECT_EQ(parse_value("-5", std::nullopt, why), object_value::of_integer(-5));
  EXPECT_EQ(parse_value("0x1F", std::nullopt, why), object_value::of_integer(31));
  EXPECT_EQ(parse_value("\"text\"", std::nullopt, why), object_value::of_text("text"));
  EXPECT_EQ(parse_value("hex:01a2ff", std::nullopt, why), object_value::of_bytes({0x01, 0xA2, 0xFF}));
  EXPECT_EQ(parse_value("label", value_format::text(), why), object_value::of_text("label")) << "a text object takes a word";
  EXPECT_EQ(parse_value("00ff", value_format::octets(), why), object_value::of_bytes({0x00, 0xFF}));
  EXPECT_FALSE(parse_value("label", std::nullopt, why)) << "a word of no known type";
  EXPECT_NE(why.find("not a number"), std::string::npos) << why;
  EXPECT_FALSE(parse_value("300", value_format::integer(1, true), why));
  EXPECT_NE(why.find("does not fit integer8"), std::string::npos) << why;
  EXPECT_FALSE(parse_value("-1", value_format::integer(2, false), why));
  EXPECT_FALSE(parse_value("hex:0", std::nullopt, why)) << "an odd number of digits";
  EXPECT_FALSE(parse_value("\"x\"", value_format::integer(4, false), why));
  EXPECT_EQ(parse_value("0xFFFFFFFFFFFFFFFF", value_format::integer(8, false), why), object_value::of_integer(-1))
      << "an UNSIGNED64 keeps its bits";
}

TEST(object_value, values_go_to_bytes_and_back_by_their_type) {
  std::vector<std::uint8_t> bytes;
  std::string why;
  ASSERT_TRUE(encode_value(object_value::of_integer(-300), value_format::integer(4, true), bytes, why));
  EXPECT_EQ(bytes, (std::vector<std::uint8_t>{0xD4, 0xFE, 0xFF, 0xFF}));
  EXPECT_EQ(decode_value(bytes, value_format::integer(4, true)), object_value::of_integer(-300));
  EXPECT_EQ(decode_value(bytes, value_format::integer(4, false)), object_value::of_integer(0xFFFFFED4));
  EXPECT_EQ(decode_value(bytes, std::nullopt), object_value::of_bytes(bytes)) << "no type: the bytes";
  EXPECT_EQ(decode_value(bytes, value_format::integer(2, false)), object_value::of_bytes(bytes)) << "not its size";
  std::vector<std::uint8_t> none;
  EXPECT_FALSE(encode_value(object_value::of_integer(70000), value_format::integer(2, false), none, why));
  EXPECT_TRUE(none.empty()) << "nothing written on failure";
  const std::vector<std::uint8_t> name{'a', 'b', 0};
  EXPECT_EQ(decode_value(name, value_format::text()), object_value::of_text("ab")) << "padding dropped";
}

TEST(object_value, json_and_words_show_numbers_texts_and_bytes) {
  EXPECT_EQ(value_json(object_value::of_integer(100), value_format::integer(2, false)), "100");
  EXPECT_EQ(value_json(object_value::of_integer(-1), value_format::integer(8, false)), "18446744073709551615");
  EXPECT_EQ(value_json(object_value::of_text("a\"b"), value_format::text()), "\"a\\\"b\"");
  EXPECT_EQ(value_json(object_value::of_bytes({0x01, 0xA2}), std::nullopt), "\"01a2\"");
  EXPECT_EQ(value_text(object_value::of_integer(4688), value_format::integer(2, false)), "4688 (0x1250)");
  EXPECT_EQ(value_text(object_value::of_integer(-300), value_format::integer(4, true)), "-300 (0xFFFFFED4)");
  EXPECT_EQ(value_text(object_value::of_bytes({0x01}), std::nullopt), "hex:01 (1 byte)");
  EXPECT_EQ(smallest_size(0), 1u);
  EXPECT_EQ(smallest_size(255), 1u);
  EXPECT_EQ(smallest_size(256), 2u);
  EXPECT_EQ(smallest_size(-129), 2u);
  EXPECT_EQ(smallest_size(70000), 4u);
  EXPECT_EQ(smallest_size(std::int64_t{1} << 40), 8u);
}

TEST(session_objects, a_cia402_object_is_read_and_written_with_its_type) {
  bench b({}, standard_profile(), false);
  const result w = b.finish([&](completion d) { return b.s->write_object(0x6081, 0, object_value::of_integer(1234), std::move(d)); });
  ASSERT_TRUE(w.ok()) << w.error;
  ASSERT_FALSE(b.link.downloads.empty());
  EXPECT_EQ(b.link.downloads.back().bytes.size(), 4u) << "UNSIGNED32 as the table says";
  const result r = b.finish([&](completion d) { return b.s->read_object(0x6081, 0, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.value, object_value::of_integer(1234));
  EXPECT_EQ(r.format, value_format::integer(4, false));
  const result refused = b.finish([&](completion d) { return b.s->write_object(0x6060, 0, object_value::of_integer(300), std::move(d)); });
  EXPECT_TRUE(refused.bad_input);
  EXPECT_NE(refused.error.find("300 is refused by the object table: value of parameter written too high (-128..127"),
            std::string::npos)
      << refused.error;
  EXPECT_EQ(refused.abort, sdo_abort::value_too_high) << "the table's refusal carries its abort code";
}

TEST(session_objects, a_read_or_write_the_drive_refuses_carries_its_abort_code_and_other_failures_none) {
  bench b({}, standard_profile(), false);
  b.link.refused[{0x2005, 0}] = sdo_abort::object_does_not_exist;
  const result r = b.finish([&](completion d) { return b.s->read_object(0x2005, 0, std::move(d)); });
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.abort, sdo_abort::object_does_not_exist);
  const result w = b.finish([&](completion d) { return b.s->write_object(0x2005, 0, object_value::of_integer(1), std::move(d)); });
  EXPECT_FALSE(w.ok());
  EXPECT_EQ(w.abort, sdo_abort::object_does_not_exist);
  const result ok = b.finish([&](completion d) { return b.s->read_object(0x6081, 0, std::move(d)); });
  ASSERT_TRUE(ok.ok()) << ok.error;
  EXPECT_EQ(ok.abort, sdo_abort::none);
}

TEST(session_objects, a_cyclic_output_is_written_there_not_by_a_transfer) {
  bench b;
  b.run_ms(10);
  const result w = b.finish([&](completion d) { return b.s->write_object(0x60FF, 0, object_value::of_integer(250), std::move(d)); });
  ASSERT_TRUE(w.ok()) << w.error;
  EXPECT_EQ(w.note, "written into the cyclic outputs");
  b.run_ms(5);
  EXPECT_EQ(b.link.drive.view().target_velocity(), 250);
  for (const auto& d : b.link.downloads) EXPECT_NE(d.index, 0x60FF);
}

TEST(session_objects, a_described_object_is_read_as_its_type_says) {
  bench b;
  b.link.own[{0x1008, 0}] = {'c', 'i', 'a'};
  b.link.described[{0x1008, 0}] = value_format::text();
  const result r = b.finish([&](completion d) { return b.s->read_object(0x1008, 0, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.value, object_value::of_text("cia"));
  EXPECT_EQ(value_json(*r.value, r.format), "\"cia\"");
  b.link.own[{0x1017, 0}] = {0, 0};
  b.link.own_size[{0x1017, 0}] = 2;
  b.link.described[{0x1017, 0}] = value_format::integer(2, false);
  const result w = b.finish([&](completion d) { return b.s->write_object(0x1017, 0, object_value::of_integer(100), std::move(d)); });
  ASSERT_TRUE(w.ok()) << w.error;
  EXPECT_EQ(b.link.downloads.back().bytes, (std::vector<std::uint8_t>{100, 0})) << "two bytes, as described";
}

TEST(session_objects, a_number_of_unknown_type_goes_as_the_smallest_size_the_drive_takes) {
  bench b;
  b.link.own[{0x2001, 0}] = {0, 0};
  b.link.own_size[{0x2001, 0}] = 2;
  const result zero = b.finish([&](completion d) { return b.s->write_object(0x2001, 0, object_value::of_integer(0), std::move(d)); });
  ASSERT_TRUE(zero.ok()) << zero.error;
  EXPECT_EQ(zero.size, 2u) << "1 byte refused as too short (0x06070013), then 2";
  EXPECT_FALSE(zero.format);
  const result big = b.finish([&](completion d) { return b.s->write_object(0x2001, 0, object_value::of_integer(70000), std::move(d)); });
  EXPECT_TRUE(failed_naming(big, {"the object is shorter: 70000 does not fit it"}));
  const result read = b.finish([&](completion d) { return b.s->read_object(0x2001, 0, std::move(d)); });
  ASSERT_TRUE(read.ok());
  EXPECT_EQ(read.value, object_value::of_bytes({0, 0})) << "no type known: the bytes";
}

}  // namespace
}  // namespace cia402::axes::test
