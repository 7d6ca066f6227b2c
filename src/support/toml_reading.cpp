#include "cia402/support/toml_reading.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <utility>

#include "cia402/support/text.hpp"

namespace cia402::toml_reading {

void refuse(const toml::source_region& at, std::string reason) {
  throw refusal{static_cast<int>(at.begin.line), static_cast<int>(at.begin.column),
                std::move(reason)};
}
void refuse(const toml::node& at, std::string reason) { refuse(at.source(), std::move(reason)); }
void refuse(const toml::key& at, std::string reason) { refuse(at.source(), std::move(reason)); }

std::string quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

const char* type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    case toml::node_type::none: break;
  }
  return "nothing";
}

void refuse_type(const toml::node& n, std::string_view what, std::string_view expected) {
  refuse(n, std::string(what) + " must be " + std::string(expected) + ", not " + type_name(n));
}

void check_keys(const toml::table& t, std::initializer_list<std::string_view> allowed,
                std::string_view where,
                const std::function<std::string(std::string_view key)>& hint) {
  for (auto&& [key, value] : t) {
    (void)value;
    if (std::find(allowed.begin(), allowed.end(), key.str()) == allowed.end()) {
      std::string list;
      for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      refuse(key, "unknown key " + quoted(key.str()) + " in " + std::string(where) +
                      " (allowed: " + list + ")" + (hint ? hint(key.str()) : std::string()));
    }
  }
}

const toml::node& require(const toml::table& t, std::string_view key, std::string_view where) {
  const toml::node* n = t.get(key);
  if (n == nullptr) refuse(t, std::string(where) + " lacks the key " + quoted(key));
  return *n;
}

std::int64_t get_int(const toml::node& n, std::string_view what, std::int64_t lo, std::int64_t hi) {
  const auto* v = n.as_integer();
  if (v == nullptr) refuse_type(n, what, "an integer");
  const std::int64_t x = v->get();
  if (x < lo || x > hi) {
    refuse(n, std::string(what) + " " + std::to_string(x) + " is outside " + std::to_string(lo) +
                  ".." + std::to_string(hi));
  }
  return x;
}

std::string_view get_string(const toml::node& n, std::string_view what) {
  const auto* v = n.as_string();
  if (v == nullptr) refuse_type(n, what, "a string");
  return v->get();
}

bool get_bool(const toml::node& n, std::string_view what) {
  const auto* v = n.as_boolean();
  if (v == nullptr) refuse_type(n, what, "true or false");
  return v->get();
}

const toml::array& get_array(const toml::node& n, std::string_view what) {
  const auto* v = n.as_array();
  if (v == nullptr) refuse_type(n, what, "an array");
  return *v;
}

const toml::table& get_table(const toml::node& n, std::string_view what) {
  const auto* v = n.as_table();
  if (v == nullptr) refuse_type(n, what, "a table");
  return *v;
}

std::optional<refusal> check_toml_text(std::string_view text) {
  if (text.size() > max_file_bytes) {
    return refusal{0, 0, "larger than " + std::to_string(max_file_bytes) + " bytes"};
  }
  enum class in { code, comment, basic, literal, multi_basic, multi_literal };
  in where = in::code;
  int line = 1;
  int column = 1;
  const auto at = [&](std::size_t i, std::string_view s) { return text.substr(i, s.size()) == s; };
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\0') return refusal{line, column, "a NUL byte"};
    const std::size_t n = support::utf8_length(text, i);
    if (n == 0) return refusal{line, column, "not UTF-8 text"};
    if (n > 1 && where == in::code) {
      return refusal{line, column, "a non-ASCII character outside a string or comment"};
    }
    std::size_t step = n;
    bool escaped = false;  // a backslash and the character after it
    switch (where) {
      case in::code:
        if (c == '#') {
          where = in::comment;
        } else if (at(i, "\"\"\"")) {
          where = in::multi_basic;
          step = 3;
        } else if (at(i, "'''")) {
          where = in::multi_literal;
          step = 3;
        } else if (c == '"') {
          where = in::basic;
        } else if (c == '\'') {
          where = in::literal;
        }
        break;
      case in::comment:
        if (c == '\n') where = in::code;
        break;
      case in::basic:
        if (c == '\\' && i + 1 < text.size() && text[i + 1] != '\n') {
          escaped = true;
        } else if (c == '"' || c == '\n') {
          where = in::code;
        }
        break;
      case in::literal:
        if (c == '\'' || c == '\n') where = in::code;
        break;
      case in::multi_basic:
        if (c == '\\' && i + 1 < text.size() && text[i + 1] != '\n') {
          escaped = true;
        } else if (at(i, "\"\"\"")) {
          where = in::code;
          step = 3;
        }
        break;
      case in::multi_literal:
        if (at(i, "'''")) {
          where = in::code;
          step = 3;
        }
        break;
    }
    if (escaped) {
      // The escaped character may be a multi-byte one: take it whole.
      const std::size_t m = support::utf8_length(text, i + 1);
      if (m == 0) return refusal{line, column + 1, "not UTF-8 text"};
      step = 1 + m;
    }
    for (std::size_t k = i; k < i + step && k < text.size(); ++k) {
      if (text[k] == '\n') {
        ++line;
        column = 1;
      } else if ((static_cast<unsigned char>(text[k]) & 0xC0) != 0x80) {
        ++column;
      }
    }
    i += step;
  }
  return std::nullopt;
}

std::optional<std::string> read_small_file(const std::string& path, std::string& why) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) {
    why = "cannot open the file";
    return std::nullopt;
  }
  if (!std::filesystem::is_regular_file(st)) {
    why = "not a regular file";
    return std::nullopt;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    why = "cannot open the file";
    return std::nullopt;
  }
  // Read at most one byte more than allowed: a file too large is refused without reading it all.
  std::string text(max_file_bytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) {
    why = "cannot read the file";
    return std::nullopt;
  }
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > max_file_bytes) {
    why = "larger than " + std::to_string(max_file_bytes) + " bytes";
    return std::nullopt;
  }
  return text;
}

std::optional<refusal> parse_and_load(std::string_view text, std::string_view source_name,
                                      const std::function<void(const toml::table& root)>& load) {
  if (auto bad = check_toml_text(text)) return bad;
  try {
    load(toml::parse(text, source_name));
    return std::nullopt;
  } catch (const toml::parse_error& e) {
    return refusal{static_cast<int>(e.source().begin.line), static_cast<int>(e.source().begin.column),
                   std::string(e.description())};
  } catch (const refusal& r) {
    return r;
  }
}

}  // namespace cia402::toml_reading
