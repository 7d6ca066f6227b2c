// The [plant] table of a scenario: the plant's constants, each key checked for its type and range,
// then the whole set by check_plant_config().
#include <limits>
#include <optional>
#include <string>

#include "cia402/support/toml_reading.hpp"
#include "scenario_reading.hpp"

namespace cia402::sim::scenario_reading {
namespace {

using toml_reading::get_bool;
using toml_reading::get_int;
using toml_reading::refuse;

constexpr std::int64_t reach = std::int64_t{1} << 40;

// A place on the shaft (increments within +-2^40), or "none" for a switch that is not fitted.
std::optional<std::int64_t> get_place(const toml::node& n, std::string_view what) {
  if (n.is_string()) {
    if (toml_reading::get_string(n, what) != "none") {
      refuse(n, std::string(what) + " takes a position in increments or \"none\"");
    }
    return std::nullopt;
  }
  return get_int(n, what, -reach, reach);
}

// home_switch: a position (active from there to the positive end of travel, as the plant's
// default), { from = A, to = B } (either may be left out: to the end of travel that way), or "none".
void load_home_switch(const toml::node& n, plant_config& c) {
  if (const toml::table* range = n.as_table()) {
    check_keys(*range, {"from", "to"}, "home_switch");
    const toml::node* from = range->get("from");
    const toml::node* to = range->get("to");
    if (!from && !to) refuse(n, "home_switch = { from = A, to = B } needs from, to or both");
    c.home_switch_position = from ? std::optional<std::int64_t>(get_int(*from, "from", -reach, reach)) : std::nullopt;
    c.home_switch_end = to ? std::optional<std::int64_t>(get_int(*to, "to", -reach, reach)) : std::nullopt;
    if (from && to && *c.home_switch_end < *c.home_switch_position) {
      refuse(*to, "the home switch must end at or above where it begins ('to' >= 'from')");
    }
    return;
  }
  const std::optional<std::int64_t> from = get_place(n, "home_switch");
  c.home_switch_fitted = from.has_value();
  c.home_switch_position = from;
  c.home_switch_end = std::nullopt;
}

}  // namespace

void load_plant(const toml::table& t, scenario& s) {
  check_keys(t,
             {"brake", "brake_engage_delay", "brake_release_delay", "brake_deceleration",
              "coast_deceleration", "standstill_window", "target_window",
              "current_limit_percent", "voltage_limit_percent", "voltage", "sto", "max_velocity",
              "max_acceleration", "torque_acceleration", "friction", "load", "home_switch", "index_position",
              "negative_limit_switch", "positive_limit_switch"},
             "[plant]");
  plant_config& c = s.plant;
  if (const auto* n = t.get("brake")) c.brake_fitted = get_bool(*n, "brake");
  auto delay = [&](const char* key, std::uint32_t& out) {
    if (const auto* n = t.get(key)) {
      const std::uint64_t us = get_time_us(*n, key);
      if (us > std::uint64_t{c.cycle_us} * 65535) {
        refuse(*n, std::string(key) + " is longer than 65535 cycles");
      }
      out = static_cast<std::uint32_t>(us);
    }
  };
  delay("brake_engage_delay", c.brake_engage_delay_us);
  delay("brake_release_delay", c.brake_release_delay_us);
  // A constant in rpm, rpm/s, percent or permille, within lo..hi.
  auto number = [&](const char* key, std::uint32_t& out, std::int64_t lo, std::int64_t hi) {
    if (const auto* n = t.get(key)) out = static_cast<std::uint32_t>(get_int(*n, key, lo, hi));
  };
  constexpr std::int64_t u32_max = std::numeric_limits<std::uint32_t>::max();
  number("brake_deceleration", c.brake_deceleration, 1, u32_max);
  number("coast_deceleration", c.coast_deceleration, 0, u32_max);
  number("standstill_window", c.standstill_window_rpm, 0, 1000000);
  number("target_window", c.target_window_rpm, 0, 65535);
  number("current_limit_percent", c.current_limit_percent, 1, 1000);
  number("voltage_limit_percent", c.voltage_limit_percent, 1, 1000);
  number("max_velocity", c.max_velocity_rpm, 1, 100000);
  number("max_acceleration", c.max_acceleration_rpm_s, 1, 100000000);
  number("torque_acceleration", c.torque_acceleration_rpm_s, 1, 100000000);
  number("friction", c.friction_permille, 0, 1000);
  if (const auto* n = t.get("load")) c.load_permille = static_cast<std::int32_t>(get_int(*n, "load", -1000, 1000));
  if (const auto* n = t.get("home_switch")) load_home_switch(*n, c);
  if (const auto* n = t.get("index_position")) c.index_position = get_int(*n, "index_position", -reach, reach);
  if (const auto* n = t.get("negative_limit_switch")) c.negative_limit_switch = get_place(*n, "negative_limit_switch");
  if (const auto* n = t.get("positive_limit_switch")) c.positive_limit_switch = get_place(*n, "positive_limit_switch");
  if (c.negative_limit_switch && c.positive_limit_switch && *c.positive_limit_switch < *c.negative_limit_switch) {
    const toml::node* blame = t.get("positive_limit_switch") ? t.get("positive_limit_switch") : t.get("negative_limit_switch");
    refuse(*blame, "the positive limit switch must lie at or above the negative one");
  }
  if (const auto* n = t.get("voltage")) s.dc_link_at_start = get_bool(*n, "voltage");
  if (const auto* n = t.get("sto")) s.sto_at_start = get_bool(*n, "sto");
  if (const char* why = check_plant_config(c)) refuse(t, std::string("[plant]: ") + why);
}

}  // namespace cia402::sim::scenario_reading
