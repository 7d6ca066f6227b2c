// An object's value as a master reads and writes it over any fieldbus: an integer, a text or bytes,
// and the format it travels in (CiA 301 §7.1.6: INTEGERn / UNSIGNEDn, VISIBLE_STRING, OCTET_STRING,
// DOMAIN). Where the format comes from is the session's business (the core's object table first,
// then the link's describe()); this file only converts: command-line text to a value, a value to the
// bytes of its format and back, and a value to JSON and to words.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cia402/objects.hpp"

namespace cia402::axes {

/// How a value travels.
struct value_format {
  enum class kind : std::uint8_t { integer, text, bytes };
  kind what = kind::bytes;
  std::uint8_t size = 0;   ///< integer: 1, 2, 4 or 8 bytes
  bool is_signed = false;  ///< integer: INTEGERn rather than UNSIGNEDn
  bool domain = false;     ///< bytes: DOMAIN rather than OCTET_STRING

  static value_format integer(unsigned bytes, bool is_signed) noexcept;
  static value_format text() noexcept;
  static value_format octets(bool domain = false) noexcept;
  /// CiA 301's name in lower case: "unsigned16", "integer32", "visible_string", "octet_string",
  /// "domain".
  std::string type_name() const;
  bool operator==(const value_format&) const = default;
};

/// The format a value of a CiA 301 data type travels in (BOOLEAN: one unsigned byte).
value_format format_of(data_type t) noexcept;

/// A value: which of the three it is, and that one.
struct object_value {
  value_format::kind what = value_format::kind::integer;
  std::int64_t number = 0;  ///< an UNSIGNED64 above INT64_MAX keeps its bits
  std::string text;
  std::vector<std::uint8_t> bytes;

  static object_value of_integer(std::int64_t v);
  static object_value of_text(std::string v);
  static object_value of_bytes(std::vector<std::uint8_t> v);
  bool operator==(const object_value&) const = default;
};

/// A command-line value: `100`, `-5`, `0x1F` (an integer), `"text"` (a text; the quotes are the
/// shell's to keep), `hex:01a2ff` (bytes). With a format known, a bare word is read as that format
/// says (a text object takes any word, a bytes object a run of hex digits too); without one, a word
/// that is neither a number, a quoted text nor hex: is refused. `why` says what is wrong.
std::optional<object_value> parse_value(std::string_view text, const std::optional<value_format>& format,
                                        std::string& why);

/// A decimal or 0x-hexadecimal integer of up to 64 bits (a minus sign for decimal); nothing else.
std::optional<std::int64_t> parse_integer(std::string_view text) noexcept;

/// The value as the bytes of `f` (little-endian integers), or false with `why` (a value outside the
/// type, a text for a number, ...). Nothing is written to `out` on failure.
bool encode_value(const object_value& v, const value_format& f, std::vector<std::uint8_t>& out, std::string& why);
/// Bytes as `f` reads them; without a format (or with bytes of another length than an integer
/// format's), the bytes themselves.
object_value decode_value(std::span<const std::uint8_t> bytes, const std::optional<value_format>& f);

/// The fewest bytes (1, 2, 4, 8) that hold `v`: what a master sends for a number of unknown type.
unsigned smallest_size(std::int64_t v) noexcept;

/// JSON: a number (unsigned above INT64_MAX when the format says unsigned), a string for a text, a
/// string of lower-case hex digits for bytes ("01a2ff").
std::string value_json(const object_value& v, const std::optional<value_format>& f);
/// Words: `100 (0x0064)`, `"text"`, `hex:01a2ff (3 bytes)`.
std::string value_text(const object_value& v, const std::optional<value_format>& f);

/// `s` as a JSON string literal, quotes included.
std::string json_string(std::string_view s);
/// Lower-case hex digits, two a byte.
std::string hex_digits(std::span<const std::uint8_t> bytes);

}  // namespace cia402::axes
