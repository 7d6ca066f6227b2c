// Bits of the control word 0x6040 and the status word 0x6041 (cia402-reference.md §1.2, §2.1).
#pragma once

#include <cstdint>

namespace cia402 {

namespace control_bit {
inline constexpr std::uint16_t switch_on = 1u << 0;
inline constexpr std::uint16_t enable_voltage = 1u << 1;
inline constexpr std::uint16_t quick_stop = 1u << 2;  ///< active low
inline constexpr std::uint16_t enable_operation = 1u << 3;
inline constexpr std::uint16_t fault_reset = 1u << 7;  ///< acts on its 0->1 edge (S2)
inline constexpr std::uint16_t halt = 1u << 8;         ///< 0x605D (S8)
// Operation-mode bits (CiA 402-2; docs/modes.md): bit 4 is the new set-point in pp and the homing
// operation start in hm; 5, 6 and 9 belong to pp.
inline constexpr std::uint16_t new_set_point = 1u << 4;           ///< pp
inline constexpr std::uint16_t homing_operation_start = 1u << 4;  ///< hm
inline constexpr std::uint16_t change_set_immediately = 1u << 5;  ///< pp
inline constexpr std::uint16_t relative = 1u << 6;                ///< pp
inline constexpr std::uint16_t change_on_set_point = 1u << 9;     ///< pp
}  // namespace control_bit

namespace status_bit {
inline constexpr std::uint16_t ready_to_switch_on = 1u << 0;
inline constexpr std::uint16_t switched_on = 1u << 1;
inline constexpr std::uint16_t operation_enabled = 1u << 2;
inline constexpr std::uint16_t fault = 1u << 3;
inline constexpr std::uint16_t voltage_enabled = 1u << 4;  ///< DC-link voltage present (S11)
inline constexpr std::uint16_t quick_stop = 1u << 5;       ///< active low
inline constexpr std::uint16_t switch_on_disabled = 1u << 6;
inline constexpr std::uint16_t warning = 1u << 7;
inline constexpr std::uint16_t remote = 1u << 9;
inline constexpr std::uint16_t target_reached = 1u << 10;
inline constexpr std::uint16_t internal_limit_active = 1u << 11;
// Operation-mode bits (CiA 402-2; docs/modes.md): bit 12 and 13 mean one thing per mode.
inline constexpr std::uint16_t set_point_acknowledge = 1u << 12;   ///< pp
inline constexpr std::uint16_t speed_zero = 1u << 12;              ///< pv
inline constexpr std::uint16_t homing_attained = 1u << 12;         ///< hm
inline constexpr std::uint16_t drive_follows_command = 1u << 12;   ///< csp, csv, cst
inline constexpr std::uint16_t homing_error = 1u << 13;            ///< hm
inline constexpr std::uint16_t following_error = 1u << 13;         ///< csp (and pp)
/// The bits the FSA state is shown in: 0..3, 5 and 6.
inline constexpr std::uint16_t state_bits = 0x006F;
/// Bits the drive passes through from the motion side unchanged: 8 and 12..15.
inline constexpr std::uint16_t mode_specific = 0xF100;
/// Bits the motion side reports through drive_inputs::status_bits: warning, target reached,
/// internal limit and the mode-specific bits.
inline constexpr std::uint16_t reported = warning | target_reached | internal_limit_active | mode_specific;
}  // namespace status_bit

/// Commands of the control word, as a profile's decoder yields them (cia402-reference.md §2.2).
/// `stop_and_inhibit` is the DRIVECOM "fast stop, switch-on inhibited" of seed 004's bit 2 (T17).
enum class command : std::uint8_t {
  disable_voltage = 0,
  quick_stop = 1,
  shutdown = 2,
  switch_on = 3,  ///< also "Disable operation": same bits, the state tells them apart
  enable_operation = 4,
  stop_and_inhibit = 5,
};

inline constexpr int command_count = 6;

/// "DISABLE_VOLTAGE", "QUICK_STOP", ...; never null.
const char* command_name(command c) noexcept;

/// The words that give a drive a fault-reset edge (S2: bit 7 rising acts, a level does not), in the
/// order to send them, each for at least one of the drive's cycles: `word` without bit 7 first if
/// the last word sent had it, then with it, then without it again. What a master sends for "Fault
/// reset" whichever way it times the words (per cycle, or held for a pulse time).
struct fault_reset_words {
  std::uint16_t words[3] = {};
  std::uint8_t count = 0;
};
constexpr fault_reset_words fault_reset_edge(std::uint16_t last_sent, std::uint16_t word) noexcept {
  fault_reset_words r;
  const auto low = static_cast<std::uint16_t>(word & ~control_bit::fault_reset);
  if ((last_sent & control_bit::fault_reset) != 0) r.words[r.count++] = low;
  r.words[r.count++] = static_cast<std::uint16_t>(low | control_bit::fault_reset);
  r.words[r.count++] = low;
  return r;
}

}  // namespace cia402
