// The EtherCAT mailbox (ETG.1000.4 §5.6) and CANopen over EtherCAT (ETG.1000.6 §5.6): the slave side
// of SDO upload and download (expedited, normal and segmented, with complete access), SDO
// information (object list, object and entry descriptions, fragmented across mailboxes) and
// emergency messages. The values are the object dictionary's, through the same object_access the
// CANopen SDO server uses, so a value refused on CAN is refused here with the same abort code.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <span>
#include <vector>

#include "cia402/canopen/301/object_dictionary.hpp"
#include "cia402/canopen/301/sdo_server.hpp"

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

/// CoE services (the high nibble of the CoE header).
enum class coe_service : std::uint8_t {
  emergency = 1,
  sdo_request = 2,
  sdo_response = 3,
  sdo_information = 8,
};

inline constexpr std::size_t mailbox_header_size = 6;
inline constexpr std::size_t coe_header_size = 2;

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

/// What a slave's CoE does with the mailboxes the master writes. Replies queue up; the slave hands
/// the next one to the master whenever its send mailbox (SM1) is free.
class coe_server {
 public:
  /// Most replies that wait for the master; beyond it the oldest (emergencies first) are dropped
  /// and counted, so a master that never reads cannot grow the queue.
  static constexpr std::size_t max_queued = 16;
  /// Longest value a download may carry (as the CANopen server's).
  static constexpr std::size_t max_download = canopen::sdo_server::max_download;

  /// `mailbox_size` is the size of the send and receive mailboxes (SM0/SM1 length).
  coe_server(canopen::object_access& access, const canopen::object_dictionary& dictionary,
             std::uint16_t mailbox_size, std::uint16_t station_address = 0);

  /// One mailbox the master wrote. Anything that is not a sound CoE request gets a mailbox error
  /// reply (or an SDO abort), changes nothing and is counted in errors().
  void on_mailbox(std::span<const std::uint8_t> mailbox);
  /// Queues an emergency (error code, error register, five manufacturer bytes).
  void emergency(std::uint16_t code, std::uint8_t error_register, const std::array<std::uint8_t, 5>& data);

  bool has_reply() const noexcept { return !replies_.empty(); }
  /// The next reply, exactly mailbox_size bytes (zero padded); empty when none waits.
  std::vector<std::uint8_t> take_reply();
  std::size_t errors() const noexcept { return errors_; }
  std::size_t dropped() const noexcept { return dropped_; }
  /// Forgets transfers in progress and queued replies (a state change to INIT).
  void reset() noexcept;

 private:
  void on_sdo(std::span<const std::uint8_t> sdo);
  void on_sdo_information(std::span<const std::uint8_t> info);
  void upload(std::uint16_t index, std::uint8_t sub, bool complete);
  void download(std::span<const std::uint8_t> sdo);
  void download_segment(std::span<const std::uint8_t> sdo);
  void upload_segment(std::uint8_t command);
  void sdo_reply(std::span<const std::uint8_t> body);
  void abort(std::uint16_t index, std::uint8_t sub, sdo_abort code);
  void reply(mailbox_type type, std::span<const std::uint8_t> body);
  void mailbox_error_reply(mailbox_error e);
  sdo_abort upload_complete(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t>& out);
  sdo_abort download_complete(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data);
  std::size_t sdo_room() const noexcept { return mailbox_size_ - mailbox_header_size - coe_header_size; }

  canopen::object_access* access_;
  const canopen::object_dictionary* dictionary_;
  std::uint16_t mailbox_size_;
  std::uint16_t station_address_;
  std::uint8_t counter_ = 0;
  std::deque<std::vector<std::uint8_t>> replies_;
  std::size_t errors_ = 0;
  std::size_t dropped_ = 0;

  // A segmented transfer in progress.
  enum class transfer : std::uint8_t { none, downloading, uploading };
  transfer transfer_ = transfer::none;
  std::uint16_t index_ = 0;
  std::uint8_t sub_ = 0;
  bool complete_access_ = false;
  std::uint8_t toggle_ = 0;
  std::size_t size_ = 0;
  std::size_t offset_ = 0;
  std::vector<std::uint8_t> buffer_;
};

}  // namespace cia402::ethercat
