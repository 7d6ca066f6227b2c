// SDO client (CiA 301 §7.2.4): one transfer at a time to one server, expedited, segmented or block,
// upload or download. Non-blocking: start a transfer, feed it the server's frames, give it time; it
// ends done or aborted (by the server's abort code, or 0x05040000 when the server stays silent). A
// block transfer asks for the CRC and checks it, acknowledges a block at the last
// segment it got in order (the server sends again from there), and falls back to the ordinary
// protocol when the server refuses block transfer (0x05040001), which it then does not ask again.
#pragma once

#include <cstdint>
#include <vector>

#include "cia402/canopen/can/channel.hpp"
#include "cia402/canopen/301/timing.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402::canopen {

class sdo_client {
 public:
  enum class status : std::uint8_t { idle, busy, done, aborted };

  sdo_client(channel& out, std::uint8_t node_id, std::uint32_t timeout_us = 500000) noexcept
      : out_(&out), node_id_(node_id), timeout_us_(timeout_us) {}

  /// Reads an object. False (and nothing sent) while another transfer runs.
  bool start_upload(std::uint16_t index, std::uint8_t sub);
  /// Writes bytes: expedited up to 4 bytes unless `segmented`, else segmented.
  bool start_download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> data,
                      bool segmented = false);
  /// Writes a number of `bytes` bytes, little-endian.
  bool start_download(std::uint16_t index, std::uint8_t sub, std::int64_t value, unsigned bytes);
  /// Reads an object by block upload in blocks of up to 127 segments; a value no longer than
  /// `switch_threshold` bytes the server may send as an ordinary upload.
  bool start_block_upload(std::uint16_t index, std::uint8_t sub, std::uint8_t switch_threshold = 0);
  /// Writes bytes by block download.
  bool start_block_download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> data);
  /// Bytes from which a value goes by block transfer where the caller knows its length: shorter
  /// ones take fewer frames segmented (a block costs 5 frames besides its segments, a segmented
  /// transfer one more for each of its 7-byte segments).
  static constexpr std::size_t block_from_bytes = 29;
  /// The server refused a block transfer (0x05040001) once: block transfers go the ordinary way.
  bool server_refuses_blocks() const noexcept { return no_blocks_; }

  /// A frame from the bus; true if it was this server's response.
  bool on_frame(const frame& f);
  /// Advances the timeout; returns when it would expire.
  std::uint32_t process(std::uint32_t elapsed_us);
  /// Ends the transfer at once and tells the server (abort 0x08000000 general error).
  void cancel();

  status state() const noexcept { return status_; }
  bool finished() const noexcept { return status_ == status::done || status_ == status::aborted; }
  sdo_abort abort_code() const noexcept { return abort_; }
  /// After a done upload: the bytes, and the value read little-endian (sign-extended if asked).
  const std::vector<std::uint8_t>& data() const noexcept { return data_; }
  std::int64_t value(bool is_signed = false) const noexcept;
  std::uint16_t index() const noexcept { return index_; }
  std::uint8_t sub() const noexcept { return sub_; }
  std::uint8_t node_id() const noexcept { return node_id_; }
  /// Back to idle after a finished transfer.
  void clear() noexcept { if (status_ != status::busy) status_ = status::idle; }

 private:
  enum class step : std::uint8_t { none, upload_initiate, upload_segment, download_initiate,
                                   download_segment, block_upload_initiate, block_upload_segments,
                                   block_upload_end, block_download_initiate, block_download_acknowledge,
                                   block_download_end };
  // A transfer of index:sub under way from `first` on.
  void begin(std::uint16_t index, std::uint8_t sub, step first) noexcept;
  void send(const std::uint8_t (&bytes)[8]);
  void fail(sdo_abort code, bool tell_server);
  void send_next_segment();
  // Block transfer (sdo_client_block.cpp): the server's frame in a block step.
  void on_block_frame(const std::uint8_t* d);
  void send_download_block();
  // A block transfer the server refused, done again the ordinary way; false when it was none.
  bool fall_back();

  channel* out_;
  std::uint8_t node_id_;
  std::uint32_t timeout_us_;
  status status_ = status::idle;
  step step_ = step::none;
  sdo_abort abort_ = sdo_abort::none;
  std::uint16_t index_ = 0;
  std::uint8_t sub_ = 0;
  std::uint8_t toggle_ = 0;
  std::size_t offset_ = 0;
  std::size_t expected_ = 0;
  bool size_known_ = false;
  bool expedited_ = false;
  std::uint32_t waited_us_ = 0;
  std::vector<std::uint8_t> data_;
  // Block transfer: the block size, the last segment taken in order (upload) or sent (download),
  // where the block sent began, whether the CRC is used, whether the last segment came or went.
  std::uint8_t block_size_ = 0;
  std::uint8_t sequence_ = 0;
  std::size_t block_start_ = 0;
  bool crc_ = false;
  bool last_segment_ = false;
  bool no_blocks_ = false;
};

}  // namespace cia402::canopen
