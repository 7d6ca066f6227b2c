// What a transition row does before its state change (S7): the stops a row can run, and what each
// means to the step (its ramp, and the option code it reads as it starts, S16). The full step
// (src/core/drive.cpp) and the profile's ordinary cycles (profile::compile_stop_start) read the one
// table here.
#pragma once

#include <cstdint>

namespace cia402 {

/// What the drive does before a row's state change takes effect (S7). `immediate`: the state changes
/// in the step the row fires and the new state's outputs apply at once (a coast where torque was on).
enum class row_stop : std::uint8_t {
  immediate = 0,
  shutdown_option = 1,           ///< 0x605B decides: 0 immediate, 1 slow-down ramp first (T8)
  disable_operation_option = 2,  ///< 0x605C decides: 0 immediate, 1 slow-down ramp first (T5)
  slow_down_ramp = 3,            ///< always ramp on the slow-down ramp first
  quick_stop_ramp = 4,           ///< always ramp on the quick-stop ramp first (seed 004 T17)
  halt_ramp = 5,                 ///< always stop "with Halt" first: the ramp 0x605D picks (seed 001 T5)
  shutdown_option_halt = 6,      ///< 0x605B decides: 0 immediate, 1 stop "with Halt" (seed 001 T8, local T9)
};

inline constexpr int row_stop_count = 7;

namespace detail {
// What a row's stop does, as a few bits, so the drive reads a table rather than a switch: the ramp
// (none, slow-down or quick-stop as stop_ramp numbers them, or `halt_ramp_live`: the one 0x605D
// picks, read live because 0x605D acts at once, S16), whether it only runs when the option code
// read as the stop starts is 1 (else the change is immediate), and which code that is. The full
// step (src/core/drive.cpp) and the ordinary cycles (compile_ordinary) both read it.
namespace stop_bits {
inline constexpr unsigned halt_ramp_live = 3;  ///< bits 0..1: the ramp; 3 = as 0x605D says
inline constexpr unsigned ramp = 3;
inline constexpr unsigned if_code_is_1 = 1u << 2;  ///< ramp only if the code read at the start is 1
inline constexpr unsigned code_605c = 1u << 3;     ///< that code is 0x605C, else 0x605B
}  // namespace stop_bits

constexpr unsigned stop_nibble(row_stop s) noexcept {
  switch (s) {
    case row_stop::immediate: break;
    case row_stop::shutdown_option: return stop_bits::if_code_is_1 | 1u;
    case row_stop::disable_operation_option: return stop_bits::if_code_is_1 | stop_bits::code_605c | 1u;
    case row_stop::slow_down_ramp: return 1u;   // stop_ramp::slow_down
    case row_stop::quick_stop_ramp: return 2u;  // stop_ramp::quick_stop
    case row_stop::halt_ramp: return stop_bits::halt_ramp_live;
    case row_stop::shutdown_option_halt: return stop_bits::if_code_is_1 | stop_bits::halt_ramp_live;
  }
  return 0;
}
}  // namespace detail

}  // namespace cia402
