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

// Bits 4..6 and 9 mean what the operation mode 0x6061 makes of them (CiA 402-2; cia402-reference.md
// §2.1): one name per meaning, several names for one bit.
/// Bit 4 in profile position: its 0->1 edge offers 0x607A as a new set-point.
inline constexpr std::uint16_t new_set_point = 1u << 4;
/// Bit 4 in homing: its 0->1 edge starts a homing run, its fall interrupts one.
inline constexpr std::uint16_t homing_operation_start = 1u << 4;
/// Bit 5 in profile position: the offered set-point replaces the running one at once.
inline constexpr std::uint16_t change_set_immediately = 1u << 5;
/// Bit 6 in profile position ("abs/rel"): the target is relative to the previous one.
inline constexpr std::uint16_t relative = 1u << 6;
/// Bit 9 in profile position: the running set-point is passed at speed into the queued one.
inline constexpr std::uint16_t change_on_set_point = 1u << 9;
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
/// In profile position and homing: at the target (home) and at rest; in profile velocity: the
/// velocity within 0x606D of the set-point for 0x606E; in profile torque: the demand at 0x6071.
/// Also set when a halt or a quick stop with 0x605A = 5..8 has brought the drive to rest.
inline constexpr std::uint16_t target_reached = 1u << 10;
/// A set-point or the motion is cut to a limit: 0x607D, 0x607F / 0x6080, 0x6072, or a stop at the
/// current or voltage limit.
inline constexpr std::uint16_t internal_limit_active = 1u << 11;

// Bits 12 and 13 mean what the operation mode 0x6061 makes of them (CiA 402-2; cia402-reference.md
// §1.2): one name per meaning, several names for one bit.
/// Bit 12 in profile position: the offered set-point was taken (or queued).
inline constexpr std::uint16_t set_point_acknowledge = 1u << 12;
/// Bit 12 in profile velocity ("speed"): |velocity| is within 0x606F (the velocity threshold).
inline constexpr std::uint16_t speed_zero = 1u << 12;
/// Bit 12 in homing: home was found and the position redefined.
inline constexpr std::uint16_t homing_attained = 1u << 12;
/// Bit 12 in the cyclic synchronous modes: the drive follows the command value (0x607A, 0x60FF,
/// 0x6071).
inline constexpr std::uint16_t drive_follows_command = 1u << 12;
/// Bit 13 in profile position and cyclic synchronous position: the following error is beyond 0x6065
/// for longer than 0x6066.
inline constexpr std::uint16_t following_error = 1u << 13;
/// Bit 13 in profile velocity: the slip beyond its maximum (an asynchronous motor's; never set by a
/// drive without one).
inline constexpr std::uint16_t max_slippage = 1u << 13;
/// Bit 13 in homing: the run failed (a limit switch where the method expects none, or nothing found
/// within the search distance).
inline constexpr std::uint16_t homing_error = 1u << 13;
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
