// Text helpers the layers above the core share: one way to write a number in hexadecimal and one
// way to read an integer a person typed (decimal or 0x-hexadecimal), one way to put text into XML
// (the ESI file, the SVG plot), and one reading of UTF-8 (a TOML file, a drive's text on the page),
// so every file format, message and command line agrees.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cia402::support {

/// `prefix` and `digits` upper-case hexadecimal digits (more if the value needs them): hex(0x6041, 4)
/// is "0x6041", hex(0x6041, 4, "") "6041", hex(1, 4, "#x") "#x0001" (an ESI file's). The layers
/// that see only the core write the same "0x" text with cia402::to_hex (cia402/hex_text.hpp).
std::string hex(std::uint64_t value, int digits, std::string_view prefix = "0x");

/// How a leading 0 reads: as decimal (a person typing "010"), or as octal (CiA 306 §4.6.3, EDS files).
enum class leading_zero { decimal, octal };

/// A decimal or 0x-hexadecimal integer with an optional sign, the whole text and nothing else,
/// within [min, max]; nothing otherwise.
std::optional<std::int64_t> parse_integer(std::string_view text, std::int64_t min, std::int64_t max,
                                          leading_zero zero = leading_zero::decimal);

/// `text` with XML's five special characters written as entities, for element content and quoted
/// attribute values alike.
std::string xml_escaped(std::string_view text);

/// Length of the UTF-8 sequence that starts at text[i] (1..4), or 0 where none does: an overlong
/// form, a surrogate, a code point above U+10FFFF, a sequence cut short. `i` < text.size().
std::size_t utf8_length(std::string_view text, std::size_t i);
/// Whether all of `text` is well-formed UTF-8 (by utf8_length).
bool is_utf8(std::string_view text);

/// The words of `line`: runs of anything but spaces and tabs, in order, viewing `line`.
std::vector<std::string_view> split_words(std::string_view line);

/// "SOURCE:LINE:COLUMN: REASON" as compilers write it; `unnamed` stands for an empty source, a line
/// or column of 0 is left out. Every file format's error reads this way.
std::string located_message(const std::string& source, const char* unnamed, int line, int column,
                            const std::string& reason);

}  // namespace cia402::support
