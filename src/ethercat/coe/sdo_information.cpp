#include "cia402/ethercat/coe/sdo_information.hpp"

#include "bytes.hpp"
#include "cia402/ethercat/coe/sdo.hpp"

namespace cia402::ethercat {

using detail::le16;
using detail::put16;

std::optional<sdo_info_view> parse_sdo_information(std::span<const std::uint8_t> body) noexcept {
  if (body.size() < sdo_info_header_size) return std::nullopt;
  sdo_info_view v;
  v.opcode = static_cast<sdo_info_opcode>(body[0] & 0x7F);
  v.incomplete = (body[0] & 0x80) != 0;
  v.fragments_left = le16(body.data() + 2);
  v.data = body.subspan(sdo_info_header_size);
  return v;
}

std::optional<sdo_info_request> parse_sdo_info_request(const sdo_info_view& v) noexcept {
  sdo_info_request r;
  switch (v.opcode) {
    case sdo_info_opcode::od_list_request:
    case sdo_info_opcode::object_description_request:
      if (v.data.size() < 2) return std::nullopt;
      r.list_or_index = le16(v.data.data());
      return r;
    case sdo_info_opcode::entry_description_request:
      if (v.data.size() < 4) return std::nullopt;
      r.list_or_index = le16(v.data.data());
      r.sub = v.data[2];
      r.value_info = v.data[3];
      return r;
    default: return std::nullopt;
  }
}

std::vector<std::uint8_t> sdo_info_fragment(sdo_info_opcode op, std::uint16_t fragments_left,
                                            std::span<const std::uint8_t> data) {
  std::vector<std::uint8_t> b;
  b.reserve(2 + sdo_info_header_size + data.size());
  put16(b, static_cast<std::uint16_t>(static_cast<unsigned>(coe_service::sdo_information) << 12));
  b.push_back(static_cast<std::uint8_t>(static_cast<unsigned>(op) | (fragments_left > 0 ? 0x80u : 0u)));
  b.push_back(0);
  put16(b, fragments_left);
  b.insert(b.end(), data.begin(), data.end());
  return b;
}

std::vector<std::uint8_t> object_description_data(std::uint16_t index, std::uint16_t data_type, std::uint8_t max_sub,
                                                  std::uint8_t object_code, std::string_view name) {
  std::vector<std::uint8_t> d;
  put16(d, index);
  put16(d, data_type);
  d.push_back(max_sub);
  d.push_back(object_code);
  d.insert(d.end(), name.begin(), name.end());
  return d;
}

std::vector<std::uint8_t> entry_description_data(std::uint16_t index, std::uint8_t sub, std::uint8_t value_info,
                                                 std::uint16_t data_type, std::uint16_t bit_length,
                                                 std::uint16_t object_access, std::string_view name) {
  std::vector<std::uint8_t> d;
  put16(d, index);
  d.push_back(sub);
  d.push_back(value_info);
  put16(d, data_type);
  put16(d, bit_length);
  put16(d, object_access);
  d.insert(d.end(), name.begin(), name.end());
  return d;
}

}  // namespace cia402::ethercat
