// The EtherCAT mailbox (ETG.1000.4 §5.6, ETG.1000.6 §5.6.1): the 6-byte header every mailbox starts
// with, the mailbox types, and the mailbox error reply. Part of the CoE codec, which both the master
// (ethercat/master) and the slave (ethercat/slave) use: no other file reads or writes a mailbox byte
// by byte. Links only the core; nothing here allocates but the builders that return a vector.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace cia402::ethercat {

/// Mailbox types (the low nibble of header byte 5).
enum class mailbox_type : std::uint8_t { error = 0, aoe = 1, eoe = 2, coe = 3, foe = 4, soe = 5, voe = 15 };

/// Mailbox error reply codes (ETG.1000.4 table 30).
enum class mailbox_error : std::uint16_t {
  syntax = 0x0001,
  unsupported_protocol = 0x0002,
  invalid_channel = 0x0003,
  service_not_supported = 0x0004,
  invalid_header = 0x0005,
  size_too_short = 0x0006,
  no_more_memory = 0x0007,
  invalid_size = 0x0008,
};

inline constexpr std::size_t mailbox_header_size = 6;

/// A mailbox header as it travels: data length after the header, station address, channel and
/// priority, type and the 1..7 counter.
struct mailbox_header {
  std::uint16_t length = 0;
  std::uint16_t address = 0;
  std::uint8_t channel = 0;
  std::uint8_t priority = 0;
  mailbox_type type = mailbox_type::error;
  std::uint8_t counter = 0;
};

bool read_mailbox_header(std::span<const std::uint8_t> mailbox, mailbox_header& out) noexcept;
void write_mailbox_header(const mailbox_header& h, std::uint8_t* six_bytes) noexcept;

/// The next mailbox counter after `c` (1..7; 0 is reserved, ETG.1000.4 §5.6).
constexpr std::uint8_t next_mailbox_counter(std::uint8_t c) noexcept {
  return static_cast<std::uint8_t>(c % 7 + 1);
}

/// A mailbox as read: its header and the `header.length` bytes of data after it.
struct mailbox_view {
  mailbox_header header;
  std::span<const std::uint8_t> data;
};

/// A mailbox a peer wrote, checked before any field after the header is read: nothing when it is
/// shorter than a header or than the length its header claims. Bytes after the length are padding.
std::optional<mailbox_view> parse_mailbox(std::span<const std::uint8_t> mailbox) noexcept;

/// A whole mailbox of `size` bytes: `h` with its length set to data's, then `data`, zero padded (the
/// last byte hands a mailbox over). Empty when the header and data do not fit `size`.
std::vector<std::uint8_t> make_mailbox(mailbox_header h, std::span<const std::uint8_t> data, std::size_t size);

/// The data of a mailbox error reply (type error, ETG.1000.4 table 29): service 1, then the code.
std::vector<std::uint8_t> mailbox_error_data(mailbox_error e);
/// The code of a mailbox error reply's data; nothing when the data does not hold one.
std::optional<std::uint16_t> parse_mailbox_error(std::span<const std::uint8_t> data) noexcept;

}  // namespace cia402::ethercat
