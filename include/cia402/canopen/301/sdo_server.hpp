// SDO server (CiA 301 §7.2.4): expedited and segmented upload and download over one default SDO
// channel (requests on 0x600 + node-ID, responses on 0x580 + node-ID). Block transfer is not offered:
// its command specifiers are refused with 0x05040001. Every refused request gets an abort frame with
// the object dictionary's reason, and a transfer left idle for `timeout_us` is aborted with
// 0x05040000. Frames whose length is not 8 are ignored, as CiA 301 defines SDO frames as 8 bytes.
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
  enum class mode : std::uint8_t { idle, downloading, uploading };
  void respond(std::uint8_t command, std::span<const std::uint8_t> data = {});
  void abort(std::uint16_t index, std::uint8_t sub, sdo_abort code);
  // A segment continues the transfer open in direction `open` and alternates the toggle (CiA 301
  // §7.2.4.3.4); otherwise the transfer ends with the abort, and false.
  bool segment_continues(mode open, std::uint8_t command);

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
};

/// An SDO abort frame: 0x80, index, sub-index, code.
frame sdo_abort_frame(std::uint32_t cob_id, std::uint16_t index, std::uint8_t sub, sdo_abort code) noexcept;

}  // namespace cia402::canopen
