// The readers the scenario loader's parts share: keys, object indices, times and velocities.
#include <cmath>
#include <string>

#include "cia402/support/text.hpp"
#include "cia402/support/toml_reading.hpp"
#include "scenario_reading.hpp"

namespace cia402::sim::scenario_reading {

using toml_reading::get_string;
using toml_reading::refuse;
using toml_reading::refuse_type;

// A key of the top level written under a [table] is the usual slip: say so.
void check_keys(const toml::table& t, std::initializer_list<std::string_view> allowed,
                std::string_view where) {
  toml_reading::check_keys(t, allowed, where, [where](std::string_view key) {
    for (std::string_view root_key : {"events", "expect", "objects", "duration", "cycle"}) {
      if (key == root_key && where != "the scenario") {
        return "; a [table] lasts until the next one, so write '" + std::string(root_key) +
               "' before the first [table] header";
      }
    }
    return std::string();
  });
}


// A decimal or 0x-hexadecimal integer written as a key ("0x605A").
// "0x605A", or "0x607D:2" for a sub-index (a quoted key: TOML keys cannot hold the colon bare).
bool parse_index(std::string_view text, std::uint16_t& out, std::uint8_t& sub) {
  sub = 0;
  const std::size_t colon = text.find(':');
  if (colon != std::string_view::npos) {
    const std::optional<std::int64_t> s = support::parse_integer(text.substr(colon + 1), 0, 0xFF);
    if (!s) return false;
    sub = static_cast<std::uint8_t>(*s);
    text = text.substr(0, colon);
  }
  const std::optional<std::int64_t> v = support::parse_integer(text, 0, 0xFFFF);
  if (v) out = static_cast<std::uint16_t>(*v);
  return v.has_value();
}

// "10ms", "1.5s", "250us", "2 s": an exact number of microseconds.
std::uint64_t get_time_us(const toml::node& n, std::string_view what) {
  if (n.is_integer() || n.is_floating_point()) {
    refuse(n, std::string(what) + " must be a string with a unit, e.g. \"10ms\", \"1.5s\" or "
                                  "\"250us\"");
  }
  const std::string text(get_string(n, what));
  std::size_t i = 0;
  std::uint64_t whole = 0;
  std::uint64_t fraction = 0;
  std::uint64_t scale = 1;  // 10^(fraction digits)
  auto bad = [&]() {
    refuse(n, std::string(what) + " " + toml_reading::quoted(text) +
                  " is not a time: write a number and a unit (s, ms, us), e.g. \"1.5s\"");
  };
  const std::size_t digits_start = i;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
    whole = whole * 10 + static_cast<std::uint64_t>(text[i] - '0');
    if (whole > 1000000000ull) bad();
    ++i;
  }
  if (i == digits_start) bad();
  if (i < text.size() && text[i] == '.') {
    ++i;
    const std::size_t frac_start = i;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
      if (scale >= 1000000000000ull) bad();
      fraction = fraction * 10 + static_cast<std::uint64_t>(text[i] - '0');
      scale *= 10;
      ++i;
    }
    if (i == frac_start) bad();
  }
  while (i < text.size() && text[i] == ' ') ++i;
  const std::string unit = text.substr(i);
  std::uint64_t us_per_unit = 0;
  if (unit == "s") us_per_unit = 1000000;
  else if (unit == "ms") us_per_unit = 1000;
  else if (unit == "us") us_per_unit = 1;
  else bad();
  if ((fraction * us_per_unit) % scale != 0) {
    refuse(n, std::string(what) + " " + toml_reading::quoted(text) + " is finer than a microsecond");
  }
  return whole * us_per_unit + fraction * us_per_unit / scale;
}

// "2 s", "1.5 s", "1.5 ms", "250 us": a time as a person writes it.
std::string seconds_text(std::uint64_t us) {
  auto decimal = [](std::uint64_t value, std::uint64_t unit, int digits, const char* name) {
    std::string s = std::to_string(value / unit);
    const std::uint64_t rest = value % unit;
    if (rest != 0) {
      std::string frac = std::to_string(rest);
      frac.insert(0, static_cast<std::size_t>(digits) - frac.size(), '0');
      while (frac.back() == '0') frac.pop_back();
      s += "." + frac;
    }
    return s + " " + name;
  };
  if (us >= 1000000) return decimal(us, 1000000, 6, "s");
  if (us >= 1000) return decimal(us, 1000, 3, "ms");
  return std::to_string(us) + " us";
}

// A velocity in rpm (integer or float) as micro-rpm.
std::int64_t get_velocity(const toml::node& n, std::string_view what) {
  constexpr double limit = 2147483647.0;
  if (const auto* i = n.as_integer()) {
    const std::int64_t v = i->get();
    if (v < -2147483648LL || v > 2147483647LL) {
      refuse(n, std::string(what) + " " + std::to_string(v) + " rpm is outside the INT32 range");
    }
    return v * 1000000;
  }
  if (const auto* f = n.as_floating_point()) {
    const double v = f->get();
    if (!std::isfinite(v) || v < -limit || v > limit) {
      refuse(n, std::string(what) + " is outside the INT32 range of rpm");
    }
    return std::llround(v * 1e6);
  }
  refuse_type(n, what, "a number of rpm");
}

}  // namespace cia402::sim::scenario_reading
