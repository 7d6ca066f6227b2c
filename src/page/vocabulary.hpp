// The words each profile's own documents use, for the page: state names and their meaning, command
// names, and each transition's event and action, as the seed pages print them (seed 002's CoE
// table 7.8, 000's and 001's transition tables, the PROFIBUS pages of 003 and 004). State and
// command names follow the profile's word names (CiA 402 or DRIVECOM); the transition texts belong
// to a built-in profile and are left out for a profile loaded from a file, whose rows may differ.
#pragma once

#include <nlohmann/json.hpp>

#include "cia402/profile.hpp"

namespace cia402::page::detail {

/// {"state_names": {"SWITCH_ON_DISABLED": "Switch-on inhibited", ...},
///  "state_meanings": {...}, "command_labels": {"quick_stop": "Fast stop", ...},
///  "transition_texts": {"2": {"event": "...", "action": "..."}, ...}}
nlohmann::ordered_json vocabulary_json(const profile& p);

}  // namespace cia402::page::detail
