// States of the power drive system finite state automaton (PDS FSA), CiA 402-2 / IEC 61800-7-201.
#pragma once

#include <cstdint>
#include <string_view>

namespace cia402 {

/// The FSA states. `start` is the power-on pseudo state that T0 leaves; it is never reported by a
/// status word of its own (it reads like NOT READY TO SWITCH ON).
enum class state : std::uint8_t {
  start = 0,
  not_ready_to_switch_on = 1,
  switch_on_disabled = 2,
  ready_to_switch_on = 3,
  switched_on = 4,
  operation_enabled = 5,
  quick_stop_active = 6,
  fault_reaction_active = 7,
  fault = 8,
};

inline constexpr int state_count = 9;

/// One bit per state, for the `from` set of a transition row.
constexpr std::uint16_t state_bit(state s) noexcept {
  return static_cast<std::uint16_t>(1u << static_cast<unsigned>(s));
}

/// The standard's name in upper snake case: "OPERATION_ENABLED". Never null.
const char* state_name(state s) noexcept;

/// Parses an upper or lower snake-case name ("operation_enabled", "QUICK_STOP_ACTIVE") or its
/// abbreviation ("OE", "qsa"; state_abbreviation). Returns false and leaves `out` untouched when the
/// name is unknown.
bool parse_state(std::string_view name, state& out) noexcept;

/// "NRTSO", "SOD", "RTSO", "SO", "OE", "QSA", "FRA", "F" ("START" for the power-on pseudo state).
const char* state_abbreviation(state s) noexcept;

/// The transition number reported when no transition was taken.
inline constexpr std::uint8_t no_transition = 0xFF;

}  // namespace cia402
