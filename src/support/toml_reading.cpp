#include "cia402/support/toml_reading.hpp"

#include <algorithm>
#include <utility>

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

}  // namespace cia402::toml_reading
