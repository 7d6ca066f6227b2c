// The CiA 402 device-control words a bus test hands drive_master to carry (drive_master carries
// words, it does not steer): the commands of cia402-reference.md §2.1 as control bits, so a test
// that needs an enabled drive to check a bus behaviour says each transition's word itself.
#pragma once

#include <cstdint>

#include "cia402/words.hpp"

namespace cia402::canopen::test {

/// Disable voltage: T7, T9, T10, T12 (every bit low).
inline constexpr std::uint16_t disable_voltage_word = 0;
/// Shutdown: T2, T6, T8.
inline constexpr std::uint16_t shutdown_word = control_bit::enable_voltage | control_bit::quick_stop;
/// Switch on: T3 (and Disable operation, T5).
inline constexpr std::uint16_t switch_on_word = shutdown_word | control_bit::switch_on;
/// Enable operation: T4 (and T16 from QUICK STOP ACTIVE).
inline constexpr std::uint16_t enable_operation_word = switch_on_word | control_bit::enable_operation;

}  // namespace cia402::canopen::test
