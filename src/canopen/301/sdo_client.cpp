#include "cia402/canopen/301/sdo_client.hpp"

#include <algorithm>

#include "cia402/canopen/can/frame.hpp"
#include "cia402/canopen/301/sdo_server.hpp"
#include "cia402/sdo_command.hpp"

namespace cia402::canopen {

using namespace sdo_command_specifier;  // ccs_*, scs_*, cs_abort: bits 5..7 of byte 0

void sdo_client::send(const std::uint8_t (&bytes)[8]) {
  frame f;
  f.id = cob::sdo_rx + node_id_;
  f.len = 8;
  std::copy(std::begin(bytes), std::end(bytes), f.data.begin());
  waited_us_ = 0;
  (void)out_->send(f);
}

void sdo_client::fail(sdo_abort code, bool tell_server) {
  if (tell_server) (void)out_->send(sdo_abort_frame(cob::sdo_rx + node_id_, index_, sub_, code));
  abort_ = code;
  status_ = status::aborted;
  step_ = step::none;
}

void sdo_client::begin(std::uint16_t index, std::uint8_t sub, step first) noexcept {
  index_ = index;
  sub_ = sub;
  abort_ = sdo_abort::none;
  status_ = status::busy;
  step_ = first;
}

bool sdo_client::start_upload(std::uint16_t index, std::uint8_t sub) {
  if (status_ == status::busy) return false;
  begin(index, sub, step::upload_initiate);
  data_.clear();
  const std::uint8_t b[8] = {ccs_initiate_upload << 5, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8),
                             sub, 0, 0, 0, 0};
  send(b);
  return true;
}

bool sdo_client::start_download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> data,
                                bool segmented) {
  if (status_ == status::busy) return false;
  begin(index, sub, step::download_initiate);
  data_ = std::move(data);
  std::uint8_t b[8] = {0, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub,
                       0, 0, 0, 0};
  if (!segmented && !data_.empty() && data_.size() <= 4) {
    // expedited (bit 1) with its size indicated (bit 0): n = 4 - size in bits 2..3
    b[0] = static_cast<std::uint8_t>((ccs_initiate_download << 5) | 0x03 | ((4 - data_.size()) << 2));
    std::copy(data_.begin(), data_.end(), b + 4);
    offset_ = data_.size();
    expedited_ = true;
  } else {
    b[0] = (ccs_initiate_download << 5) | 0x01;  // segmented, its size in bytes 4..7
    put_le(b + 4, data_.size(), 4);
    offset_ = 0;
    expedited_ = false;
  }
  toggle_ = 0;
  send(b);
  return true;
}

bool sdo_client::start_download(std::uint16_t index, std::uint8_t sub, std::int64_t value,
                                unsigned bytes) {
  std::vector<std::uint8_t> d(bytes);
  put_le(d.data(), static_cast<std::uint64_t>(value), bytes);
  return start_download(index, sub, std::move(d));
}

void sdo_client::send_next_segment() {
  const std::size_t n = std::min<std::size_t>(7, data_.size() - offset_);
  const bool last = offset_ + n == data_.size();
  std::uint8_t b[8] = {static_cast<std::uint8_t>((toggle_ << 4) | ((7 - n) << 1) | (last ? 1 : 0)),
                       0, 0, 0, 0, 0, 0, 0};
  std::copy(data_.begin() + static_cast<std::ptrdiff_t>(offset_),
            data_.begin() + static_cast<std::ptrdiff_t>(offset_ + n), b + 1);
  offset_ += n;
  step_ = step::download_segment;
  send(b);
}

bool sdo_client::on_frame(const frame& f) {
  if (f.extended || f.rtr || f.id != cob::sdo_tx + node_id_ || f.len != 8) return false;
  if (status_ != status::busy) return true;
  const std::uint8_t* d = f.data.data();
  if (d[0] == cs_abort << 5) {
    if (static_cast<sdo_abort>(get_le(d + 4, 4)) == sdo_abort::command_specifier_invalid && fall_back()) return true;
    abort_ = static_cast<sdo_abort>(get_le(d + 4, 4));
    status_ = status::aborted;
    step_ = step::none;
    return true;
  }
  if (step_ >= step::block_upload_initiate) {
    on_block_frame(d);
    return true;
  }
  const unsigned scs = d[0] >> 5;
  const bool same_object = get_le(d + 1, 2) == index_ && d[3] == sub_;
  switch (step_) {
    case step::upload_initiate: {
      if (scs != scs_initiate_upload || !same_object) {
        fail(sdo_abort::command_specifier_invalid, true);
        break;
      }
      if (d[0] & 0x02) {  // expedited
        const std::size_t n = (d[0] & 0x01) ? 4 - ((d[0] >> 2) & 0x03) : 4;
        data_.assign(d + 4, d + 4 + n);
        status_ = status::done;
        step_ = step::none;
        break;
      }
      size_known_ = d[0] & 0x01;
      expected_ = size_known_ ? static_cast<std::size_t>(get_le(d + 4, 4)) : 0;
      toggle_ = 0;
      step_ = step::upload_segment;
      const std::uint8_t b[8] = {ccs_upload_segment << 5, 0, 0, 0, 0, 0, 0, 0};
      send(b);
      break;
    }
    case step::upload_segment: {
      if (scs != scs_upload_segment) {
        fail(sdo_abort::command_specifier_invalid, true);
        break;
      }
      if (((d[0] >> 4) & 1) != toggle_) {
        fail(sdo_abort::toggle_bit_not_alternated, true);
        break;
      }
      const std::size_t n = 7 - ((d[0] >> 1) & 0x07);
      data_.insert(data_.end(), d + 1, d + 1 + n);
      toggle_ ^= 1;
      if (d[0] & 0x01) {
        if (size_known_ && data_.size() != expected_) {
          fail(sdo_abort::data_type_length_mismatch, false);
        } else {
          status_ = status::done;
          step_ = step::none;
        }
        break;
      }
      const std::uint8_t b[8] = {static_cast<std::uint8_t>((ccs_upload_segment << 5) | (toggle_ << 4)), 0, 0, 0, 0, 0, 0, 0};
      send(b);
      break;
    }
    case step::download_initiate:
      if (scs != scs_initiate_download || !same_object) {
        fail(sdo_abort::command_specifier_invalid, true);
      } else if (expedited_) {
        status_ = status::done;  // expedited: the whole value went with the initiate
        step_ = step::none;
      } else {
        send_next_segment();
      }
      break;
    case step::download_segment:
      if (scs != scs_download_segment || ((d[0] >> 4) & 1) != toggle_) {
        fail(scs != scs_download_segment ? sdo_abort::command_specifier_invalid : sdo_abort::toggle_bit_not_alternated,
             true);
        break;
      }
      toggle_ ^= 1;
      if (offset_ == data_.size()) {
        status_ = status::done;
        step_ = step::none;
      } else {
        send_next_segment();
      }
      break;
    default: break;
  }
  return true;
}

std::uint32_t sdo_client::process(std::uint32_t elapsed_us) {
  if (status_ != status::busy) return no_deadline;
  waited_us_ = elapsed_us >= timeout_us_ - std::min(waited_us_, timeout_us_) ? timeout_us_
                                                                             : waited_us_ + elapsed_us;
  if (waited_us_ >= timeout_us_) {
    fail(sdo_abort::sdo_protocol_timed_out, true);
    return no_deadline;
  }
  return timeout_us_ - waited_us_;
}

void sdo_client::cancel() {
  if (status_ == status::busy) fail(sdo_abort::general_error, true);
}

std::int64_t sdo_client::value(bool is_signed) const noexcept {
  const unsigned n = static_cast<unsigned>(std::min<std::size_t>(data_.size(), 8));
  if (n == 0) return 0;
  const std::uint64_t raw = get_le(data_.data(), n);
  if (is_signed && n < 8) {
    const std::uint64_t sign = 1ull << (8 * n - 1);
    return static_cast<std::int64_t>((raw ^ sign) - sign);
  }
  return static_cast<std::int64_t>(raw);
}

}  // namespace cia402::canopen
