// Private to src/sim: the readers the scenario loader's parts share (scenario_file.cpp, the
// loader; scenario_plant.cpp, the [plant] table). Refusals travel as toml_reading::refusal.
#pragma once

#include <toml++/toml.h>

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

#include "cia402/sim/scenario.hpp"

namespace cia402::sim::scenario_reading {

/// Refuses an unknown key; a key of the top level written under a [table] is the usual slip and
/// the reason says so.
void check_keys(const toml::table& t, std::initializer_list<std::string_view> allowed,
                std::string_view where);
/// "0x605A", or "0x607D:2" for a sub-index (a quoted key: TOML keys cannot hold the colon bare).
bool parse_index(std::string_view text, std::uint16_t& out, std::uint8_t& sub);
/// "10ms", "1.5s", "250us", "2 s": an exact number of microseconds.
std::uint64_t get_time_us(const toml::node& n, std::string_view what);
/// "2 s", "1.5 s", "1.5 ms", "250 us": a time as a person writes it.
std::string seconds_text(std::uint64_t us);
/// A velocity in rpm (integer or float) as micro-rpm.
std::int64_t get_velocity(const toml::node& n, std::string_view what);

/// The [plant] table into s.plant (and the power-up voltage and STO), checked as a whole by
/// check_plant_config() (scenario_plant.cpp).
void load_plant(const toml::table& t, scenario& s);

}  // namespace cia402::sim::scenario_reading
