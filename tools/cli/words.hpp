// `cia402 decode`: status and control words taken apart, bit by bit, against a profile's tables.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "cia402/profile.hpp"
#include "cia402/state.hpp"

namespace cia402::cli {

/// The state a status word shows under the profile's state patterns. Bits 0..3, 5, 6 are compared
/// (mask 0x6F), except that bit 5 is don't-care in NOT READY TO SWITCH ON, SWITCH ON DISABLED,
/// FAULT REACTION ACTIVE and FAULT (mask 0x4F; cia402-reference.md §1.1). Empty if no state
/// matches.
std::optional<state> state_of_status_word(const profile& p, std::uint16_t status_word);

/// The status-word mask a state is recognised by: 0x4F or 0x6F.
std::uint16_t status_mask_of(state s);

/// A readable report: the state and every bit named with its value.
std::string describe_status_word(const profile& p, std::uint16_t status_word);
/// A readable report: the command the profile decodes, fault reset, halt, and every bit named.
std::string describe_control_word(const profile& p, std::uint16_t control_word);

}  // namespace cia402::cli
