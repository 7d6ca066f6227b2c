// Emergency error codes (the 16-bit code of an EMCY message, of 0x603F and of 0x1003): CiA 301
// table 21 ("Emergency error codes"), the generic classes and the communication codes, and the
// device-profile codes of CiA 402 (IEC 61800-7-201) a drive reports, with an English text each.
// One table for every layer: the monitor names EMCYs with it, the page and the master may name
// 0x603F with it. Constexpr data, no heap, no I/O.
#pragma once

#include <cstddef>
#include <cstdint>

namespace cia402 {

/// One entry of the table.
struct error_code_description {
  std::uint16_t code;
  const char* text;  ///< lower case, e.g. "continuous over-current"
};

/// The entries, in ascending code order.
std::size_t error_code_count() noexcept;
const error_code_description& error_code_entry(std::size_t i) noexcept;

/// The text of an error code: the code's own entry if the table has one, else the text of its
/// class 0xXX00 (e.g. 0x2315 -> 0x2300 "current, device output side"), else of its group 0xX000
/// (0x2A17 -> 0x2000 "current"); "unknown error code" for a code in no class (0x0001..0x0FFF,
/// 0xA000..0xEFFF). Never null.
const char* error_code_text(std::uint16_t code) noexcept;

}  // namespace cia402
