#include "cia402/ethercat/coe/sdo.hpp"

#include <algorithm>

#include "bytes.hpp"
#include "cia402/sdo_command.hpp"

namespace cia402::ethercat {
namespace {

using detail::le16;
using detail::le32;
using detail::put16;
using detail::put32;

using namespace sdo_command_specifier;  // ccs_*, scs_*, cs_abort: CiA 301's, the top three bits
constexpr std::uint8_t complete_access_bit = 0x10;
constexpr std::uint8_t toggle_bit = 0x10;
constexpr std::size_t segment_data_in_ten_bytes = 7;

std::vector<std::uint8_t> coe(coe_service s) {
  std::vector<std::uint8_t> b;
  b.reserve(coe_header_size + sdo_header_size);
  put16(b, static_cast<std::uint16_t>(static_cast<unsigned>(s) << 12));
  return b;
}

void put_address(std::vector<std::uint8_t>& b, std::uint16_t index, std::uint8_t sub) {
  put16(b, index);
  b.push_back(sub);
}

// A segment's data: the rest of the frame, or, when that is no more than 7 bytes (a frame padded to
// the SDO's 8), 7 less the unused count of bits 1..3; never more than the frame holds.
std::span<const std::uint8_t> segment_data(std::span<const std::uint8_t> body) noexcept {
  const std::size_t available = body.size() - 1;
  std::size_t n = available;
  if (available <= segment_data_in_ten_bytes) n = segment_data_in_ten_bytes - ((body[0] >> 1) & 7u);
  return body.subspan(1, std::min(n, available));
}

// A segment that carries data (download request, upload response): the toggle, the last flag, the data.
sdo_frame data_segment(sdo_command command, std::span<const std::uint8_t> body) noexcept {
  sdo_frame f;
  f.command = command;
  f.toggle = (body[0] & toggle_bit) != 0;
  f.last = (body[0] & 0x01) != 0;
  f.data = segment_data(body);
  return f;
}

// A segment without data (upload request, download response): only the toggle.
sdo_frame empty_segment(sdo_command command, std::uint8_t cmd) noexcept {
  sdo_frame f;
  f.command = command;
  f.toggle = (cmd & toggle_bit) != 0;
  return f;
}

// The object an initiate frame names, and whether it is CoE's complete access.
void read_object(std::span<const std::uint8_t> body, sdo_frame& f) noexcept {
  f.index = le16(body.data() + 1);
  f.sub = body[3];
  f.complete_access = (body[0] & complete_access_bit) != 0;
}

// The value part of an initiate frame (download request, upload response): expedited in the four data
// bytes (4 - n of them when the size is indicated), else the size and what of the value follows.
void read_initiate(std::span<const std::uint8_t> body, sdo_frame& f) noexcept {
  const std::uint8_t cmd = body[0];
  read_object(body, f);
  f.expedited = (cmd & 0x02) != 0;
  f.size_indicated = (cmd & 0x01) != 0;
  if (f.expedited) {
    const std::size_t n = f.size_indicated ? 4 - ((cmd >> 2) & 3u) : 4;
    f.size = static_cast<std::uint32_t>(n);
    f.data = body.subspan(4, n);
    return;
  }
  f.size = f.size_indicated ? le32(body.data() + 4) : 0;
  f.data = body.subspan(sdo_header_size, std::min<std::size_t>(f.size, body.size() - sdo_header_size));
}

void read_abort(std::span<const std::uint8_t> body, sdo_frame& f) noexcept {
  f.command = sdo_command::abort;
  f.index = le16(body.data() + 1);
  f.sub = body[3];
  f.abort_code = le32(body.data() + 4);
}

std::vector<std::uint8_t> padded(std::vector<std::uint8_t> b) {
  if (b.size() < coe_header_size + sdo_header_size) b.resize(coe_header_size + sdo_header_size, 0);
  return b;
}

std::uint8_t unused_of(std::size_t n) noexcept {
  return static_cast<std::uint8_t>(n < segment_data_in_ten_bytes ? segment_data_in_ten_bytes - n : 0);
}

// A client's request and the server's response of the other direction are alike but for the service
// and the command specifier (CiA 301 §7.2.4.3.3 ff., ETG.1000.6 §5.6.2): the frames that carry a
// value (download request, upload response) and those that ask for or confirm one (upload request,
// download response).
// Initiate, expedited: 1..4 bytes in the frame, the size indicated (bits 2..3: 4 - n unused).
std::vector<std::uint8_t> initiate_expedited(coe_service s, std::uint8_t cs, std::uint16_t index, std::uint8_t sub,
                                             std::span<const std::uint8_t> value) {
  const std::size_t n = std::clamp<std::size_t>(value.size(), 1, 4);
  std::vector<std::uint8_t> b = coe(s);
  b.push_back(static_cast<std::uint8_t>((std::size_t{cs} << 5) | ((4 - n) << 2) | 0x03));
  put_address(b, index, sub);
  b.insert(b.end(), value.begin(), value.begin() + static_cast<std::ptrdiff_t>(std::min(n, value.size())));
  return padded(std::move(b));
}

// Initiate, normal: the complete size, then as much of the value as the mailbox takes.
std::vector<std::uint8_t> initiate_normal(coe_service s, std::uint8_t cs, std::uint16_t index, std::uint8_t sub,
                                          bool complete_access, std::uint32_t size, std::span<const std::uint8_t> first) {
  std::vector<std::uint8_t> b = coe(s);
  b.push_back(static_cast<std::uint8_t>((cs << 5) | (complete_access ? complete_access_bit : 0) | 0x01));
  put_address(b, index, sub);
  put32(b, size);
  b.insert(b.end(), first.begin(), first.end());
  return b;
}

// A segment: the toggle, the unused count of a short one, the last flag, the data.
std::vector<std::uint8_t> segment(coe_service s, std::uint8_t cs, bool toggle, bool last, std::span<const std::uint8_t> data) {
  std::vector<std::uint8_t> b = coe(s);
  b.push_back(static_cast<std::uint8_t>((cs << 5) | (toggle ? toggle_bit : 0) | (unused_of(data.size()) << 1) |
                                        (last ? 1 : 0)));
  b.insert(b.end(), data.begin(), data.end());
  return padded(std::move(b));
}

// Initiate without a value: the object and the complete access bit.
std::vector<std::uint8_t> initiate_without_value(coe_service s, std::uint8_t cs, std::uint16_t index, std::uint8_t sub,
                                                 bool complete_access) {
  std::vector<std::uint8_t> b = coe(s);
  b.push_back(static_cast<std::uint8_t>((cs << 5) | (complete_access ? complete_access_bit : 0)));
  put_address(b, index, sub);
  return padded(std::move(b));
}

// A segment without data: the toggle alone.
std::vector<std::uint8_t> segment_without_data(coe_service s, std::uint8_t cs, bool toggle) {
  std::vector<std::uint8_t> b = coe(s);
  b.push_back(static_cast<std::uint8_t>((cs << 5) | (toggle ? toggle_bit : 0)));
  return padded(std::move(b));
}

}  // namespace

std::optional<coe_view> parse_coe(std::span<const std::uint8_t> data) noexcept {
  if (data.size() < coe_header_size) return std::nullopt;
  coe_view v;
  const std::uint16_t header = le16(data.data());
  v.number = header & 0x01FF;
  v.service = static_cast<coe_service>(header >> 12);
  v.body = data.subspan(coe_header_size);
  return v;
}

std::optional<sdo_frame> parse_sdo_request(std::span<const std::uint8_t> body) noexcept {
  if (body.empty()) return std::nullopt;
  sdo_frame f;
  const std::uint8_t cmd = body[0];
  switch (cmd >> 5) {
    case ccs_download_segment: return data_segment(sdo_command::download_segment, body);
    case ccs_upload_segment: return empty_segment(sdo_command::upload_segment, cmd);
    case cs_abort:
      // The master gives up: whatever it names, the transfer ends.
      f.command = sdo_command::abort;
      if (body.size() >= sdo_header_size) read_abort(body, f);
      return f;
    default: break;
  }
  if (body.size() < sdo_header_size) return std::nullopt;
  if ((cmd >> 5) == ccs_initiate_download) {
    f.command = sdo_command::initiate_download;
    read_initiate(body, f);
    return f;
  }
  read_object(body, f);
  f.command = (cmd >> 5) == ccs_initiate_upload ? sdo_command::initiate_upload : sdo_command::other;
  return f;
}

std::optional<sdo_frame> parse_sdo_response(coe_service service, std::span<const std::uint8_t> body) noexcept {
  if (body.empty()) return std::nullopt;
  const std::uint8_t cmd = body[0];
  sdo_frame f;
  if ((cmd >> 5) == cs_abort && (service == coe_service::sdo_request || service == coe_service::sdo_response)) {
    if (body.size() < sdo_header_size) return std::nullopt;
    read_abort(body, f);
    return f;
  }
  if (service != coe_service::sdo_response) return std::nullopt;
  switch (cmd >> 5) {
    case scs_upload_segment: return data_segment(sdo_command::upload_segment, body);
    case scs_download_segment: return empty_segment(sdo_command::download_segment, cmd);
    case scs_initiate_upload:
      if (body.size() < sdo_header_size) return std::nullopt;
      f.command = sdo_command::initiate_upload;
      read_initiate(body, f);
      return f;
    case scs_initiate_download:
      if (body.size() < sdo_header_size) return std::nullopt;
      f.command = sdo_command::initiate_download;
      read_object(body, f);
      return f;
    default: return std::nullopt;
  }
}

std::vector<std::uint8_t> sdo_upload_request(std::uint16_t index, std::uint8_t sub, bool complete_access) {
  return initiate_without_value(coe_service::sdo_request, ccs_initiate_upload, index, sub, complete_access);
}

std::vector<std::uint8_t> sdo_upload_segment_request(bool toggle) {
  return segment_without_data(coe_service::sdo_request, ccs_upload_segment, toggle);
}

std::vector<std::uint8_t> sdo_download_expedited(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> value) {
  return initiate_expedited(coe_service::sdo_request, ccs_initiate_download, index, sub, value);
}

std::vector<std::uint8_t> sdo_download_normal(std::uint16_t index, std::uint8_t sub, bool complete_access,
                                              std::uint32_t size, std::span<const std::uint8_t> first) {
  return initiate_normal(coe_service::sdo_request, ccs_initiate_download, index, sub, complete_access, size, first);
}

std::vector<std::uint8_t> sdo_download_segment(bool toggle, bool last, std::span<const std::uint8_t> data) {
  return segment(coe_service::sdo_request, ccs_download_segment, toggle, last, data);
}

std::vector<std::uint8_t> sdo_abort_request(std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
  std::vector<std::uint8_t> b = coe(coe_service::sdo_request);
  b.push_back(static_cast<std::uint8_t>(cs_abort << 5));
  put_address(b, index, sub);
  put32(b, code);
  return b;
}

std::vector<std::uint8_t> sdo_upload_expedited_response(std::uint16_t index, std::uint8_t sub,
                                                        std::span<const std::uint8_t> value) {
  return initiate_expedited(coe_service::sdo_response, scs_initiate_upload, index, sub, value);
}

std::vector<std::uint8_t> sdo_upload_normal_response(std::uint16_t index, std::uint8_t sub, bool complete_access,
                                                     std::uint32_t size, std::span<const std::uint8_t> first) {
  return initiate_normal(coe_service::sdo_response, scs_initiate_upload, index, sub, complete_access, size, first);
}

std::vector<std::uint8_t> sdo_upload_segment_response(bool toggle, bool last, std::span<const std::uint8_t> data) {
  return segment(coe_service::sdo_response, scs_upload_segment, toggle, last, data);
}

std::vector<std::uint8_t> sdo_download_response(std::uint16_t index, std::uint8_t sub, bool complete_access) {
  return initiate_without_value(coe_service::sdo_response, scs_initiate_download, index, sub, complete_access);
}

std::vector<std::uint8_t> sdo_download_segment_response(bool toggle) {
  return segment_without_data(coe_service::sdo_response, scs_download_segment, toggle);
}

std::vector<std::uint8_t> emergency_request(const emergency_message& e) {
  std::vector<std::uint8_t> b = coe(coe_service::emergency);
  put16(b, e.code);
  b.push_back(e.error_register);
  b.insert(b.end(), e.data.begin(), e.data.end());
  return b;
}

std::optional<emergency_message> parse_emergency(std::span<const std::uint8_t> body) noexcept {
  if (body.size() < 8) return std::nullopt;
  emergency_message e;
  e.code = le16(body.data());
  e.error_register = body[2];
  std::copy_n(body.begin() + 3, e.data.size(), e.data.begin());
  return e;
}

}  // namespace cia402::ethercat
