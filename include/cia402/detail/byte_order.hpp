// Where a byte of a small object sits in an integer read from it: the compiled tables (the profile's
// ordinary cycles, compiled.hpp) hold an axis's first four bytes and the outputs' first eight as
// integers, so one load, one AND and one OR rewrite them.
#pragma once

namespace cia402::detail {

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
inline constexpr bool little_endian = false;
#else
inline constexpr bool little_endian = true;
#endif

/// Where byte `i` of an object of `Size` bytes sits in an integer read from it, in bits.
template <unsigned Size>
constexpr unsigned byte_shift(unsigned i) noexcept {
  return little_endian ? 8u * i : 8u * (Size - 1u - i);
}

/// Where the status word's lowest bit sits in the outputs' first 8 bytes read as one integer (the
/// word is bytes 2 and 3 of drive_outputs).
inline constexpr unsigned status_shift = little_endian ? 16u : 32u;

}  // namespace cia402::detail
