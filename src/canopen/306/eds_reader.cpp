#include "cia402/canopen/306/eds_reader.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <optional>

#include "cia402/support/text.hpp"

namespace cia402::canopen {
namespace {

struct value_line {
  std::string text;
  std::size_t line = 0;
};

// One section: its keys (lower case) with their values and lines.
struct section {
  std::string written;  // the name as the file spells it
  std::size_t line = 0;
  std::map<std::string, value_line> keys;
};

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::optional<std::uint32_t> hex_number(std::string_view s, std::size_t max_digits) {
  if (s.empty() || s.size() > max_digits) return std::nullopt;
  std::uint32_t v = 0;
  for (char c : s) {
    const int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    if (d < 0) return std::nullopt;
    v = v * 16 + static_cast<std::uint32_t>(d);
  }
  return v;
}

// CiA 306 §4.6.3: decimal, 0x-hexadecimal, or octal with a leading 0; an optional sign.
std::optional<std::int64_t> integer(std::string_view s) {
  return support::parse_integer(trim(s), std::numeric_limits<std::int64_t>::min(),
                                std::numeric_limits<std::int64_t>::max(), support::leading_zero::octal);
}

bool known_type(std::int64_t t) {
  switch (t) {
    case 0x0001: case 0x0002: case 0x0003: case 0x0004: case 0x0005: case 0x0006: case 0x0007:
    case 0x0009: case 0x0015: case 0x001B: return true;
    default: return false;
  }
}

class reader {
 public:
  explicit reader(std::string_view text) : text_(text) {}

  std::variant<eds_contents, eds_error> run() {
    if (!split()) return error_;
    eds_contents out;
    // The node first: a "$NODEID+X" value must fit its type for the node the file names.
    const auto commissioning = sections_.find("devicecomissioning");
    if (commissioning != sections_.end()) {
      if (const value_line* v = find(commissioning->second, "NodeID")) {
        const auto id = integer(v->text);
        if (!id || *id < 1 || *id > 127) {
          return eds_error{v->line, "NodeID '" + v->text + "' is not 1..127"};
        }
        out.node_id = static_cast<std::uint8_t>(*id);
      }
    }
    node_id_ = out.node_id;
    std::map<std::uint32_t, const section*> entries;  // (index << 8 | sub) of each sub section
    for (const auto& [name, s] : sections_) {
      const auto index = name.size() > 7 && name.compare(4, 3, "sub") == 0 ? hex_number(name.substr(0, 4), 4) : std::nullopt;
      const auto sub = index ? hex_number(std::string_view(name).substr(7), 2) : std::nullopt;
      if (!sub) continue;
      if (sections_.count(name.substr(0, 4)) == 0) {
        return eds_error{s.line, "[" + s.written + "] has no object section [" + s.written.substr(0, 4) + "]"};
      }
      // "[60E3sub2]" and "[60E3sub02]" name one entry: a file that gives it twice is ambiguous.
      const auto [it, fresh] = entries.try_emplace(*index << 8 | *sub, &s);
      if (!fresh) {
        const section& a = it->second->line < s.line ? *it->second : s;
        const section& b = it->second->line < s.line ? s : *it->second;
        return eds_error{b.line, "[" + b.written + "] names the entry of [" + a.written + "] (line " +
                                     std::to_string(a.line) + ") again"};
      }
    }
    for (const auto& [name, s] : sections_) {
      if (name.size() != 4) continue;
      const auto index = hex_number(name, 4);
      if (!index) continue;
      dictionary::object_entry o;
      if (!object(static_cast<std::uint16_t>(*index), s, o)) return error_;
      if (!o.subs.empty()) out.objects.push_back(std::move(o));
    }
    std::sort(out.objects.begin(), out.objects.end(),
              [](const dictionary::object_entry& a, const dictionary::object_entry& b) { return a.index < b.index; });
    return out;
  }

 private:
  bool fail(std::size_t line, std::string reason) {
    error_ = eds_error{line, std::move(reason)};
    return false;
  }

  static const value_line* find(const section& s, const char* key) {
    const auto it = s.keys.find(lower(key));
    return it == s.keys.end() ? nullptr : &it->second;
  }

  bool split() {
    section* current = nullptr;
    std::size_t number = 0;
    std::size_t start = 0;
    while (start <= text_.size()) {
      const auto end = text_.find('\n', start);
      const std::string_view line = trim(text_.substr(start, end == std::string_view::npos ? end : end - start));
      ++number;
      start = end == std::string_view::npos ? text_.size() + 1 : end + 1;
      if (line.empty() || line[0] == ';') continue;
      if (line[0] == '[') {
        if (line.back() != ']' || line.size() < 3) return fail(number, "a section name needs [ and ]");
        const std::string name = lower(trim(line.substr(1, line.size() - 2)));
        auto [it, fresh] = sections_.try_emplace(name);
        if (!fresh) {
          return fail(number, "section [" + std::string(line.substr(1, line.size() - 2)) + "] appears twice (lines " +
                                  std::to_string(it->second.line) + " and " + std::to_string(number) + ")");
        }
        it->second.line = number;
        it->second.written = std::string(trim(line.substr(1, line.size() - 2)));
        current = &it->second;
        continue;
      }
      const auto eq = line.find('=');
      if (eq == std::string_view::npos || eq == 0) return fail(number, "expected [SECTION] or KEY=VALUE");
      if (current == nullptr) return fail(number, "KEY=VALUE before the first section");
      const std::string key = lower(trim(line.substr(0, eq)));
      if (!current->keys.try_emplace(key, value_line{std::string(trim(line.substr(eq + 1))), number}).second) {
        return fail(number, "key " + std::string(trim(line.substr(0, eq))) + " appears twice in its section");
      }
    }
    return true;
  }

  // A number key of a section: false (and error_) when present and not a number.
  bool number_key(const section& s, const char* key, std::optional<std::int64_t>& out) {
    out.reset();
    const value_line* v = find(s, key);
    if (v == nullptr || v->text.empty()) return true;
    out = integer(v->text);
    if (!out) return fail(v->line, std::string(key) + " '" + v->text + "' is not a number");
    return true;
  }

  // One sub-index from its section (the object's own for a VAR). `keep` is false for a data type
  // the dictionary cannot hold.
  bool entry(const section& s, std::uint8_t sub, dictionary::sub_entry& e, bool& keep) {
    e.sub = sub;
    if (const value_line* v = find(s, "ParameterName")) e.name = v->text;
    std::optional<std::int64_t> type;
    if (!number_key(s, "DataType", type)) return false;
    if (!type) return fail(s.line, "no DataType");
    keep = known_type(*type);
    if (!keep) return true;
    e.type = static_cast<data_type>(*type);
    if (const value_line* v = find(s, "AccessType")) {
      const std::string a = lower(v->text);
      if (a == "ro") e.acc = dictionary::access::ro;
      else if (a == "wo") e.acc = dictionary::access::wo;
      else if (a == "rw" || a == "rwr" || a == "rww") e.acc = dictionary::access::rw;
      else if (a == "const") e.acc = dictionary::access::constant;
      else return fail(v->line, "AccessType '" + v->text + "' is not ro, wo, rw, rwr, rww or const");
    }
    std::optional<std::int64_t> mapping;
    if (!number_key(s, "PDOMapping", mapping)) return false;
    e.pdo_mappable = mapping.value_or(0) != 0;
    std::optional<std::int64_t> low, high;
    if (!limit_key(s, "LowLimit", e.type, low) || !limit_key(s, "HighLimit", e.type, high)) return false;
    if (low || high) {
      e.has_limits = true;
      e.low = low.value_or(type_min(e.type));
      e.high = high.value_or(type_max(e.type));
    }
    // Both values are checked, the one taken and the one left: a file with a value its type cannot
    // hold is at fault, whichever a reader takes.
    const value_line* parameter = find(s, "ParameterValue");
    const value_line* standard = find(s, "DefaultValue");
    e.parameter_value = parameter != nullptr && !parameter->text.empty();
    if (e.parameter_value && standard != nullptr) {
      dictionary::sub_entry left = e;
      if (!default_value(*standard, left)) return false;
    }
    const value_line* value = e.parameter_value ? parameter : standard;
    if (value == nullptr) return true;
    return default_value(*value, e);
  }

  // LowLimit or HighLimit: a number its entry's type can hold (CiA 306 §4.6.3).
  bool limit_key(const section& s, const char* key, data_type type, std::optional<std::int64_t>& out) {
    if (!number_key(s, key, out)) return false;
    if (!out) return true;
    const value_line& v = *find(s, key);
    if (type == data_type::visible_string) return fail(v.line, std::string(key) + " '" + v.text + "': a VISIBLE_STRING has no limits");
    if (*out < type_min(type) || *out > type_max(type)) {
      return fail(v.line, std::string(key) + " '" + v.text + "' is outside its data type " + type_range(type));
    }
    return true;
  }

  static std::string type_range(data_type t) {
    return std::string(type_name(t)) + " (" + std::to_string(type_min(t)) + ".." + std::to_string(type_max(t)) + ")";
  }

  bool default_value(const value_line& v, dictionary::sub_entry& e) {
    if (e.type == data_type::visible_string) {
      e.default_text = v.text;
      e.capacity = v.text.size();
      return true;
    }
    std::string text = lower(v.text);
    constexpr std::string_view node = "$nodeid";
    if (const auto at = text.find(node); at != std::string::npos) {
      e.plus_node_id = true;
      text.erase(at, node.size());
      text = std::string(trim(text));
      if (!text.empty() && text.front() == '+') text.erase(0, 1);
      else if (!text.empty() && text.back() == '+') text.pop_back();
      else if (!text.empty()) return fail(v.line, "value '" + v.text + "' is not $NODEID+X or X+$NODEID");
    }
    std::int64_t n = 0;
    if (!text.empty()) {
      const auto parsed = integer(text);
      if (!parsed) return fail(v.line, "value '" + v.text + "' is not a number");
      n = *parsed;
    }
    if (n < type_min(e.type) || n > type_max(e.type)) {
      return fail(v.line, "value '" + v.text + "' is outside its data type " + type_range(e.type));
    }
    e.default_value = n;
    if (!e.plus_node_id) return true;
    // $NODEID+X: X + the node-ID must fit too, for the file's node, or for any node 1..127 when the
    // file names none. Checked, so no sum overflows (X may be INTEGER64's largest).
    if (node_id_ != 0 ? !value_for_node(e, node_id_) : !value_for_node(e, 1) || !value_for_node(e, 127)) {
      return fail(v.line, "value '" + v.text + "' is outside its data type " + type_range(e.type) +
                              (node_id_ != 0 ? " for node " + std::to_string(node_id_) : " for a node-ID of 1..127"));
    }
    return true;
  }

  bool object(std::uint16_t index, const section& s, dictionary::object_entry& o) {
    o.index = index;
    if (const value_line* v = find(s, "ParameterName")) o.name = v->text;
    std::optional<std::int64_t> code;
    if (!number_key(s, "ObjectType", code)) return false;
    const std::int64_t c = code.value_or(7);
    if (c != 7 && c != 8 && c != 9) return true;  // NULL, DOMAIN, DEFTYPE, DEFSTRUCT: no values
    o.code = static_cast<dictionary::object_code>(c);
    o.category = index >= 0x2000 && index <= 0x5FFF ? dictionary::object_category::manufacturer : dictionary::object_category::optional;
    if (c == 7) {
      dictionary::sub_entry e;
      bool keep = false;
      if (!entry(s, 0, e, keep)) return false;
      if (keep) o.subs.push_back(std::move(e));
      return true;
    }
    std::optional<std::int64_t> compact;
    if (!number_key(s, "CompactSubObj", compact)) return false;
    if (compact && *compact > 0) return compact_subs(s, *compact, o);
    const std::string prefix = lower(support::hex(index, 4, "")) + "sub";
    for (const auto& [name, sub_section] : sections_) {
      if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
      const auto sub = hex_number(std::string_view(name).substr(prefix.size()), 2);
      if (!sub) continue;
      dictionary::sub_entry e;
      bool keep = false;
      if (!entry(sub_section, static_cast<std::uint8_t>(*sub), e, keep)) return false;
      if (keep) o.subs.push_back(std::move(e));
    }
    std::sort(o.subs.begin(), o.subs.end(), [](const dictionary::sub_entry& a, const dictionary::sub_entry& b) { return a.sub < b.sub; });
    return true;
  }

  // CiA 306 compact storage: sub-index 0 holds the count, subs 1..N share the object's keys.
  bool compact_subs(const section& s, std::int64_t count, dictionary::object_entry& o) {
    if (count > 254) return fail(s.line, "CompactSubObj above 254");
    dictionary::sub_entry e;
    bool keep = false;
    if (!entry(s, 1, e, keep)) return false;
    dictionary::sub_entry highest;
    highest.sub = 0;
    highest.name = "Highest sub-index supported";
    highest.type = data_type::unsigned8;
    highest.default_value = count;
    o.subs.push_back(highest);
    if (!keep) return true;
    for (std::int64_t i = 1; i <= count; ++i) {
      dictionary::sub_entry sub = e;
      sub.sub = static_cast<std::uint8_t>(i);
      // Trimmed as the file's own names are, so the name a DCF writes of it reads back.
      sub.name = o.name.empty() ? std::to_string(i) : o.name + " " + std::to_string(i);
      o.subs.push_back(std::move(sub));
    }
    return true;
  }

  std::string_view text_;
  std::uint8_t node_id_ = 0;  // [DeviceComissioning] NodeID, 0: none
  std::map<std::string, section> sections_;
  eds_error error_;
};

}  // namespace

std::variant<eds_contents, eds_error> read_eds(std::string_view text) { return reader(text).run(); }

std::optional<std::int64_t> value_for_node(const dictionary::sub_entry& e, int node_id) {
  std::int64_t v = e.default_value;
  if (e.plus_node_id && __builtin_add_overflow(v, std::int64_t{node_id}, &v)) return std::nullopt;
  if (v < type_min(e.type) || v > type_max(e.type)) return std::nullopt;
  return v;
}

}  // namespace cia402::canopen
