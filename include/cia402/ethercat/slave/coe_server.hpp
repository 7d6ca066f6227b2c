// The slave side of CANopen over EtherCAT (ETG.1000.6 §5.6): SDO upload and download (expedited,
// normal and segmented, with complete access), SDO information (object list, object and entry
// descriptions, fragmented across mailboxes) and emergency messages, over a CANopen object
// dictionary. The values go through the same object_access the CANopen SDO server uses
// (dictionary/dictionary_access.hpp), so a value refused on CAN is refused here with the same abort
// code. Every frame is read and written by the CoE codec (ethercat/coe).
#pragma once

#include <cstdint>
#include <deque>
#include <span>
#include <vector>

#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/dictionary/object_access.hpp"
#include "cia402/ethercat/coe/mailbox.hpp"
#include "cia402/ethercat/coe/sdo.hpp"
#include "cia402/ethercat/coe/sdo_information.hpp"

namespace cia402::ethercat {

/// What a slave's CoE does with the mailboxes the master writes. Replies queue up; the slave hands
/// the next one to the master whenever its send mailbox (SM1) is free.
class coe_server {
 public:
  /// Most replies that wait for the master; beyond it the oldest (emergencies first) are dropped
  /// and counted, so a master that never reads cannot grow the queue.
  static constexpr std::size_t max_queued = 16;
  /// Longest value a download may carry (as the CANopen server's).
  static constexpr std::size_t max_download = dictionary::max_download;

  /// `mailbox_size` is the size of the send and receive mailboxes (SM0/SM1 length).
  coe_server(dictionary::object_access& access, const dictionary::object_dictionary& dictionary,
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
  void on_sdo(std::span<const std::uint8_t> body);
  void on_sdo_information(std::span<const std::uint8_t> body);
  void upload(const sdo_frame& f);
  void download(const sdo_frame& f);
  void download_segment(const sdo_frame& f);
  void upload_segment(const sdo_frame& f);
  void abort(std::uint16_t index, std::uint8_t sub, sdo_abort code);
  void reply(mailbox_type type, std::span<const std::uint8_t> data);
  void mailbox_error_reply(mailbox_error e);
  void information_reply(sdo_info_opcode op, std::span<const std::uint8_t> data);
  std::vector<std::uint8_t> od_list(std::uint16_t list) const;
  sdo_abort upload_complete(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t>& out);
  sdo_abort download_complete(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data);

  dictionary::object_access* access_;
  const dictionary::object_dictionary* dictionary_;
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
  bool toggle_ = false;
  std::size_t size_ = 0;
  std::size_t offset_ = 0;
  std::vector<std::uint8_t> buffer_;
};

}  // namespace cia402::ethercat
