// The SDO client's block transfer (CiA 301 §7.2.4.3): block upload and block download with
// the CRC. Every frame the server sends is checked against the step of the transfer; a block the
// client did not get whole is acknowledged at its last segment in order.
#include <algorithm>

#include "cia402/canopen/301/sdo_client.hpp"
#include "cia402/canopen/301/sdo_server.hpp"
#include "cia402/canopen/can/frame.hpp"

namespace cia402::canopen {
namespace {

constexpr std::uint8_t max_block_size = 127;
constexpr std::uint8_t last_segment_flag = 0x80;
constexpr std::size_t segment_bytes = 7;

}  // namespace

bool sdo_client::start_block_upload(std::uint16_t index, std::uint8_t sub, std::uint8_t switch_threshold) {
  if (no_blocks_) return start_upload(index, sub);
  if (status_ == status::busy) return false;
  begin(index, sub, step::block_upload_initiate);
  data_.clear();
  // 101 00 cc=1 00: the CRC asked for; the block size; the protocol switch threshold.
  const std::uint8_t b[8] = {0xA4, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub,
                             max_block_size, switch_threshold, 0, 0};
  send(b);
  return true;
}

bool sdo_client::start_block_download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> data) {
  if (no_blocks_) return start_download(index, sub, std::move(data), true);
  if (status_ == status::busy) return false;
  begin(index, sub, step::block_download_initiate);
  data_ = std::move(data);
  // 110 00 cc=1 s=1 0, the size.
  std::uint8_t b[8] = {0xC6, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub, 0, 0, 0, 0};
  put_le(b + 4, data_.size(), 4);
  offset_ = 0;
  send(b);
  return true;
}

bool sdo_client::fall_back() {
  if (step_ != step::block_upload_initiate && step_ != step::block_download_initiate) return false;
  no_blocks_ = true;
  status_ = status::idle;
  if (step_ == step::block_upload_initiate) return start_upload(index_, sub_);
  return start_download(index_, sub_, std::move(data_), true);
}

void sdo_client::on_block_frame(const std::uint8_t* d) {
  const bool same_object = get_le(d + 1, 2) == index_ && d[3] == sub_;
  switch (step_) {
    case step::block_upload_initiate: {
      if ((d[0] & 0xE0) == 0x40) {
        // The server switched to the ordinary protocol (the value is within the threshold).
        step_ = step::upload_initiate;
        frame f;
        f.id = cob::sdo_tx + node_id_;
        f.len = 8;
        std::copy(d, d + 8, f.data.begin());
        (void)on_frame(f);
        return;
      }
      // 110 00 sc s 0, the size.
      if ((d[0] & 0xE1) != 0xC0 || !same_object) return fail(sdo_abort::command_specifier_invalid, true);
      crc_ = (d[0] & 0x04) != 0;
      size_known_ = (d[0] & 0x02) != 0;
      expected_ = size_known_ ? static_cast<std::size_t>(get_le(d + 4, 4)) : 0;
      sequence_ = 0;
      last_segment_ = false;
      step_ = step::block_upload_segments;
      const std::uint8_t b[8] = {0xA3, 0, 0, 0, 0, 0, 0, 0};  // start
      return send(b);
    }
    case step::block_upload_segments: {
      const std::uint8_t sequence = d[0] & 0x7F;
      const bool last = (d[0] & last_segment_flag) != 0;
      if (sequence == 0 || sequence > max_block_size) return fail(sdo_abort::invalid_sequence_number, true);
      if (sequence == sequence_ + 1 && !last_segment_) {
        data_.insert(data_.end(), d + 1, d + 1 + segment_bytes);
        sequence_ = sequence;
        last_segment_ = last;
        if (data_.size() > (size_known_ ? expected_ : 1u << 20) + segment_bytes) {
          return fail(sdo_abort::data_type_length_mismatch, true);
        }
      }
      if (sequence != max_block_size && !last) return;
      const std::uint8_t b[8] = {0xA2, sequence_, max_block_size, 0, 0, 0, 0, 0};  // acknowledge
      if (last_segment_) {
        step_ = step::block_upload_end;
      } else {
        sequence_ = 0;
      }
      return send(b);
    }
    case step::block_upload_end: {
      // 110 n 0 ss=1, the CRC.
      if ((d[0] & 0xE3) != 0xC1) return fail(sdo_abort::command_specifier_invalid, true);
      const std::size_t unused = (d[0] >> 2) & 0x07;
      if (unused > data_.size()) return fail(sdo_abort::data_type_length_mismatch, true);
      data_.resize(data_.size() - unused);
      if (size_known_ && data_.size() != expected_) return fail(sdo_abort::data_type_length_mismatch, true);
      if (crc_ && static_cast<std::uint16_t>(get_le(d + 1, 2)) != sdo_block_crc(data_)) {
        return fail(sdo_abort::crc_error, true);
      }
      const std::uint8_t b[8] = {0xA1, 0, 0, 0, 0, 0, 0, 0};
      send(b);
      status_ = status::done;
      step_ = step::none;
      return;
    }
    case step::block_download_initiate: {
      // 101 00 sc 0 ss=0, the block size.
      if ((d[0] & 0xE3) != 0xA0 || !same_object) return fail(sdo_abort::command_specifier_invalid, true);
      if (d[4] == 0 || d[4] > max_block_size) return fail(sdo_abort::invalid_block_size, true);
      crc_ = (d[0] & 0x04) != 0;
      block_size_ = d[4];
      return send_download_block();
    }
    case step::block_download_acknowledge: {
      // 101 00 ss=2, the last segment received in order, the next block size.
      if ((d[0] & 0xE3) != 0xA2) return fail(sdo_abort::command_specifier_invalid, true);
      if (d[1] > sequence_) return fail(sdo_abort::invalid_sequence_number, true);
      if (d[2] == 0 || d[2] > max_block_size) return fail(sdo_abort::invalid_block_size, true);
      offset_ = std::min(data_.size(), block_start_ + std::size_t{d[1]} * segment_bytes);
      block_size_ = d[2];
      if (d[1] == sequence_ && last_segment_) {
        const std::size_t unused = sdo_block_unused(data_.size());
        std::uint8_t b[8] = {static_cast<std::uint8_t>(0xC1 | (unused << 2)), 0, 0, 0, 0, 0, 0, 0};
        put_le(b + 1, crc_ ? sdo_block_crc(data_) : 0u, 2);
        step_ = step::block_download_end;
        return send(b);
      }
      return send_download_block();
    }
    case step::block_download_end:
      if ((d[0] & 0xE3) != 0xA1) return fail(sdo_abort::command_specifier_invalid, true);
      status_ = status::done;
      step_ = step::none;
      return;
    default: return;
  }
}

void sdo_client::send_download_block() {
  block_start_ = offset_;
  sequence_ = 0;
  last_segment_ = false;
  while (sequence_ < block_size_ && !last_segment_) {
    std::uint8_t segment[8];
    const std::size_t at = offset_ + std::size_t{sequence_} * segment_bytes;
    last_segment_ = sdo_block_segment(data_, at, ++sequence_, segment);
    send(segment);
  }
  step_ = step::block_download_acknowledge;
}

}  // namespace cia402::canopen
