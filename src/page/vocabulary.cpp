#include "vocabulary.hpp"

#include <string>

#include "cia402/state.hpp"

namespace cia402::page::detail {
namespace {

using json = nlohmann::ordered_json;

struct state_words {
  const char* name;
  const char* meaning;
};

// Indexed by cia402::state. CiA 402's names with the standard's meaning of each state.
constexpr state_words cia402_states[state_count] = {
    {"Start", "Power on or reset: the drive initialises itself."},
    {"Not ready to switch on", "Low-level power on; the drive initialises and tests itself. No torque."},
    {"Switch on disabled", "Initialisation done, parameters can be set. High voltage may be off. No torque."},
    {"Ready to switch on", "High voltage may be on, parameters can be set. No torque."},
    {"Switched on", "High voltage on, the power section is ready. Drive function disabled."},
    {"Operation enabled", "No fault. The drive function is enabled and the motor has torque."},
    {"Quick stop active", "The quick stop function runs (0x605A). The drive function is enabled."},
    {"Fault reaction active", "A fault occurred; the fault reaction runs (0x605E)."},
    {"Fault", "The fault reaction is done; the drive waits for a fault reset. No torque."},
};

// Seed 003's "States of the state machine" (004 prints the same machine).
constexpr state_words drivecom_states[state_count] = {
    {"Start", "Reset / 24 V supply switched on."},
    {"Not ready for switch-on",
     "Amplifier is not ready for switch-on. No operation readiness (BTB) is signaled from the "
     "amplifier software."},
    {"Switch-on inhibited",
     "Amplifier is ready for switch-on. Parameters can be transferred, DC-link (DC-bus) can be "
     "switched on, motion functions cannot be carried out yet."},
    {"Ready for switch-on",
     "DC-link voltage must be applied. Parameters can be transferred, motion functions cannot be "
     "carried out yet."},
    {"Ready for operation",
     "DC-link voltage must be switched on. Parameters can be transferred, motion functions cannot "
     "be carried out yet. Output stage is switched on (enabled)."},
    {"Operation enabled",
     "No error present. Output stage is switched on, motion functions are enabled."},
    {"Fast stop activated",
     "Drive has been stopped, using the emergency stop ramp. Output stage is switched on "
     "(enabled), motion functions are enabled."},
    {"Error response active",
     "An instrument error occurred: the power stage is switched off immediately; then the state "
     "changes to \"Error\"."},
    {"Error",
     "Can only be left by the bit-command \"Error-reset\", with the cause of the error removed."},
};

struct command_words {
  const char* key;  // page_command_key
  const char* cia402;
  const char* drivecom;  // seed 003 / 004: "(command: shutdown)", "fast stop", "inhibit voltage"
};

constexpr command_words commands[] = {
    {"shutdown", "Shutdown", "Shutdown"},
    {"switch_on", "Switch on", "Switch-on"},
    {"enable_operation", "Enable operation", "Operation enable"},
    {"disable_operation", "Disable operation", "Inhibit"},
    {"disable_voltage", "Disable voltage", "Inhibit voltage"},
    {"quick_stop", "Quick stop", "Fast stop"},
    {"fault_reset", "Fault reset", "Error reset"},
    {"halt", "Halt", "Halt"},
};

struct transition_words {
  int number;
  const char* event;
  const char* action;
};

// Seed 002, CoE table 7.8. Its text lost words where the table's cells broke ("The | immediately"
// in T6, T8..T10; the end of T14's action); there the standard's wording completes the sentence.
constexpr transition_words seed_002[] = {
    {0, "Automatic transition after reset application", "Drive device initialisation shall be performed"},
    {1, "Automatic transition", "Communication shall be activated"},
    {2, "Shutdown command from control device or local signal", "None"},
    {3, "Switch on command received from control device or local signal",
     "Power section shall be switched on if not already switched on"},
    {4, "Enable operation command received from control device or local signal",
     "Drive function shall be enabled and clear all internal set-points"},
    {5, "Disable operation command received from control device or local signal",
     "Drive function shall be disabled"},
    {6, "Shutdown command received from control device or local signal",
     "The power section shall be switched off immediately, and the motor shall be free to rotate "
     "if not braked; additional action depends on the shutdown option code"},
    {7, "Quick stop or disable voltage command from control device or local signal", "None"},
    {8, "Shutdown command from control device or local signal",
     "The power section shall be switched off immediately if possible, and the motor shall be "
     "free to rotate if not braked"},
    {9, "Disable voltage command from control device or local signal",
     "The power section shall be switched off immediately if possible, and the motor shall be "
     "free to rotate if not braked"},
    {10, "Disable voltage or quick stop command from control device or local signal",
     "The power section shall be switched off immediately if possible, and the motor shall be "
     "free to rotate if not braked"},
    {11, "Quick stop command from control device or local signal",
     "The quick stop function shall be started"},
    {12, "Automatic transition when the quick stop function is completed and quick stop option "
         "code 1, 2, 3 or 4, or disable voltage command received from control device",
     "The power section shall be switched off"},
    {13, "Fault signal", "The configured fault reaction function shall be executed"},
    {14, "Automatic transition", "The drive function shall be disabled; the power section may be switched off"},
    {15, "Fault reset command from control device or local signal",
     "A reset of the fault condition is carried out, if no fault exists currently on the drive "
     "device; after leaving the Fault state, the Fault reset bit in the controlword shall be "
     "cleared by the control device"},
    {16, "Enable operation command from control device, if the quick stop option code is 5, 6, 7 or 8",
     "The drive function shall be enabled"},
};

// Seed 000: a CANopen drive without quick stop.
constexpr transition_words seed_000[] = {
    {0, "System internal, after completion of the actions in the state 'START'",
     "With the 24 VDC supply connected the system runs to 'SWITCH ON DISABLED' by itself"},
    {1, "System internal, after completion of the actions in 'NOT READY TO SWITCH ON'", "none"},
    {2, "'Shutdown' command received", "none"},
    {3, "'Switch On' command received", "The system checks that the power supply is switched on"},
    {4, "'Enable Operation' command received",
     "The power output stage is enabled and the motor is energized; the holding brake is opened"},
    {5, "'Disable Operation' command received",
     "The motor decelerates to standstill on 0x221E; at standstill the brake closes and the power "
     "output stage is disabled"},
    {6, "'Shutdown' command received", "none"},
    {7, "'Disable Voltage' or 'Quick Stop' command received (quick stop is not supported)", "none"},
    {8, "'Shutdown' command received",
     "The motor decelerates to standstill on 0x221E; at standstill the brake closes and the power "
     "output stage is disabled"},
    {9, "'Disable Voltage' command received",
     "Power output stage is immediately disabled and the motor coasts; the brake closes at once"},
    {10, "'Disable Voltage' or 'Quick Stop' command received", "none"},
    {13, "Error condition detected", "none"},
    {14, "Error reaction completed", "The control bit 'Fault Reset' (bit 7) must be reset"},
    {15, "'Fault Reset' command received",
     "Reset the fault state, system booting, new calculation of any changed parameters"},
};

// Seed 001: Lexium-32-style.
constexpr transition_words seed_001[] = {
    {0, "Device electronics successfully initialized", ""},
    {1, "Parameter successfully initialized", ""},
    {2, "No undervoltage, encoder checked, actual velocity < 1000 rpm, STO signals = +24 V, and "
        "fieldbus command Shutdown", ""},
    {3, "Request for enabling the power stage, or fieldbus command Switch On or Enable Operation", ""},
    {4, "Automatic transition, or fieldbus command Enable Operation",
     "Power stage is enabled. User parameters are checked. Holding brake is released."},
    {5, "Fieldbus command Disable Operation",
     "Movement is canceled with \"Halt\". Holding brake is applied. Power stage is disabled."},
    {6, "Fieldbus command Shutdown", ""},
    {7, "Undervoltage, STO signals = 0 V, actual velocity > 1000 rpm, or fieldbus command Disable "
        "Voltage", ""},
    {8, "Fieldbus command Shutdown",
     "Movement is canceled with \"Halt\" or the power stage is disabled at once (DSM_ShutDownOption)"},
    {9, "Request for disabling the power stage, or fieldbus command Disable Voltage",
     "Power stage is disabled (at once for Disable Voltage)"},
    {10, "Request for disabling the power stage, or fieldbus command Disable Voltage", ""},
    {11, "Error of error class 1, or fieldbus command Quick Stop",
     "Movement is canceled with \"Quick Stop\""},
    {12, "Request for disabling the power stage, or fieldbus command Disable Voltage",
     "Power stage is disabled immediately, even if \"Quick Stop\" is still active"},
    {13, "Error of error class 2, 3 or 4", "Error response is carried out"},
    {14, "Error response terminated (class 2), or error of class 3 or 4", ""},
    {15, "Function \"Fault Reset\"", "Error is reset (the cause must have been corrected)"},
    {16, "Function \"Fault Reset\", or fieldbus command Enable Operation",
     "After a quick stop for an error of class 1, back to Operation Enabled"},
};

// Seed 003: the PROFIBUS instrument control page (fast stop on bit 2).
constexpr transition_words seed_003[] = {
    {0, "Reset / 24V supply is switched on", "Initialization started"},
    {1, "Initialization successfully completed, amplifier switch-on inhibit", "none"},
    {2, "Bit 1 (inhibit voltage) and Bit 2 (fast stop) are set in the control word (command: "
        "shutdown). DC-link voltage is present.", "none"},
    {3, "Bit 0 (switch-on) is also set (command: switch-on)",
     "Output stage is switched on (enabled). Drive has torque."},
    {4, "Bit 3 (operation enabled) is also set (command: operation enable)",
     "Motion functions are enabled, depending on the operating mode that is set."},
    {5, "Bit 3 is canceled (command: inhibit)",
     "Motion functions are disabled. Drive is braked, using the relevant ramp."},
    {6, "Bit 0 is canceled (ready for switch-on).",
     "Output stage is switched off (disabled). Drive has no torque."},
    {7, "Bit 1 or Bit 2 is canceled.", "(Command: \"Fast stop\" or \"Inhibit voltage\")"},
    {8, "Bit 0 is canceled (operation enabled -> ready for switch-on)",
     "Output stage is switched off (disabled) - motor loses torque."},
    {9, "Bit 1 is canceled (operation enabled -> switch-on inhibited)",
     "Output stage is switched off (disabled) - motor loses torque."},
    {10, "Bit 1 or 2 are canceled (ready for operation -> switch-on inhibited)",
     "Output stage is switched off (disabled) - motor loses torque."},
    {11, "Bit 2 is canceled (operation enabled -> fast stop)",
     "Drive is stopped, using the emergency ramp. The output stage remains enabled. Setpoints are "
     "canceled."},
    {12, "Bit 1 is canceled (fast stop -> switch-on inhibited)",
     "Output stage is switched off (disabled) - motor loses torque."},
    {13, "Error response active", "Output stage is switched off (disabled) - motor loses torque."},
    {14, "Error", "none"},
    {15, "Bit 7 is set (error -> switch-on inhibited)",
     "Acknowledge error (depending on error - with/without reset)"},
    {16, "Bit 2 is set (fast stop -> operation enabled)", "Motion function is enabled again."},
};

// Seed 004: Beckhoff AX2000/AX2500 (fast stop on bit 4, T17).
constexpr transition_words seed_004[] = {
    {0, "Reset / 24V supply is switched on", "Initialization started"},
    {1, "Initialization successfully completed, AX2000/2500 switch-on inhibit", "none"},
    {2, "Bit 1 (inhibit voltage) and Bit 2 (fast stop) are set in the control word (command: "
        "shutdown). DC bus link voltage is present.", "none"},
    {3, "Bit 0 (switch-on) is also set (command: switch-on)",
     "Output stage is switched on (enabled). Motor has torque."},
    {4, "Bit 3 (operation enabled) is also set (command: operation enable)",
     "Motion functions are enabled, depending on the operating mode that is set."},
    {5, "Bit 3 is canceled (command: inhibit)",
     "Motion functions are disabled. Motor is braked, using the relevant ramp."},
    {6, "Bit 0 is canceled (ready for switch-on).",
     "Output stage is switched off (disabled). Motor has no torque."},
    {7, "Bit 1 or Bit 2 is canceled.", "(Command: \"Fast stop\" or \"Inhibit voltage\")"},
    {8, "Bit 0 is canceled (operation enabled -> ready for switch-on)",
     "Output stage is switched off (disabled) - motor has no torque."},
    {9, "Bit 1 is canceled (operation enabled -> switch-on inhibited)",
     "Output stage is switched off (disabled) - motor has no torque."},
    {10, "Bit 1 or 2 are canceled (ready for operation -> switch-on inhibited)",
     "Output stage is switched off (disabled) - motor has no torque."},
    {11, "Bit 4 is canceled (operation enabled -> fast stop)",
     "Drive is stopped, using the emergency ramp. The output stage remains enabled. Setpoints are "
     "canceled."},
    {12, "Bit 1 is canceled (fast stop -> switch-on inhibited)",
     "Output stage is switched off (disabled) - motor has no torque."},
    {13, "Error response active", "Output stage is switched off (disabled) - motor has no torque."},
    {14, "Error", "none"},
    {15, "Bit 7 is set (error -> switch-on inhibited)",
     "Acknowledge error (depending on error - with/without reset)"},
    {16, "Bit 4 is set (fast stop -> operation enabled)", "Motion function is enabled again."},
    {17, "Bit 2 is canceled", "Switch-on inhibited, output stage disabled"},
};

struct seed_texts {
  const char* profile;
  const transition_words* rows;
  std::size_t count;
};

template <std::size_t N>
constexpr seed_texts texts(const char* name, const transition_words (&rows)[N]) {
  return {name, rows, N};
}

constexpr seed_texts by_profile[] = {
    texts("cia402", seed_002),        texts("no-quick-stop", seed_000), texts("lexium32", seed_001),
    texts("s300-profibus", seed_003), texts("ax2000-profibus", seed_004),
};

}  // namespace

json vocabulary_json(const profile& p) {
  const bool drivecom = p.words == word_names::drivecom;
  json names = json::object();
  json meanings = json::object();
  for (int s = 0; s < state_count; ++s) {
    const state_words& w = drivecom ? drivecom_states[s] : cia402_states[s];
    const char* key = state_name(static_cast<state>(s));
    names[key] = w.name;
    meanings[key] = w.meaning;
  }
  json labels = json::object();
  for (const command_words& c : commands) labels[c.key] = drivecom ? c.drivecom : c.cia402;
  json transitions = json::object();
  // Only for the built-in profile itself: a profile file may reuse a name with other rows.
  const profile* builtin = find_builtin_profile(p.name);
  if (builtin != nullptr && builtin->rows == p.rows) {
    for (const seed_texts& t : by_profile) {
      if (std::string(t.profile) != p.name) continue;
      for (std::size_t i = 0; i < t.count; ++i) {
        transitions[std::to_string(t.rows[i].number)] = {{"event", t.rows[i].event},
                                                         {"action", t.rows[i].action}};
      }
    }
  }
  return {{"state_names", std::move(names)},
          {"state_meanings", std::move(meanings)},
          {"command_labels", std::move(labels)},
          {"transition_texts", std::move(transitions)}};
}

}  // namespace cia402::page::detail
