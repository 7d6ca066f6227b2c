// Names of the core's enums, as the CLI, profile files and JSON output spell them.
#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"
#include "cia402/state.hpp"
#include "cia402/words.hpp"

namespace cia402 {
namespace {

constexpr const char* state_names[state_count] = {
    "START",          "NOT_READY_TO_SWITCH_ON", "SWITCH_ON_DISABLED",
    "READY_TO_SWITCH_ON", "SWITCHED_ON",        "OPERATION_ENABLED",
    "QUICK_STOP_ACTIVE",  "FAULT_REACTION_ACTIVE", "FAULT",
};

constexpr const char* fact_names[fact_count] = {
    "disable_voltage", "quick_stop",       "shutdown",        "switch_on",
    "enable_operation", "stop_and_inhibit", "fault_reset",     "automatic",
    "fault",           "fault_quick_stop", "fault_present",   "fault_immediate",
    "dc_link",         "sto",              "overspeed",       "stop_complete",
    "quick_stop_ends", "quick_stop_stays", "entered_by_fault", "local_enable",
    "local_disable",   "fault_latched",    "undervoltage",    "halt",
    "below_speed_limit",
};

constexpr const char* command_names[command_count] = {
    "DISABLE_VOLTAGE", "QUICK_STOP", "SHUTDOWN", "SWITCH_ON", "ENABLE_OPERATION", "STOP_AND_INHIBIT",
};

constexpr const char* ramp_names[] = {
    "none", "slow_down", "quick_stop", "current_limit", "voltage_limit", "coast",
};

// Case-insensitive, '-' and '_' alike, so "quick-stop-active" and "QUICK_STOP_ACTIVE" both parse.
bool same_name(std::string_view a, const char* b) noexcept {
  std::size_t i = 0;
  for (; i < a.size() && b[i] != '\0'; ++i) {
    char x = a[i];
    char y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x == '-') x = '_';
    if (y == '-') y = '_';
    if (x != y) return false;
  }
  return i == a.size() && b[i] == '\0';
}

}  // namespace

const char* state_name(state s) noexcept {
  const auto i = static_cast<unsigned>(s);
  return i < state_count ? state_names[i] : "UNKNOWN";
}

// The short forms the docs and masters' logs use, by state.
constexpr const char* state_abbreviations[state_count] = {
    "START", "NRTSO", "SOD", "RTSO", "SO", "OE", "QSA", "FRA", "F",
};

bool parse_state(std::string_view name, state& out) noexcept {
  for (int i = 0; i < state_count; ++i) {
    if (same_name(name, state_names[i]) || same_name(name, state_abbreviations[i])) {
      out = static_cast<state>(i);
      return true;
    }
  }
  return false;
}

const char* state_abbreviation(state s) noexcept {
  const auto i = static_cast<unsigned>(s);
  return i < static_cast<unsigned>(state_count) ? state_abbreviations[i] : "?";
}

const char* command_name(command c) noexcept {
  const auto i = static_cast<unsigned>(c);
  return i < command_count ? command_names[i] : "UNKNOWN";
}

const char* fact_name(fact f) noexcept {
  const auto b = static_cast<std::uint32_t>(f);
  for (int i = 0; i < fact_count; ++i) {
    if (b == (1u << i)) return fact_names[i];
  }
  return "unknown";
}

bool parse_fact(std::string_view name, fact& out) noexcept {
  for (int i = 0; i < fact_count; ++i) {
    if (same_name(name, fact_names[i])) {
      out = static_cast<fact>(1u << i);
      return true;
    }
  }
  return false;
}

const char* stop_ramp_name(stop_ramp r) noexcept {
  const auto i = static_cast<unsigned>(r);
  return i < sizeof(ramp_names) / sizeof(ramp_names[0]) ? ramp_names[i] : "unknown";
}

const char* sdo_abort_text(sdo_abort code) noexcept {
  switch (code) {
    case sdo_abort::none: return "no error";
    case sdo_abort::toggle_bit_not_alternated: return "toggle bit not alternated";
    case sdo_abort::sdo_protocol_timed_out: return "SDO protocol timed out";
    case sdo_abort::command_specifier_invalid: return "client/server command specifier not valid";
    case sdo_abort::invalid_block_size: return "invalid block size";
    case sdo_abort::invalid_sequence_number: return "invalid sequence number";
    case sdo_abort::crc_error: return "CRC error";
    case sdo_abort::out_of_memory: return "out of memory";
    case sdo_abort::unsupported_access: return "unsupported access to an object";
    case sdo_abort::write_only_object: return "attempt to read a write only object";
    case sdo_abort::read_only_object: return "attempt to write a read only object";
    case sdo_abort::object_does_not_exist: return "object does not exist in the object dictionary";
    case sdo_abort::cannot_map_to_pdo: return "object cannot be mapped to the PDO";
    case sdo_abort::pdo_length_exceeded: return "PDO length exceeded";
    case sdo_abort::general_parameter_incompatibility: return "general parameter incompatibility";
    case sdo_abort::hardware_error: return "access failed due to a hardware error";
    case sdo_abort::data_type_length_mismatch: return "data type does not match, length mismatch";
    case sdo_abort::data_type_length_too_high: return "data type does not match, length too high";
    case sdo_abort::data_type_length_too_low: return "data type does not match, length too low";
    case sdo_abort::sub_index_does_not_exist: return "sub-index does not exist";
    case sdo_abort::invalid_value: return "invalid value for parameter";
    case sdo_abort::value_too_high: return "value of parameter written too high";
    case sdo_abort::value_too_low: return "value of parameter written too low";
    case sdo_abort::general_error: return "general error";
    case sdo_abort::cannot_store_in_present_state:
      return "data cannot be transferred or stored because of the present device state";
    case sdo_abort::no_data_available: return "no data available";
  }
  return "unknown abort code";
}

namespace {

// CiA 402 (the standard's names of 0x6040 and 0x6041).
constexpr word_bit_names cia402_bit_names = {
    "controlword 0x6040",
    "statusword 0x6041",
    {"Switch on", "Enable voltage", "Quick stop (active low)", "Enable operation",
     "Operation mode specific", "Operation mode specific", "Operation mode specific",
     "Fault reset (0->1 edge)", "Halt", "Operation mode specific", "Reserved",
     "Manufacturer specific", "Manufacturer specific", "Manufacturer specific",
     "Manufacturer specific", "Manufacturer specific"},
    {"Ready to switch on", "Switched on", "Operation enabled", "Fault", "Voltage enabled",
     "Quick stop (active low)", "Switch on disabled", "Warning", "Manufacturer specific", "Remote",
     "Target reached", "Internal limit active", "Operation mode specific",
     "Operation mode specific", "Manufacturer specific", "Manufacturer specific"},
};

// DRIVECOM's STW and ZSW, as the Kollmorgen S300 and Beckhoff AX2000 PROFIBUS manuals name them.
// Bit 4 of the ZSW: the core sets it when DC-link voltage is present, as CiA 402 does; the name
// says what it shows (docs/profiles/s300-profibus.md keeps the manuals' "voltage inhibited" as an
// open point).
constexpr word_bit_names drivecom_bit_names = {
    "control word STW (0x6040)",
    "status word ZSW (0x6041)",
    {"Switch on", "Inhibit voltage (active low)", "Fast stop, switch-on inhibited (active low)",
     "Operation enabled", "Fast stop / inhibit ramp function generator", "Pause",
     "Setpoint enable", "Reset fault", "Jog", "Reserved", "PZD enable", "Start homing (edge)",
     "Reset position", "Acknowledge warnings", "Manufacturer specific", "Manufacturer specific"},
    {"Ready for switch-on", "Switched on", "Operation enabled", "Error",
     "Voltage present (DC link)", "Fast stop (active low)", "Switch-on inhibit", "Warning",
     "Following error", "Remote", "In position", "Limit", "Mode specific", "Mode specific",
     "Manufacturer specific", "Manufacturer specific"},
};

}  // namespace

const word_bit_names& bit_names_of(const profile& p) noexcept {
  return p.words == word_names::drivecom ? drivecom_bit_names : cia402_bit_names;
}

const char* word_names_name(word_names w) noexcept {
  return w == word_names::drivecom ? "drivecom" : "cia402";
}

bool parse_word_names(std::string_view name, word_names& out) noexcept {
  if (name == "cia402") {
    out = word_names::cia402;
    return true;
  }
  if (name == "drivecom") {
    out = word_names::drivecom;
    return true;
  }
  return false;
}

}  // namespace cia402
