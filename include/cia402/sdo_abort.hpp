// One error enum for object access; its values are the CiA 301 SDO abort codes, so the CANopen layer
// sends them unchanged.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cia402/hex_text.hpp"

namespace cia402 {

enum class sdo_abort : std::uint32_t {
  none = 0,
  toggle_bit_not_alternated = 0x05030000,
  sdo_protocol_timed_out = 0x05040000,
  command_specifier_invalid = 0x05040001,
  invalid_block_size = 0x05040002,       ///< block mode only
  invalid_sequence_number = 0x05040003,  ///< block mode only
  crc_error = 0x05040004,                ///< block mode only
  out_of_memory = 0x05040005,
  unsupported_access = 0x06010000,
  write_only_object = 0x06010001,
  read_only_object = 0x06010002,
  object_does_not_exist = 0x06020000,
  cannot_map_to_pdo = 0x06040041,
  pdo_length_exceeded = 0x06040042,
  general_parameter_incompatibility = 0x06040043,
  hardware_error = 0x06060000,
  data_type_length_mismatch = 0x06070010,
  data_type_length_too_high = 0x06070012,
  data_type_length_too_low = 0x06070013,
  sub_index_does_not_exist = 0x06090011,
  invalid_value = 0x06090030,
  value_too_high = 0x06090031,
  value_too_low = 0x06090032,
  general_error = 0x08000000,
  cannot_store_in_present_state = 0x08000022,
  no_data_available = 0x08000024,  ///< e.g. 0x1003 sub-index beyond the number of errors (CiA 301 §7.5.2.5)
};

/// A short English reason, e.g. "value range of parameter exceeded"; never null.
const char* sdo_abort_text(sdo_abort code) noexcept;

/// The text of an abort as every message names it, in a buffer the result carries (no allocation).
struct sdo_abort_words_text {
  char chars[112] = {};  ///< the longest line (0x08000022's) is 95 characters and the NUL
  constexpr const char* c_str() const noexcept { return chars; }
};

/// "SDO abort 0x06090030 (invalid value for parameter)": the code's 8 hexadecimal digits and its
/// sdo_abort_text(). The one spelling of an abort in the page, the scenario log, the replay and the
/// masters' messages.
inline sdo_abort_words_text sdo_abort_words(sdo_abort code) noexcept {
  sdo_abort_words_text out;
  std::size_t n = 0;
  const auto put = [&](const char* s) {
    while (*s != '\0' && n + 1 < sizeof out.chars) out.chars[n++] = *s++;
  };
  put("SDO abort ");
  put(to_hex(static_cast<std::uint32_t>(code), 8).c_str());
  put(" (");
  put(sdo_abort_text(code));
  put(")");
  return out;
}

}  // namespace cia402
