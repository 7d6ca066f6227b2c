#include "cia402/canopen/301/sdo_server.hpp"

#include <algorithm>

#include "cia402/canopen/can/frame.hpp"
#include "cia402/sdo_command.hpp"

namespace cia402::canopen {
namespace {

using namespace sdo_command_specifier;  // ccs_*, cs_abort: bits 5..7 of byte 0

}  // namespace

frame sdo_abort_frame(std::uint32_t cob_id, std::uint16_t index, std::uint8_t sub,
                      sdo_abort code) noexcept {
  frame f;
  f.id = cob_id;
  f.len = 8;
  f.data[0] = 0x80;
  put_le(&f.data[1], index, 2);
  f.data[3] = sub;
  put_le(&f.data[4], static_cast<std::uint32_t>(code), 4);
  return f;
}

void sdo_server::respond(std::uint8_t command, std::span<const std::uint8_t> data) {
  frame f;
  f.id = cob::sdo_tx + node_id_;
  f.len = 8;
  f.data[0] = command;
  std::copy(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(data.size(), 7)),
            f.data.begin() + 1);
  (void)out_->send(f);
}

void sdo_server::abort(std::uint16_t index, std::uint8_t sub, sdo_abort code) {
  (void)out_->send(sdo_abort_frame(cob::sdo_tx + node_id_, index, sub, code));
  mode_ = mode::idle;
}

bool sdo_server::segment_continues(mode open, std::uint8_t command) {
  if (mode_ != open) {
    // No transfer of this direction is open: the abort names no object unless another one is.
    abort(mode_ == mode::idle ? 0 : index_, mode_ == mode::idle ? 0 : sub_, sdo_abort::command_specifier_invalid);
    return false;
  }
  if (((command >> 4) & 1u) != toggle_) {
    abort(index_, sub_, sdo_abort::toggle_bit_not_alternated);
    return false;
  }
  return true;
}

void sdo_server::on_request(const frame& request) {
  if (request.len != 8 || request.rtr) return;
  const std::uint8_t* d = request.data.data();
  // Inside a block download the first byte is a sequence number, not a command: only an abort
  // (0x80, sequence number 0, which no segment has) ends it.
  if (mode_ == mode::block_downloading && d[0] != 0x80) {
    idle_us_ = 0;
    return block_download_segment(d);
  }
  const unsigned ccs = d[0] >> 5;
  const auto req_index = static_cast<std::uint16_t>(get_le(d + 1, 2));
  const std::uint8_t req_sub = d[3];
  idle_us_ = 0;

  switch (ccs) {
    case ccs_initiate_download: {
      mode_ = mode::idle;  // a new initiate replaces any transfer in progress
      const bool expedited = d[0] & 0x02;
      const bool size_indicated = d[0] & 0x01;
      if (expedited) {
        const std::size_t n = size_indicated ? 4 - ((d[0] >> 2) & 0x03) : 4;
        sdo_abort a = od_->check_download(req_index, req_sub, n, size_indicated);
        if (a == sdo_abort::none) {
          a = od_->download(req_index, req_sub, std::span<const std::uint8_t>(d + 4, n), size_indicated);
        }
        if (a != sdo_abort::none) return abort(req_index, req_sub, a);
        const std::uint8_t mux[3] = {d[1], d[2], d[3]};
        return respond(0x60, mux);
      }
      size_known_ = size_indicated;
      size_ = size_indicated ? static_cast<std::size_t>(get_le(d + 4, 4)) : 0;
      sdo_abort a = od_->check_download(req_index, req_sub, size_, size_known_);
      if (a == sdo_abort::none && size_known_ && size_ > max_download) {
        a = sdo_abort::data_type_length_too_high;
      }
      if (a != sdo_abort::none) return abort(req_index, req_sub, a);
      mode_ = mode::downloading;
      index_ = req_index;
      sub_ = req_sub;
      toggle_ = 0;
      buffer_.clear();
      const std::uint8_t mux[3] = {d[1], d[2], d[3]};
      return respond(0x60, mux);
    }
    case ccs_download_segment: {
      if (!segment_continues(mode::downloading, d[0])) return;
      const std::uint8_t t = toggle_;
      const std::size_t n = 7 - ((d[0] >> 1) & 0x07);
      buffer_.insert(buffer_.end(), d + 1, d + 1 + n);
      if (buffer_.size() > max_download || (size_known_ && buffer_.size() > size_)) {
        return abort(index_, sub_, size_known_ ? sdo_abort::data_type_length_mismatch
                                               : sdo_abort::data_type_length_too_high);
      }
      toggle_ ^= 1;
      if (d[0] & 0x01) {  // last segment
        if (size_known_ && buffer_.size() != size_) {
          return abort(index_, sub_, sdo_abort::data_type_length_mismatch);
        }
        sdo_abort a = size_known_ ? sdo_abort::none
                                  : od_->check_download(index_, sub_, buffer_.size(), true);
        if (a == sdo_abort::none) a = od_->download(index_, sub_, buffer_, true);
        if (a != sdo_abort::none) return abort(index_, sub_, a);
        mode_ = mode::idle;
      }
      return respond(static_cast<std::uint8_t>(0x20 | (t << 4)));
    }
    case ccs_initiate_upload: {
      mode_ = mode::idle;
      buffer_.clear();
      const sdo_abort a = od_->upload(req_index, req_sub, buffer_);
      if (a != sdo_abort::none) return abort(req_index, req_sub, a);
      if (!buffer_.empty() && buffer_.size() <= 4) {
        std::uint8_t payload[7] = {d[1], d[2], d[3], 0, 0, 0, 0};
        std::copy(buffer_.begin(), buffer_.end(), payload + 3);
        return respond(static_cast<std::uint8_t>(0x43 | ((4 - buffer_.size()) << 2)), payload);
      }
      mode_ = mode::uploading;
      index_ = req_index;
      sub_ = req_sub;
      toggle_ = 0;
      offset_ = 0;
      std::uint8_t payload[7] = {d[1], d[2], d[3], 0, 0, 0, 0};
      put_le(payload + 3, buffer_.size(), 4);
      return respond(0x41, payload);
    }
    case ccs_upload_segment: {
      if (!segment_continues(mode::uploading, d[0])) return;
      const std::uint8_t t = toggle_;
      const std::size_t n = std::min<std::size_t>(7, buffer_.size() - offset_);
      const bool last = offset_ + n == buffer_.size();
      const std::span<const std::uint8_t> part(buffer_.data() + offset_, n);
      offset_ += n;
      toggle_ ^= 1;
      if (last) mode_ = mode::idle;
      return respond(static_cast<std::uint8_t>((t << 4) | ((7 - n) << 1) | (last ? 1 : 0)), part);
    }
    case cs_abort:
      mode_ = mode::idle;
      return;
    case ccs_block_download: return block_download(d);
    case ccs_block_upload: return block_upload(d);
    default:  // 7
      mode_ = mode::idle;
      return abort(req_index, req_sub, sdo_abort::command_specifier_invalid);
  }
}

std::uint32_t sdo_server::process(std::uint32_t elapsed_us) noexcept {
  if (mode_ == mode::idle) return no_deadline;
  idle_us_ = elapsed_us >= timeout_us_ - std::min(idle_us_, timeout_us_) ? timeout_us_ : idle_us_ + elapsed_us;
  if (idle_us_ >= timeout_us_) {
    abort(index_, sub_, sdo_abort::sdo_protocol_timed_out);
    return no_deadline;
  }
  return timeout_us_ - idle_us_;
}

}  // namespace cia402::canopen
