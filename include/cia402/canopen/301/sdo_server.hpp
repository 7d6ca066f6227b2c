// SDO server (CiA 301 §7.2.4): expedited, segmented and block upload and download over one default
// SDO channel (requests on 0x600 + node-ID, responses on 0x580 + node-ID). Block transfer
// with the CRC both sides offer, blocks of up to 127 segments, a segment out of
// sequence acknowledged at the last one in order (the client sends again from there), and the
// protocol switch threshold of an upload honoured (a value that short goes expedited or
// segmented). Every refused request gets an abort frame with the object dictionary's reason, and a
// transfer left idle for `timeout_us` is aborted with 0x05040000. Frames whose length is not 8 are
// ignored, as CiA 301 defines SDO frames as 8 bytes.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cia402/canopen/can/channel.hpp"
#include "cia402/canopen/301/timing.hpp"
#include "cia402/dictionary/object_access.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402::canopen {

class sdo_server {
 public:
  static constexpr std::size_t max_download = dictionary::max_download;

  sdo_server(dictionary::object_access& od, channel& out, std::uint8_t node_id,
             std::uint32_t timeout_us = 1000000) noexcept
      : od_(&od), out_(&out), node_id_(node_id), timeout_us_(timeout_us) {}

  /// One request frame (the caller has checked its identifier is 0x600 + node-ID).
  void on_request(const frame& request);
  /// Advances the transfer timeout; returns when it would expire.
  std::uint32_t process(std::uint32_t elapsed_us) noexcept;
  /// Drops any transfer without a word (NMT reset, stopped).
  void reset() noexcept { mode_ = mode::idle; }
  bool busy() const noexcept { return mode_ != mode::idle; }

 private:
  enum class mode : std::uint8_t {
    idle,
    downloading,
    uploading,
    block_downloading,    // segments of a block come
    block_download_end,   // the last block acknowledged: the end frame comes
    block_upload_start,   // the initiate answered: the client's start comes
    block_uploading,      // a block sent: its acknowledge comes
    block_upload_end,     // the end frame sent: its response comes
  };
  void respond(std::uint8_t command, std::span<const std::uint8_t> data = {});
  void abort(std::uint16_t index, std::uint8_t sub, sdo_abort code);
  // A segment continues the transfer open in direction `open` and alternates the toggle (CiA 301
  // §7.2.4.3.4); otherwise the transfer ends with the abort, and false.
  bool segment_continues(mode open, std::uint8_t command);
  // Block transfer (sdo_block.cpp).
  void block_download(const std::uint8_t* d);
  void block_download_segment(const std::uint8_t* d);
  void block_upload(const std::uint8_t* d);
  void send_upload_block();

  dictionary::object_access* od_;
  channel* out_;
  std::uint8_t node_id_;
  std::uint32_t timeout_us_;
  mode mode_ = mode::idle;
  std::uint16_t index_ = 0;
  std::uint8_t sub_ = 0;
  std::uint8_t toggle_ = 0;
  bool size_known_ = false;
  std::size_t size_ = 0;
  std::size_t offset_ = 0;
  std::uint32_t idle_us_ = 0;
  std::vector<std::uint8_t> buffer_;
  // Block transfer: the block size agreed, the last segment taken in order (download) or sent
  // (upload), where the block sent began, whether the CRC is used, whether the last segment came.
  std::uint8_t block_size_ = 0;
  std::uint8_t sequence_ = 0;
  std::size_t block_start_ = 0;
  bool crc_ = false;
  bool last_segment_ = false;
};

/// The CRC of a block transfer: CRC-16-CCITT, polynomial x^16 + x^12 + x^5 +
/// 1, initial value 0, no reflection.
std::uint16_t sdo_block_crc(std::span<const std::uint8_t> data) noexcept;
/// Segment `sequence` (1..127) of a block that starts its data at byte `at`: the sequence number,
/// flagged last when the segment holds the value's last byte (a value of no bytes is one empty last
/// segment), then up to 7 bytes. Both ends send segments this way; true when it is the last.
bool sdo_block_segment(std::span<const std::uint8_t> data, std::size_t at, std::uint8_t sequence,
                       std::uint8_t (&out)[8]) noexcept;
/// The bytes of the last segment that carry no data (n of a block transfer's end).
std::uint8_t sdo_block_unused(std::size_t size) noexcept;

/// An SDO abort frame: 0x80, index, sub-index, code.
frame sdo_abort_frame(std::uint32_t cob_id, std::uint16_t index, std::uint8_t sub, sdo_abort code) noexcept;

}  // namespace cia402::canopen
