// Values as a person reads them: named and typed by the node's description or the CiA 402 table.
#include <cstdio>

#include "cia402/error_codes.hpp"
#include "cia402/master.hpp"
#include "cia402/objects.hpp"
#include "node_state.hpp"

namespace cia402::canopen::monitor {
namespace {

struct object_info {
  std::string name;
  bool typed = false;
  data_type type = data_type::unsigned8;
  std::string unit;
};

object_info info_of(const object_table* table, std::uint16_t index, std::uint8_t sub) {
  object_info info;
  const object_description* d = find_drive_object(index, sub);
  if (d != nullptr) {
    info.name = d->name;
    info.typed = true;
    info.type = d->type;
    info.unit = d->unit;
  }
  if (table == nullptr) return info;
  for (const dictionary::object_entry& o : *table) {
    if (o.index != index) continue;
    for (const dictionary::sub_entry& e : o.subs) {
      if (e.sub != sub) continue;
      info.name = o.code == dictionary::object_code::var || e.name.empty() ? o.name : o.name + ": " + e.name;
      info.typed = true;
      info.type = e.type;
    }
  }
  return info;
}

bool printable(std::span<const std::uint8_t> bytes) {
  for (std::uint8_t b : bytes) {
    if (b < 0x20 || b > 0x7E) return false;
  }
  return true;
}

std::string quoted(std::span<const std::uint8_t> bytes) {
  std::string out = "\"";
  for (std::uint8_t b : bytes) {
    if (b == '"' || b == '\\') {
      out += '\\';
      out += static_cast<char>(b);
    } else if (b >= 0x20 && b <= 0x7E) {
      out += static_cast<char>(b);
    } else {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\x%02X", b);
      out += esc;
    }
  }
  return out + "\"";
}

// What a few values say, where the drive profile defines it.
std::string meaning_of(std::uint16_t index, std::uint8_t sub, std::int64_t v) {
  if (sub != 0) return "";
  if (index == object_index::status_word) {
    state s{};
    return decode_status(standard_profile(), static_cast<std::uint16_t>(v), s) ? state_name(s) : "";
  }
  if (index == object_index::modes_of_operation || index == object_index::modes_of_operation_display) {
    return mode::short_name(v);
  }
  if (index == object_index::error_code && v != 0) return error_code_text(static_cast<std::uint16_t>(v));
  return "";
}

}  // namespace

std::string hex(std::uint64_t value, int digits) { return to_hex(value, digits).c_str(); }

std::string object_ref(std::uint16_t index, std::uint8_t sub) {
  return hex(index, 4) + ":" + std::to_string(sub);
}

std::string hex_bytes(std::span<const std::uint8_t> bytes) {
  std::string out;
  char b[4];
  for (std::uint8_t x : bytes) {
    std::snprintf(b, sizeof b, out.empty() ? "%02X" : " %02X", x);
    out += b;
  }
  return out;
}

std::string object_name(const object_table* table, std::uint16_t index, std::uint8_t sub) {
  return info_of(table, index, sub).name;
}

object_value read_value(const object_table* table, std::uint16_t index, std::uint8_t sub,
                        std::span<const std::uint8_t> bytes) {
  const object_info info = info_of(table, index, sub);
  object_value v;
  v.index = index;
  v.sub = sub;
  v.name = info.name;
  v.unit = info.unit;
  const bool text_type = info.typed && info.type == data_type::visible_string;
  const unsigned type_bytes = info.typed ? type_size(info.type) : 0;
  if (text_type || (!info.typed && bytes.size() > 8)) {
    v.shown = text_type || printable(bytes) ? quoted(bytes) : hex_bytes(bytes);
    return v;
  }
  if (bytes.empty()) {
    v.shown = "(no data)";
    return v;
  }
  // A number: as many bytes as its type has (fewer if fewer came), little-endian.
  const std::size_t n = type_bytes != 0 && type_bytes < bytes.size() ? type_bytes
                        : bytes.size() > 8                          ? 8
                                                                    : bytes.size();
  const std::uint64_t raw = get_le(bytes.data(), static_cast<unsigned>(n));
  v.is_number = true;
  v.is_signed = info.typed && type_is_signed(info.type);
  if (v.is_signed && n < 8) {
    const std::uint64_t sign = 1ull << (8 * n - 1);
    v.number = static_cast<std::int64_t>((raw ^ sign) - sign);
  } else {
    v.number = static_cast<std::int64_t>(raw);
  }
  v.shown = v.is_signed ? std::to_string(v.number) : hex(raw, static_cast<int>(2 * (type_bytes != 0 ? type_bytes : n)));
  v.meaning = meaning_of(index, sub, v.number);
  return v;
}

std::string describe(const object_value& v) {
  std::string out = object_ref(v.index, v.sub) + " = " + v.shown;
  if (!v.unit.empty()) out += " " + v.unit;
  if (!v.name.empty() || !v.meaning.empty()) {
    out += " (" + v.name + (v.name.empty() || v.meaning.empty() ? "" : ": ") + v.meaning + ")";
  }
  return out;
}

}  // namespace cia402::canopen::monitor
