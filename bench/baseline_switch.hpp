// The baseline the benchmarks compare against: a plain switch-based CiA 402 machine of the kind
// open drives and masters ship (one state byte, a fixed quick-stop ramp, fixed command words).
// It has far fewer features than the core (no option codes, no pending stops, no profiles, no
// brake or ramp outputs), which is the point: the core must not cost much more.
#pragma once

#include <cstdint>

namespace baseline {

enum class state : std::uint8_t { not_ready, disabled, ready, switched_on, enabled, quick_stop, reaction, fault };

struct drive {
  state current = state::not_ready;
  bool last_reset = false;
};

struct output {
  std::uint16_t status_word;
  bool torque;
};

output step(drive& d, std::uint16_t control_word, bool fault_present) noexcept;

/// The plain master: status word in, fixed control word out, towards OPERATION ENABLED.
std::uint16_t master_step(std::uint16_t status_word, std::uint16_t& last_control_word) noexcept;

}  // namespace baseline
