#include "cia402/axis/object_value.hpp"

#include <charconv>
#include <limits>

#include "cia402/hex_text.hpp"

namespace cia402::axes {
namespace {

constexpr char hex_chars[] = "0123456789abcdef";

int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::optional<std::vector<std::uint8_t>> parse_hex_bytes(std::string_view digits) {
  if (digits.size() % 2 != 0) return std::nullopt;
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < digits.size(); i += 2) {
    const int hi = hex_value(digits[i]);
    const int lo = hex_value(digits[i + 1]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out.push_back(static_cast<std::uint8_t>(hi * 16 + lo));
  }
  return out;
}

// The range of an integer format, as [low, high] over int64 (an UNSIGNED64 above INT64_MAX is
// written as its bits, so its high end is -1 read as unsigned: checked apart).
bool fits(std::int64_t v, const value_format& f) noexcept {
  const unsigned bits = 8u * f.size;
  if (f.is_signed) {
    if (bits >= 64) return true;
    const std::int64_t high = (std::int64_t{1} << (bits - 1)) - 1;
    return v >= -high - 1 && v <= high;
  }
  if (bits >= 64) return true;  // any bits: a negative number is not a valid input (parse refuses it)
  return v >= 0 && v <= static_cast<std::int64_t>((std::uint64_t{1} << bits) - 1);
}

}  // namespace

value_format value_format::integer(unsigned bytes, bool is_signed) noexcept {
  value_format f;
  f.what = kind::integer;
  f.size = static_cast<std::uint8_t>(bytes);
  f.is_signed = is_signed;
  return f;
}

value_format value_format::text() noexcept {
  value_format f;
  f.what = kind::text;
  return f;
}

value_format value_format::octets(bool domain) noexcept {
  value_format f;
  f.what = kind::bytes;
  f.domain = domain;
  return f;
}

std::string value_format::type_name() const {
  switch (what) {
    case kind::integer: return std::string(is_signed ? "integer" : "unsigned") + std::to_string(8u * size);
    case kind::text: return "visible_string";
    case kind::bytes: return domain ? "domain" : "octet_string";
  }
  return "unknown";
}

value_format format_of(data_type t) noexcept {
  if (t == data_type::visible_string) return value_format::text();
  return value_format::integer(type_size(t), type_is_signed(t));
}

object_value object_value::of_integer(std::int64_t v) {
  object_value o;
  o.what = value_format::kind::integer;
  o.number = v;
  return o;
}

object_value object_value::of_text(std::string v) {
  object_value o;
  o.what = value_format::kind::text;
  o.text = std::move(v);
  return o;
}

object_value object_value::of_bytes(std::vector<std::uint8_t> v) {
  object_value o;
  o.what = value_format::kind::bytes;
  o.bytes = std::move(v);
  return o;
}

std::optional<std::int64_t> parse_integer(std::string_view text) noexcept {
  if (text.empty()) return std::nullopt;
  const bool negative = text.front() == '-';
  std::string_view digits = negative ? text.substr(1) : text;
  int base = 10;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    if (negative) return std::nullopt;  // -0x.. is not a value anyone means
    base = 16;
    digits = digits.substr(2);
  }
  if (digits.empty()) return std::nullopt;
  std::uint64_t magnitude = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), magnitude, base);
  if (ec != std::errc() || end != digits.data() + digits.size()) return std::nullopt;
  if (negative) {
    if (magnitude > std::uint64_t{1} << 63) return std::nullopt;
    return static_cast<std::int64_t>(~magnitude + 1);
  }
  // Decimal stays within INT64; hex may give all 64 bits (an UNSIGNED64).
  if (base == 10 && magnitude > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    return std::nullopt;
  }
  return static_cast<std::int64_t>(magnitude);
}

std::optional<object_value> parse_value(std::string_view text, const std::optional<value_format>& format,
                                        std::string& why) {
  using kind = value_format::kind;
  if (text.size() >= 2 && text.front() == '"' && text.back() == '"') {
    if (format && format->what != kind::text) {
      why = "a text for an object of type " + format->type_name();
      return std::nullopt;
    }
    return object_value::of_text(std::string(text.substr(1, text.size() - 2)));
  }
  if (text.substr(0, 4) == "hex:") {
    const auto bytes = parse_hex_bytes(text.substr(4));
    if (!bytes) {
      why = "hex: takes pairs of hex digits, e.g. hex:01a2ff";
      return std::nullopt;
    }
    if (format && format->what == kind::integer) {
      why = "bytes for an object of type " + format->type_name() + " (write the number)";
      return std::nullopt;
    }
    return object_value::of_bytes(*bytes);
  }
  if (format && format->what == kind::text) return object_value::of_text(std::string(text));
  if (format && format->what == kind::bytes) {
    if (const auto bytes = parse_hex_bytes(text)) return object_value::of_bytes(*bytes);
    why = "'" + std::string(text) + "' is not bytes for a " + format->type_name() + " (hex digits, e.g. 01a2ff)";
    return std::nullopt;
  }
  const auto number = parse_integer(text);
  if (!number) {
    why = "'" + std::string(text) + "' is not a number (decimal or 0x hex), a \"text\" or hex:BYTES";
    return std::nullopt;
  }
  if (format && !fits(*number, *format) && !(format->size == 8 && !format->is_signed && text.substr(0, 2) == "0x")) {
    why = std::string(text) + " does not fit " + format->type_name();
    return std::nullopt;
  }
  return object_value::of_integer(*number);
}

bool encode_value(const object_value& v, const value_format& f, std::vector<std::uint8_t>& out, std::string& why) {
  using kind = value_format::kind;
  if (f.what == kind::integer) {
    if (v.what != kind::integer) {
      why = "not a number, and the object is " + f.type_name();
      return false;
    }
    if (f.size == 0 || f.size > 8 || !fits(v.number, f)) {
      why = std::to_string(v.number) + " does not fit " + f.type_name();
      return false;
    }
    for (unsigned i = 0; i < f.size; ++i) out.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(v.number) >> (8 * i)));
    return true;
  }
  if (v.what == kind::integer) {
    why = "a number, and the object is " + f.type_name();
    return false;
  }
  if (v.what == kind::text) {
    out.insert(out.end(), v.text.begin(), v.text.end());
  } else {
    out.insert(out.end(), v.bytes.begin(), v.bytes.end());
  }
  return true;
}

object_value decode_value(std::span<const std::uint8_t> bytes, const std::optional<value_format>& f) {
  using kind = value_format::kind;
  if (f && f->what == kind::integer && bytes.size() == f->size) {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < bytes.size(); ++i) v |= static_cast<std::uint64_t>(bytes[i]) << (8 * i);
    if (f->is_signed && f->size < 8 && (bytes.back() & 0x80)) v |= ~std::uint64_t{0} << (8 * f->size);
    return object_value::of_integer(static_cast<std::int64_t>(v));
  }
  if (f && f->what == kind::text) {
    std::string s(bytes.begin(), bytes.end());
    while (!s.empty() && s.back() == '\0') s.pop_back();  // a fixed-size field's padding
    return object_value::of_text(std::move(s));
  }
  return object_value::of_bytes(std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
}

unsigned smallest_size(std::int64_t v) noexcept {
  for (unsigned bytes : {1u, 2u, 4u}) {
    const std::int64_t span = std::int64_t{1} << (8 * bytes);
    // Unsigned for a positive value (0..255 is one byte), two's complement for a negative one.
    if (v >= 0 ? v < span : v >= -(span / 2)) return bytes;
  }
  return 8;
}

std::string hex_digits(std::span<const std::uint8_t> bytes) {
  std::string s;
  for (std::uint8_t b : bytes) {
    s += hex_chars[b >> 4];
    s += hex_chars[b & 0xF];
  }
  return s;
}

std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += "\\u00";
          out += hex_chars[(c >> 4) & 0xF];
          out += hex_chars[c & 0xF];
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string value_json(const object_value& v, const std::optional<value_format>& f) {
  using kind = value_format::kind;
  switch (v.what) {
    case kind::integer:
      if (f && !f->is_signed && v.number < 0) return std::to_string(static_cast<std::uint64_t>(v.number));
      return std::to_string(v.number);
    case kind::text: return json_string(v.text);
    case kind::bytes: return json_string(hex_digits(v.bytes));
  }
  return "null";
}

std::string value_text(const object_value& v, const std::optional<value_format>& f) {
  using kind = value_format::kind;
  switch (v.what) {
    case kind::integer: {
      const unsigned size = f && f->what == kind::integer ? f->size : smallest_size(v.number);
      const std::uint64_t bits = size >= 8 ? static_cast<std::uint64_t>(v.number)
                                           : static_cast<std::uint64_t>(v.number) & ((std::uint64_t{1} << (8 * size)) - 1);
      return value_json(v, f) + " (" + to_hex(bits, static_cast<int>(2 * size)).c_str() + ")";
    }
    case kind::text: return json_string(v.text);
    case kind::bytes:
      return "hex:" + hex_digits(v.bytes) + " (" + std::to_string(v.bytes.size()) +
             (v.bytes.size() == 1 ? " byte" : " bytes") + ")";
  }
  return "";
}

}  // namespace cia402::axes
