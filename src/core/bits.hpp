// Bit counting for the core, with the compiler's builtin where there is one and a bounded loop
// where there is not, so the core builds with any C++17 toolchain for a microcontroller.
#pragma once

#include <cstdint>

namespace cia402::detail {

/// The index of the lowest set bit of v (v != 0), without builtins: at most 31 steps.
constexpr int portable_lowest_bit(std::uint32_t v) noexcept {
  int i = 0;
  while (i < 31 && !((v >> i) & 1u)) ++i;
  return i;
}

/// The number of set bits of v, without builtins: at most 32 steps.
constexpr int portable_set_bits(std::uint32_t v) noexcept {
  int n = 0;
  for (; v != 0; v &= v - 1) ++n;
  return n;
}

// One choice of implementation for both: the builtins where the compiler has them.
#if defined(__GNUC__) || defined(__clang__)
inline int lowest_bit(std::uint32_t v) noexcept { return __builtin_ctz(v); }
inline int set_bits(std::uint32_t v) noexcept { return __builtin_popcount(v); }
#else
inline int lowest_bit(std::uint32_t v) noexcept { return portable_lowest_bit(v); }
inline int set_bits(std::uint32_t v) noexcept { return portable_set_bits(v); }
#endif

}  // namespace cia402::detail
