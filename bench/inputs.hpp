// Input sequences shared by the core's and the baseline's benchmarks, so both do the same work.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

namespace bench {

struct cycle_input {
  std::uint16_t control_word;
  bool fault;
};

/// A master's life in miniature: mostly Enable operation, with shutdowns, quick stops, disable
/// voltage, fault resets and a rare fault, so every state is visited.
inline std::vector<cycle_input> mixed_inputs(std::size_t n) {
  std::mt19937 rng(402);
  constexpr std::uint16_t words[] = {0x0F, 0x0F, 0x0F, 0x0F, 0x0F, 0x0F, 0x06, 0x06,
                                     0x07, 0x02, 0x00, 0x80, 0x0F, 0x0F, 0x06, 0x0F};
  std::vector<cycle_input> v(n);
  for (auto& c : v) {
    c.control_word = words[rng() % 16];
    c.fault = rng() % 64 == 0;
  }
  return v;
}

/// A master as masters are: each command held until the drive has followed it, so most cycles
/// change nothing (a command every 64 cycles on average) and a fault now and then.
inline std::vector<cycle_input> held_inputs(std::size_t n) {
  std::mt19937 rng(403);
  constexpr std::uint16_t words[] = {0x06, 0x0F, 0x0F, 0x0F, 0x07, 0x02, 0x00, 0x80};
  std::vector<cycle_input> v(n);
  std::uint16_t word = 0x0F;
  for (auto& c : v) {
    if (rng() % 64 == 0) word = words[rng() % 8];
    c.control_word = word;
    c.fault = rng() % 4096 == 0;
  }
  return v;
}

}  // namespace bench
