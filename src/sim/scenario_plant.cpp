// The [plant] table of a scenario: the plant's constants, each key checked for its type and range,
// then the whole set by check_plant_config().
#include <limits>
#include <string>

#include "cia402/support/toml_reading.hpp"
#include "scenario_reading.hpp"

namespace cia402::sim::scenario_reading {
namespace {

using toml_reading::get_bool;
using toml_reading::get_int;
using toml_reading::refuse;

std::uint32_t get_u32(const toml::node& n, std::string_view what, std::int64_t lo = 0) {
  return static_cast<std::uint32_t>(get_int(n, what, lo, std::numeric_limits<std::uint32_t>::max()));
}

}  // namespace

void load_plant(const toml::table& t, scenario& s) {
  check_keys(t,
             {"brake", "brake_engage_delay", "brake_release_delay", "brake_deceleration",
              "coast_deceleration", "standstill_window", "target_window",
              "current_limit_percent", "voltage_limit_percent", "voltage", "sto", "max_velocity",
              "max_acceleration", "torque_acceleration", "friction", "load", "home_switch", "index_position"},
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
  if (const auto* n = t.get("brake_deceleration")) {
    c.brake_deceleration = get_u32(*n, "brake_deceleration", 1);
  }
  if (const auto* n = t.get("coast_deceleration")) {
    c.coast_deceleration = get_u32(*n, "coast_deceleration");
  }
  if (const auto* n = t.get("standstill_window")) {
    c.standstill_window_rpm =
        static_cast<std::uint32_t>(get_int(*n, "standstill_window", 0, 1000000));
  }
  if (const auto* n = t.get("target_window")) {
    c.target_window_rpm = static_cast<std::uint32_t>(get_int(*n, "target_window", 0, 1000000));
  }
  if (const auto* n = t.get("current_limit_percent")) {
    c.current_limit_percent =
        static_cast<std::uint32_t>(get_int(*n, "current_limit_percent", 1, 1000));
  }
  if (const auto* n = t.get("voltage_limit_percent")) {
    c.voltage_limit_percent =
        static_cast<std::uint32_t>(get_int(*n, "voltage_limit_percent", 1, 1000));
  }
  if (const auto* n = t.get("max_velocity")) {
    c.max_velocity_rpm = static_cast<std::uint32_t>(get_int(*n, "max_velocity", 1, 100000));
  }
  if (const auto* n = t.get("max_acceleration")) {
    c.max_acceleration_rpm_s = static_cast<std::uint32_t>(get_int(*n, "max_acceleration", 1, 100000000));
  }
  if (const auto* n = t.get("torque_acceleration")) {
    c.torque_acceleration_rpm_s = static_cast<std::uint32_t>(get_int(*n, "torque_acceleration", 1, 100000000));
  }
  if (const auto* n = t.get("friction")) c.friction_permille = static_cast<std::uint32_t>(get_int(*n, "friction", 0, 1000));
  if (const auto* n = t.get("load")) c.load_permille = static_cast<std::int32_t>(get_int(*n, "load", -1000, 1000));
  constexpr std::int64_t reach = std::int64_t{1} << 40;
  if (const auto* n = t.get("home_switch")) c.home_switch_position = get_int(*n, "home_switch", -reach, reach);
  if (const auto* n = t.get("index_position")) c.index_position = get_int(*n, "index_position", -reach, reach);
  if (const auto* n = t.get("voltage")) s.dc_link_at_start = get_bool(*n, "voltage");
  if (const auto* n = t.get("sto")) s.sto_at_start = get_bool(*n, "sto");
  if (const char* why = check_plant_config(c)) refuse(t, std::string("[plant]: ") + why);
}

}  // namespace cia402::sim::scenario_reading
