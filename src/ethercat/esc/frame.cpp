#include "cia402/ethercat/esc/frame.hpp"

#include <algorithm>

namespace cia402::ethercat {
namespace {

std::uint16_t le16(const std::uint8_t* p) noexcept { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
void put16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}

}  // namespace

const char* command_name(command c) noexcept {
  constexpr const char* names[] = {"NOP",  "APRD", "APWR", "APRW", "FPRD", "FPWR", "FPRW", "BRD",
                                   "BWR",  "BRW",  "LRD",  "LWR",  "LRW",  "ARMW", "FRMW"};
  const auto i = static_cast<std::size_t>(c);
  return i < sizeof names / sizeof names[0] ? names[i] : "?";
}

const char* frame_error_text(frame_error e) noexcept {
  switch (e) {
    case frame_error::none: return "no error";
    case frame_error::too_short: return "frame shorter than its headers";
    case frame_error::not_ethercat: return "not an EtherCAT frame (EtherType 0x88A4)";
    case frame_error::vlan_tagged: return "VLAN-tagged frame (not supported)";
    case frame_error::not_commands: return "EtherCAT header type is not 1 (datagrams)";
    case frame_error::length_mismatch: return "EtherCAT length runs past the frame";
    case frame_error::datagram_truncated: return "a datagram runs past the EtherCAT length";
    case frame_error::more_follows_past_end: return "a datagram says more follow, but the EtherCAT length ends";
    case frame_error::too_many_datagrams: return "more datagrams than a frame may carry";
  }
  return "?";
}

std::uint16_t datagram::working_counter() const noexcept { return le16(wkc); }
void datagram::set_working_counter(std::uint16_t v) noexcept { put16(wkc, v); }
void datagram::set_position(std::uint16_t adp) noexcept {
  put16(header + 2, adp);
  address = (address & 0xFFFF0000u) | adp;
}

frame_error parse_frame(std::span<std::uint8_t> frame, parsed_frame& out) noexcept {
  out.count = 0;
  if (frame.size() < ethernet_header_size + ethercat_header_size) return frame_error::too_short;
  // The EtherType travels big-endian, unlike everything inside the frame.
  const auto type = static_cast<std::uint16_t>((frame[12] << 8) | frame[13]);
  if (type == 0x8100 || type == 0x88A8) return frame_error::vlan_tagged;
  if (type != ethertype) return frame_error::not_ethercat;
  const std::uint16_t header = le16(frame.data() + ethernet_header_size);
  const std::size_t length = header & 0x07FFu;
  if ((header >> 12) != 1) return frame_error::not_commands;
  const std::size_t start = ethernet_header_size + ethercat_header_size;
  if (start + length > frame.size()) return frame_error::length_mismatch;
  const std::size_t end = start + length;
  std::size_t at = start;
  // Bounded: every datagram moves `at` forward by at least 12 bytes, and at most max_datagrams.
  for (;;) {
    if (out.count == max_datagrams) {
      out.count = 0;
      return frame_error::too_many_datagrams;
    }
    if (at + datagram_header_size > end) {
      // The first datagram must fit; a later one is here only because the one before said so.
      out.count = 0;
      return at == start ? frame_error::datagram_truncated : frame_error::more_follows_past_end;
    }
    datagram& d = out.datagrams[out.count];
    std::uint8_t* h = frame.data() + at;
    const std::uint16_t len_field = le16(h + 6);
    d.cmd = static_cast<command>(h[0]);
    d.index = h[1];
    d.address = le16(h + 2) | (static_cast<std::uint32_t>(le16(h + 4)) << 16);
    d.length = len_field & 0x07FFu;
    d.circulating = (len_field & 0x4000u) != 0;
    d.more = (len_field & 0x8000u) != 0;
    d.irq = le16(h + 8);
    d.header = h;
    if (at + datagram_header_size + d.length + working_counter_size > end) {
      out.count = 0;
      return frame_error::datagram_truncated;
    }
    d.data = h + datagram_header_size;
    d.wkc = d.data + d.length;
    ++out.count;
    at += datagram_header_size + d.length + working_counter_size;
    if (!d.more) break;
  }
  return frame_error::none;
}

frame_builder::frame_builder(const std::array<std::uint8_t, 6>& destination,
                             const std::array<std::uint8_t, 6>& source) {
  bytes_.reserve(maximum_frame_size);
  bytes_.insert(bytes_.end(), destination.begin(), destination.end());
  bytes_.insert(bytes_.end(), source.begin(), source.end());
  bytes_.push_back(0x88);
  bytes_.push_back(0xA4);
  bytes_.push_back(0);
  bytes_.push_back(0x10);  // type 1
}

long frame_builder::add(command cmd, std::uint8_t index, std::uint32_t address, std::span<const std::uint8_t> data,
                        std::uint16_t length) {
  length = static_cast<std::uint16_t>(length & 0x07FFu);
  if (bytes_.size() + datagram_header_size + length + working_counter_size > maximum_frame_size) return -1;
  if (last_header_ >= 0) {
    // The datagram before this one now has one following it.
    bytes_[static_cast<std::size_t>(last_header_) + 7] |= 0x80;
  }
  last_header_ = static_cast<long>(bytes_.size());
  std::uint8_t h[datagram_header_size] = {static_cast<std::uint8_t>(cmd), index};
  put16(h + 2, static_cast<std::uint16_t>(address));
  put16(h + 4, static_cast<std::uint16_t>(address >> 16));
  put16(h + 6, length);
  bytes_.insert(bytes_.end(), h, h + datagram_header_size);
  const long data_at = static_cast<long>(bytes_.size());
  const std::size_t given = std::min<std::size_t>(data.size(), length);
  bytes_.insert(bytes_.end(), data.begin(), data.begin() + static_cast<std::ptrdiff_t>(given));
  bytes_.resize(bytes_.size() + (length - given) + working_counter_size, 0);  // zeros, then the working counter
  return data_at;
}

std::vector<std::uint8_t> frame_builder::finish() const {
  std::vector<std::uint8_t> f = bytes_;
  const std::size_t length = f.size() - ethernet_header_size - ethercat_header_size;
  put16(f.data() + ethernet_header_size, static_cast<std::uint16_t>(length | 0x1000u));
  if (f.size() < minimum_frame_size) f.resize(minimum_frame_size, 0);
  return f;
}

}  // namespace cia402::ethercat
