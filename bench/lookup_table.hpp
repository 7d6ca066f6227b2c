// The yardstick of the speed targets, and the scenarios measured against it: a bare 256-entry lookup table, the fastest a drive state
// machine can be. Indexed by the state (3 bits) and control-word bits 0..4; it knows the standard's
// commands and status patterns and nothing else (no faults, options, stops, brake or plant).
#pragma once

#include <array>
#include <cstdint>

#include "cia402/drive.hpp"

namespace bench {

struct lookup_table {
  std::array<std::uint8_t, 256> next{};     ///< next state by (state << 5 | cw & 0x1F)
  std::array<std::uint16_t, 8> status{};    ///< status word of each state

  lookup_table() {
    // States: 0 SOD, 1 RTSO, 2 SO, 3 OE, 4 QSA; decoded as S1.
    constexpr std::uint16_t pattern[8] = {0x0250, 0x0231, 0x0233, 0x0237, 0x0217, 0, 0, 0};
    for (unsigned s = 0; s < 8; ++s) {
      status[s] = pattern[s];
      for (unsigned cw = 0; cw < 32; ++cw) {
        const bool dv = !(cw & 2), qs = !(cw & 4), sd = !(cw & 1), so = !(cw & 8);
        unsigned n = s;
        if (dv) n = 0;
        else if (qs) n = s == 3 ? 4 : (s == 4 ? 4 : 0);
        else if (sd) n = s == 4 ? 4 : 1;
        else if (so) n = s == 1 ? 2 : (s == 3 ? 2 : (s == 4 ? 4 : s));
        else n = s == 1 ? 2 : (s == 2 ? 3 : (s == 4 ? 3 : s));
        if (s >= 5) n = 0;
        next[(s << 5) | cw] = static_cast<std::uint8_t>(n);
      }
    }
  }

  struct axis {
    std::uint8_t state = 0;
  };

  std::uint16_t step(axis& a, std::uint16_t control_word) const noexcept {
    a.state = next[(static_cast<unsigned>(a.state) << 5) | (control_word & 0x1Fu)];
    return status[a.state];
  }
};

/// The sequence of the "a transition nearly every cycle" figure: a fixed pseudo-random choice among
/// Disable voltage, Shutdown, Switch on, Enable operation, Quick stop and the same with bit 7 set.
inline constexpr std::uint16_t transition_words[8] = {0x00, 0x06, 0x07, 0x0F, 0x0B, 0x80, 0x86, 0x8F};

/// An axis of the profile in OPERATION ENABLED, brought there by real steps.
inline cia402::axis enabled_axis(const cia402::profile& p) {
  cia402::axis a = cia402::make_axis(p);
  cia402::drive_inputs in;
  for (std::uint16_t w : {0x00, 0x00, 0x06, 0x0F, 0x0F}) {
    in.control_word = w;
    cia402::step(p, a, in);
  }
  return a;
}

inline std::uint16_t transition_word(std::uint32_t& seed) noexcept {
  seed = seed * 1664525u + 1013904223u;  // a fixed LCG: the same sequence in every run
  return transition_words[seed >> 29];
}

}  // namespace bench
