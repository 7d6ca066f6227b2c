// `cia402 decode`: status and control words taken apart, bit by bit, against a profile's tables:
// the state by the core's decode_status, the bits by the profile's own names (bit_names_of).
#pragma once

#include <cstdint>
#include <string>

#include "cia402/profile.hpp"
#include "cia402/state.hpp"

namespace cia402::cli {

/// A readable report: the state and every bit named with its value.
std::string describe_status_word(const profile& p, std::uint16_t status_word);
/// A readable report: the command the profile decodes, fault reset, halt, and every bit named.
std::string describe_control_word(const profile& p, std::uint16_t control_word);

/// The same as one line of JSON: {"profile", "word", "state" (null if none), "bits": [{"bit",
/// "value", "name"}]}.
std::string status_word_json(const profile& p, std::uint16_t status_word);
/// {"profile", "word", "command", "fault_reset", "halt", "bits": [{"bit", "value", "name",
/// "decoded"}]}.
std::string control_word_json(const profile& p, std::uint16_t control_word);

}  // namespace cia402::cli
