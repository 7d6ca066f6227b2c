// What the page's command buttons and bit toggles do to the control word, decided alike for both
// backends: the words come from the core (cia402::encode_command, S1). A backend only gets the
// word to its drive its own way (one word a cycle to the virtual drive, RPDO1 on a bus) and logs
// the action.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <variant>

#include "action_log.hpp"
#include "cia402/page/backend.hpp"
#include "cia402/profile.hpp"

namespace cia402::page::detail {

struct word_change {
  std::string action;      ///< as the results name it: "SHUTDOWN", "BIT_8=1 (QUICK_STOP)"
  std::uint16_t word = 0;  ///< the control word from now on
  /// A fault reset: bit 7 must rise, an edge (S2), and fall again; `word` has it low.
  bool fault_reset_edge = false;
  /// Tracked until the drive settles; else over at once, reported as done with `text`.
  bool tracked = true;
  std::string text;
  /// What the change asks of a drive in a given state (for the result when nothing happens).
  action_log::expectation expect_in(const profile& p, std::uint16_t before,
                                    std::optional<state> now) const;
};

/// A command button; refused (409) when the profile has no control word for it.
std::variant<word_change, refused> press_button(const profile& p, page_command c,
                                                std::uint16_t control_word);

/// Bit `bit` (0..15) flipped by hand. Tracked when the word then decodes to another command, or
/// sets bit 7 (a fault-reset edge); else it changed nothing the state machine reads.
word_change flip_bit(const profile& p, std::uint16_t control_word, int bit);

/// Why the set-point handshake of profile position (bit 4 up until status bit 12, then down) cannot
/// run, or nothing: the profile gives bit 4 a meaning of its own (409), or the drive shows another
/// mode in 0x6061 (`mode`, when known; 409).
std::optional<refused> new_setpoint_refusal(const profile& p, std::optional<std::int64_t> mode);

/// How long the handshake waits for status bit 12 before it lets bit 4 fall unacknowledged.
inline constexpr std::uint64_t new_setpoint_wait_us = 1000000;

}  // namespace cia402::page::detail
