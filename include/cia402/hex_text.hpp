// One way to write a number in hexadecimal for the layers that see only the core (the axis session,
// CiA 301, the CAN monitor, the EtherCAT master, link and slave): upper-case digits after "0x", in a
// buffer the result carries, so it allocates nothing. The layers that may see support use
// support::hex, which writes the same text into a std::string.
#pragma once

#include <cstdint>

namespace cia402 {

/// The text of one hexadecimal number: "0x" and up to 16 digits.
struct hex_text {
  char chars[19] = {};
  constexpr const char* c_str() const noexcept { return chars; }
};

/// "0x" and `digits` upper-case hexadecimal digits, more if the value needs them (16 at the most):
/// to_hex(0x6041, 4) is "0x6041", to_hex(0x12345, 4) "0x12345", to_hex(0x6, 2) "0x06".
constexpr hex_text to_hex(std::uint64_t value, int digits) noexcept {
  int needed = 1;
  while (needed < 16 && (value >> (4 * needed)) != 0) ++needed;
  const int n = digits > 16 ? 16 : (digits > needed ? digits : needed);
  hex_text t;
  t.chars[0] = '0';
  t.chars[1] = 'x';
  for (int i = 0; i < n; ++i) t.chars[1 + n - i] = "0123456789ABCDEF"[(value >> (4 * i)) & 0xF];
  return t;
}

}  // namespace cia402
