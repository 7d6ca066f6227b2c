#include "cia402/ethercat/coe/mailbox.hpp"

#include <algorithm>

#include "bytes.hpp"

namespace cia402::ethercat {

bool read_mailbox_header(std::span<const std::uint8_t> mailbox, mailbox_header& out) noexcept {
  if (mailbox.size() < mailbox_header_size) return false;
  out.length = detail::le16(mailbox.data());
  out.address = detail::le16(mailbox.data() + 2);
  out.channel = mailbox[4] & 0x3F;
  out.priority = static_cast<std::uint8_t>(mailbox[4] >> 6);
  out.type = static_cast<mailbox_type>(mailbox[5] & 0x0F);
  out.counter = static_cast<std::uint8_t>((mailbox[5] >> 4) & 0x07);
  return true;
}

void write_mailbox_header(const mailbox_header& h, std::uint8_t* p) noexcept {
  p[0] = static_cast<std::uint8_t>(h.length);
  p[1] = static_cast<std::uint8_t>(h.length >> 8);
  p[2] = static_cast<std::uint8_t>(h.address);
  p[3] = static_cast<std::uint8_t>(h.address >> 8);
  p[4] = static_cast<std::uint8_t>((h.channel & 0x3F) | (h.priority << 6));
  p[5] = static_cast<std::uint8_t>((static_cast<std::uint8_t>(h.type) & 0x0F) | ((h.counter & 0x07) << 4));
}

std::optional<mailbox_view> parse_mailbox(std::span<const std::uint8_t> mailbox) noexcept {
  mailbox_view v;
  if (!read_mailbox_header(mailbox, v.header)) return std::nullopt;
  if (v.header.length > mailbox.size() - mailbox_header_size) return std::nullopt;
  v.data = mailbox.subspan(mailbox_header_size, v.header.length);
  return v;
}

std::vector<std::uint8_t> make_mailbox(mailbox_header h, std::span<const std::uint8_t> data, std::size_t size) {
  if (size < mailbox_header_size || data.size() > size - mailbox_header_size || data.size() > 0xFFFF) return {};
  std::vector<std::uint8_t> m(size, 0);
  h.length = static_cast<std::uint16_t>(data.size());
  write_mailbox_header(h, m.data());
  std::copy(data.begin(), data.end(), m.begin() + mailbox_header_size);
  return m;
}

std::vector<std::uint8_t> mailbox_error_data(mailbox_error e) {
  std::vector<std::uint8_t> d;
  detail::put16(d, 0x0001);  // service: mailbox error
  detail::put16(d, static_cast<std::uint16_t>(e));
  return d;
}

std::optional<std::uint16_t> parse_mailbox_error(std::span<const std::uint8_t> data) noexcept {
  if (data.size() < 4) return std::nullopt;
  return detail::le16(data.data() + 2);
}

}  // namespace cia402::ethercat
