// The SDO server's block transfer (CiA 301 §7.2.4.3): block download and block upload with
// the CRC, blocks of up to 127 segments of 7 bytes, and the upload's protocol switch threshold.
// Every command and sequence number the client sends is checked against the state of the transfer;
// anything else ends it with an abort.
#include <algorithm>

#include "cia402/canopen/301/sdo_server.hpp"
#include "cia402/canopen/can/frame.hpp"

namespace cia402::canopen {
namespace {

constexpr std::uint8_t max_block_size = 127;
constexpr std::uint8_t last_segment_flag = 0x80;  // "c": no more segments
constexpr std::size_t segment_bytes = 7;

// The client's sub-commands (byte 0, bits 0..1) of a block transfer.
constexpr std::uint8_t cs_initiate = 0, cs_end = 1, cs_block_acknowledge = 2, cs_start_upload = 3;

}  // namespace

std::uint16_t sdo_block_crc(std::span<const std::uint8_t> data) noexcept {
  std::uint16_t crc = 0;
  for (const std::uint8_t byte : data) {
    crc = static_cast<std::uint16_t>(crc ^ (byte << 8));
    for (int bit = 0; bit < 8; ++bit) {
      crc = static_cast<std::uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1);
    }
  }
  return crc;
}

bool sdo_block_segment(std::span<const std::uint8_t> data, std::size_t at, std::uint8_t sequence,
                       std::uint8_t (&out)[8]) noexcept {
  const std::size_t n = at < data.size() ? std::min(segment_bytes, data.size() - at) : 0;
  const bool last = at + n >= data.size();
  std::fill(std::begin(out), std::end(out), std::uint8_t{0});
  out[0] = static_cast<std::uint8_t>(sequence | (last ? last_segment_flag : 0));
  std::copy(data.begin() + static_cast<std::ptrdiff_t>(std::min(at, data.size())),
            data.begin() + static_cast<std::ptrdiff_t>(std::min(at, data.size()) + n), out + 1);
  return last;
}

std::uint8_t sdo_block_unused(std::size_t size) noexcept {
  const std::size_t rest = size % segment_bytes;
  return static_cast<std::uint8_t>(size == 0 ? segment_bytes : (rest == 0 ? 0 : segment_bytes - rest));
}

void sdo_server::block_download(const std::uint8_t* d) {
  const auto index = static_cast<std::uint16_t>(get_le(d + 1, 2));
  const std::uint8_t sub = d[3];
  const std::uint8_t cs = d[0] & 0x01;
  if (cs == cs_initiate) {
    // 110 00 cc s 0: the client's CRC support, whether the size is given.
    mode_ = mode::idle;
    size_known_ = (d[0] & 0x02) != 0;
    size_ = size_known_ ? static_cast<std::size_t>(get_le(d + 4, 4)) : 0;
    sdo_abort a = od_->check_download(index, sub, size_, size_known_);
    if (a == sdo_abort::none && size_known_ && size_ > max_download) a = sdo_abort::data_type_length_too_high;
    if (a != sdo_abort::none) return abort(index, sub, a);
    mode_ = mode::block_downloading;
    index_ = index;
    sub_ = sub;
    crc_ = (d[0] & 0x04) != 0;  // this server offers the CRC: it is used when the client does too
    block_size_ = max_block_size;
    sequence_ = 0;
    last_segment_ = false;
    buffer_.clear();
    const std::uint8_t answer[7] = {d[1], d[2], d[3], block_size_, 0, 0, 0};
    return respond(0xA4, answer);  // 101 00 sc=1 0 ss=0
  }
  // 110 n 0 cs=1: the end, n bytes of the last segment carry no data, then the CRC.
  if (mode_ != mode::block_download_end) {
    return abort(mode_ == mode::idle ? 0 : index_, mode_ == mode::idle ? 0 : sub_, sdo_abort::command_specifier_invalid);
  }
  const std::size_t unused = (d[0] >> 2) & 0x07;
  if (unused > buffer_.size()) return abort(index_, sub_, sdo_abort::data_type_length_mismatch);
  buffer_.resize(buffer_.size() - unused);
  if (size_known_ && buffer_.size() != size_) return abort(index_, sub_, sdo_abort::data_type_length_mismatch);
  if (crc_ && static_cast<std::uint16_t>(get_le(d + 1, 2)) != sdo_block_crc(buffer_)) {
    return abort(index_, sub_, sdo_abort::crc_error);
  }
  sdo_abort a = size_known_ ? sdo_abort::none : od_->check_download(index_, sub_, buffer_.size(), true);
  if (a == sdo_abort::none) a = od_->download(index_, sub_, buffer_, true);
  if (a != sdo_abort::none) return abort(index_, sub_, a);
  mode_ = mode::idle;
  respond(0xA1);  // 101 000 ss=1
}

void sdo_server::block_download_segment(const std::uint8_t* d) {
  const std::uint8_t sequence = d[0] & 0x7F;
  const bool last = (d[0] & last_segment_flag) != 0;
  if (sequence == 0 || sequence > block_size_) return abort(index_, sub_, sdo_abort::invalid_sequence_number);
  // A segment in order is taken; one out of order (a lost frame before it) is not, and the block's
  // acknowledge names the last in order, from which the client sends again.
  if (sequence == sequence_ + 1 && !last_segment_) {
    buffer_.insert(buffer_.end(), d + 1, d + 1 + segment_bytes);
    sequence_ = sequence;
    last_segment_ = last;
    if (buffer_.size() > max_download + segment_bytes || (size_known_ && buffer_.size() > size_ + segment_bytes)) {
      return abort(index_, sub_, size_known_ ? sdo_abort::data_type_length_mismatch : sdo_abort::data_type_length_too_high);
    }
  }
  if (sequence != block_size_ && !last) return;  // the block goes on
  const std::uint8_t answer[7] = {sequence_, block_size_, 0, 0, 0, 0, 0};
  respond(0xA2, answer);  // 101 00 ss=2: acknowledge sequence, next block size
  if (last_segment_) {
    mode_ = mode::block_download_end;
  } else {
    sequence_ = 0;  // the next block counts from 1 again
  }
}

void sdo_server::block_upload(const std::uint8_t* d) {
  const std::uint8_t cs = d[0] & 0x03;
  const auto index = static_cast<std::uint16_t>(get_le(d + 1, 2));
  const std::uint8_t sub = d[3];
  switch (cs) {
    case cs_initiate: {
      // 101 00 cc 00, block size, protocol switch threshold.
      mode_ = mode::idle;
      const std::uint8_t block_size = d[4];
      const std::uint8_t threshold = d[5];
      if (block_size == 0 || block_size > max_block_size) return abort(index, sub, sdo_abort::invalid_block_size);
      buffer_.clear();
      const sdo_abort a = od_->upload(index, sub, buffer_);
      if (a != sdo_abort::none) return abort(index, sub, a);
      index_ = index;
      sub_ = sub;
      if (threshold != 0 && buffer_.size() <= threshold) {
        // Short enough for the client's threshold: the answer of an ordinary upload.
        if (!buffer_.empty() && buffer_.size() <= 4) {
          std::uint8_t payload[7] = {d[1], d[2], d[3], 0, 0, 0, 0};
          std::copy(buffer_.begin(), buffer_.end(), payload + 3);
          return respond(static_cast<std::uint8_t>(0x43 | ((4 - buffer_.size()) << 2)), payload);
        }
        mode_ = mode::uploading;
        toggle_ = 0;
        offset_ = 0;
        std::uint8_t payload[7] = {d[1], d[2], d[3], 0, 0, 0, 0};
        put_le(payload + 3, buffer_.size(), 4);
        return respond(0x41, payload);
      }
      mode_ = mode::block_upload_start;
      crc_ = (d[0] & 0x04) != 0;
      block_size_ = block_size;
      offset_ = 0;
      std::uint8_t payload[7] = {d[1], d[2], d[3], 0, 0, 0, 0};
      put_le(payload + 3, buffer_.size(), 4);
      return respond(0xC6, payload);  // 110 00 sc=1 s=1 ss=0, the size
    }
    case cs_start_upload:
      if (mode_ != mode::block_upload_start) break;
      mode_ = mode::block_uploading;
      return send_upload_block();
    case cs_block_acknowledge: {
      if (mode_ != mode::block_uploading) break;
      // 101 00 cs=2, the last segment received in order, the next block size.
      const std::uint8_t acknowledged = d[1];
      const std::uint8_t block_size = d[2];
      if (acknowledged > sequence_) return abort(index_, sub_, sdo_abort::invalid_sequence_number);
      if (block_size == 0 || block_size > max_block_size) return abort(index_, sub_, sdo_abort::invalid_block_size);
      block_size_ = block_size;
      offset_ = std::min(buffer_.size(), block_start_ + std::size_t{acknowledged} * segment_bytes);
      if (acknowledged == sequence_ && last_segment_) {
        // Everything acknowledged: the end, with the bytes of the last segment that carry no data.
        const std::size_t unused = sdo_block_unused(buffer_.size());
        std::uint8_t payload[7] = {0, 0, 0, 0, 0, 0, 0};
        put_le(payload, crc_ ? sdo_block_crc(buffer_) : 0u, 2);
        mode_ = mode::block_upload_end;
        return respond(static_cast<std::uint8_t>(0xC1 | (unused << 2)), payload);  // 110 n 0 ss=1
      }
      return send_upload_block();  // the next block, or this one again from the first not received
    }
    case cs_end:
      if (mode_ != mode::block_upload_end) break;
      mode_ = mode::idle;
      return;
    default: break;
  }
  abort(mode_ == mode::idle ? index : index_, mode_ == mode::idle ? sub : sub_, sdo_abort::command_specifier_invalid);
}

void sdo_server::send_upload_block() {
  // Up to block_size_ segments from offset_, the one that holds the last byte flagged; a value of
  // no bytes is one empty last segment.
  block_start_ = offset_;
  sequence_ = 0;
  last_segment_ = false;
  while (sequence_ < block_size_ && !last_segment_) {
    std::uint8_t segment[8];
    const std::size_t at = offset_ + std::size_t{sequence_} * segment_bytes;
    last_segment_ = sdo_block_segment(buffer_, at, ++sequence_, segment);
    frame f;
    f.id = cob::sdo_tx + node_id_;
    f.len = 8;
    std::copy(std::begin(segment), std::end(segment), f.data.begin());
    (void)out_->send(f);
  }
}

}  // namespace cia402::canopen
