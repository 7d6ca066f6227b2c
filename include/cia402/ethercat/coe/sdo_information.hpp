// CoE SDO information (ETG.1000.6 §5.6.3): the object dictionary lists, object and entry
// descriptions, and their error reply; each response fragmented across as many mailboxes as it
// needs. Part of the CoE codec (links only the core).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "cia402/ethercat/coe/sdo.hpp"

namespace cia402::ethercat {

enum class sdo_info_opcode : std::uint8_t {
  od_list_request = 1,
  od_list_response = 2,
  object_description_request = 3,
  object_description_response = 4,
  entry_description_request = 5,
  entry_description_response = 6,
  error = 7,
};

inline constexpr std::size_t sdo_info_header_size = 4;
/// Bytes of data one fragment carries in a mailbox of `mailbox_size` bytes.
constexpr std::size_t sdo_info_room(std::size_t mailbox_size) noexcept {
  return coe_room(mailbox_size, sdo_info_header_size);
}

/// An SDO information frame: opcode, whether fragments follow, how many, and its data.
struct sdo_info_view {
  sdo_info_opcode opcode = sdo_info_opcode::error;
  bool incomplete = false;
  std::uint16_t fragments_left = 0;
  std::span<const std::uint8_t> data;
};
/// From the CoE body; nothing when it is shorter than the information header.
std::optional<sdo_info_view> parse_sdo_information(std::span<const std::uint8_t> body) noexcept;

/// What a request asks for: the list type (OD list), or the index (object description), or index,
/// sub-index and value info (entry description). Nothing when the data is too short for its opcode.
struct sdo_info_request {
  std::uint16_t list_or_index = 0;
  std::uint8_t sub = 0;
  std::uint8_t value_info = 0;
};
std::optional<sdo_info_request> parse_sdo_info_request(const sdo_info_view& v) noexcept;

/// One fragment as a mailbox's data: CoE header (service 8), information header (the incomplete bit
/// set while fragments are left), data.
std::vector<std::uint8_t> sdo_info_fragment(sdo_info_opcode op, std::uint16_t fragments_left,
                                            std::span<const std::uint8_t> data);

/// The data of an object description: index, data type, highest sub-index, object code, name.
std::vector<std::uint8_t> object_description_data(std::uint16_t index, std::uint16_t data_type, std::uint8_t max_sub,
                                                  std::uint8_t object_code, std::string_view name);
/// The data of an entry description: index, sub-index, value info, data type, bit length, object
/// access, name.
std::vector<std::uint8_t> entry_description_data(std::uint16_t index, std::uint8_t sub, std::uint8_t value_info,
                                                 std::uint16_t data_type, std::uint16_t bit_length,
                                                 std::uint16_t object_access, std::string_view name);

}  // namespace cia402::ethercat
