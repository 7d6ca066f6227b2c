#include "page_json.hpp"

#include "cia402/objects.hpp"

#include <algorithm>
#include <cstdio>
#include <tuple>
#include <vector>

#include "cia402/master.hpp"
#include "cia402/motion/homing.hpp"
#include "page_names.hpp"
#include "vocabulary.hpp"

namespace cia402::page {
namespace detail {
namespace {

constexpr command_entry commands[] = {
    {page_command::shutdown, "shutdown", "SHUTDOWN"},
    {page_command::switch_on, "switch_on", "SWITCH_ON"},
    {page_command::enable_operation, "enable_operation", "ENABLE_OPERATION"},
    {page_command::disable_operation, "disable_operation", "DISABLE_OPERATION"},
    {page_command::disable_voltage, "disable_voltage", "DISABLE_VOLTAGE"},
    {page_command::quick_stop, "quick_stop", "QUICK_STOP"},
    {page_command::fault_reset, "fault_reset", "FAULT_RESET"},
    {page_command::halt, "halt", "HALT"},
};

}  // namespace

const command_entry& entry_of(page_command c) noexcept {
  for (const command_entry& e : commands) {
    if (e.id == c) return e;
  }
  return commands[0];
}

bool core_command_of(page_command c, command& out) noexcept {
  switch (c) {
    case page_command::shutdown: out = command::shutdown; return true;
    case page_command::switch_on: out = command::switch_on; return true;
    // Disable operation is the Switch on word (S1); the state tells them apart (T5 vs T3).
    case page_command::disable_operation: out = command::switch_on; return true;
    case page_command::enable_operation: out = command::enable_operation; return true;
    case page_command::disable_voltage: out = command::disable_voltage; return true;
    case page_command::quick_stop: out = command::quick_stop; return true;
    case page_command::fault_reset:
    case page_command::halt: return false;
  }
  return false;
}

json profile_info(const profile& p) {
  json j;
  j["profile"] = {{"name", p.name}, {"title", p.title}, {"seed", p.seed}};
  json states = json::array();
  for (int i = 0; i < state_count; ++i) states.push_back(state_name(static_cast<state>(i)));
  j["states"] = std::move(states);

  // One entry per (number, from set, to): T12 may be two rows with the same ends.
  json rows = json::array();
  std::vector<std::tuple<int, std::uint16_t, int>> seen;
  for (std::size_t r = 0; r < p.row_count; ++r) {
    const transition_row row = p.row(r);
    const auto key = std::make_tuple(int{row.number}, row.from, static_cast<int>(row.to));
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
    seen.push_back(key);
    json from = json::array();
    for (int s = 0; s < state_count; ++s) {
      if ((row.from >> s) & 1u) from.push_back(state_name(static_cast<state>(s)));
    }
    rows.push_back({{"number", row.number}, {"from", std::move(from)}, {"to", state_name(row.to)}});
  }
  j["rows"] = std::move(rows);

  const std::uint16_t owned = owned_control_bits(p);
  const bit_names names = bit_names_for(p);
  json cbits = json::array();
  json sbits = json::array();
  for (int b = 0; b < 16; ++b) {
    cbits.push_back({{"bit", b}, {"name", names.control[b]}, {"owned", ((owned >> b) & 1u) != 0}});
    sbits.push_back({{"bit", b},
                     {"name", names.status[b]},
                     {"state", ((status_bit::state_bits >> b) & 1u) != 0}});
  }
  j["control_word_name"] = names.control_word;
  j["status_word_name"] = names.status_word;
  j["control_bits"] = std::move(cbits);
  j["status_bits"] = std::move(sbits);

  json cmds = json::array();
  for (const command_entry& e : commands) {
    cia402::command c{};
    std::uint16_t word = 0;
    const bool plain = core_command_of(e.id, c);
    // Halt is a button only where the profile has a halt (0x605D): on the PROFIBUS profiles bit 8
    // is something else (Jog), toggled as a bit under the profile's own name.
    const bool available = e.id == page_command::halt ? p.spec(option::halt).exists()
                                                      : !plain || encode_command(p, c, 0, word);
    cmds.push_back({{"key", e.key}, {"action", e.action}, {"available", available}});
  }
  j["commands"] = std::move(cmds);
  j["halt_supported"] = p.spec(option::halt).exists();
  j["error_classes"] = p.error_classes;

  json objects = json::array();
  for (const object_name& o : object_names(p)) {
    const json values = accepted_values(p, o.index);
    json entry = {{"index", hex(o.index, 4)}, {"name", o.name}, {"values", values}};
    // The range the object table allows, so the page refuses an impossible value without a request.
    if (const object_description* d = find_drive_object(o.index)) {
      entry["min"] = d->low;
      entry["max"] = d->high;
    }
    objects.push_back(std::move(entry));
  }
  j["objects"] = std::move(objects);
  // The modes by number: short names ("pp"), CiA 402-2's names ("Profile position"), and the names
  // of the bits the profile leaves to the mode as each mode gives them (the page renames those bits
  // when 0x6061 changes; a DRIVECOM profile keeps the names it gives its bits).
  json modes = json::object();
  json titles = json::object();
  json mode_bits = json::object();
  for (int m = 1; m <= 10; ++m) {
    if (mode::short_name(m)[0] == '\0') continue;
    const std::string key = std::to_string(m);
    modes[key] = mode::short_name(m);
    titles[key] = mode_title(m);
    json control = json::object();
    json status = json::object();
    for (int b = 0; b < 16; ++b) {
      if (const char* n = mode_bit_name(p, true, b, m)) control[std::to_string(b)] = n;
      if (const char* n = mode_bit_name(p, false, b, m)) status[std::to_string(b)] = n;
    }
    mode_bits[key] = {{"control", std::move(control)}, {"status", std::move(status)}};
  }
  j["modes"] = std::move(modes);
  j["mode_names"] = std::move(titles);
  j["mode_bits"] = std::move(mode_bits);
  // The set-point handshake of profile position (POST /api/command "new_setpoint") needs bit 4 left
  // to the mode.
  j["new_setpoint"] = left_to_mode(p, true, 4);
  j.update(vocabulary_json(p));
  return j;
}

}  // namespace detail

const char* page_command_key(page_command c) noexcept { return detail::entry_of(c).key; }

bool parse_page_command(std::string_view key, page_command& out) noexcept {
  for (const detail::command_entry& e : detail::commands) {
    if (key == e.key) {
      out = e.id;
      return true;
    }
  }
  return false;
}

}  // namespace cia402::page
