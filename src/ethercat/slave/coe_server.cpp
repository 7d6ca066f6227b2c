#include "cia402/ethercat/coe/mailbox.hpp"

#include <algorithm>
#include <cstring>

namespace cia402::ethercat {
namespace {

using canopen::access;
using canopen::data_type;
using canopen::object_code;
using canopen::object_entry;
using canopen::sub_entry;

std::uint16_t le16(const std::uint8_t* p) noexcept { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
std::uint32_t le32(const std::uint8_t* p) noexcept {
  return le16(p) | (static_cast<std::uint32_t>(le16(p + 2)) << 16);
}
void put16(std::vector<std::uint8_t>& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v));
  b.push_back(static_cast<std::uint8_t>(v >> 8));
}
void put32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  put16(b, static_cast<std::uint16_t>(v));
  put16(b, static_cast<std::uint16_t>(v >> 16));
}

// SDO command specifiers, as on CAN (CiA 301 §7.2.4.3); bit 4 of an initiate request is CoE's
// complete access.
constexpr std::uint8_t ccs_download_segment = 0;
constexpr std::uint8_t ccs_initiate_download = 1;
constexpr std::uint8_t ccs_initiate_upload = 2;
constexpr std::uint8_t ccs_upload_segment = 3;
constexpr std::uint8_t ccs_abort = 4;
constexpr std::uint8_t complete_access_bit = 0x10;

// SDO information opcodes (ETG.1000.6 §5.6.3).
constexpr std::uint8_t info_od_list_request = 1;
constexpr std::uint8_t info_od_list_response = 2;
constexpr std::uint8_t info_object_request = 3;
constexpr std::uint8_t info_object_response = 4;
constexpr std::uint8_t info_entry_request = 5;
constexpr std::uint8_t info_entry_response = 6;
constexpr std::uint8_t info_error = 7;

// Objects whose writes configure the process data: writable in PRE-OP only (ETG.1000.6).
bool pdo_configuration(std::uint16_t index) noexcept {
  return (index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF) ||
         index == 0x1C12 || index == 0x1C13;
}

// Object access word of an entry description: read in PRE-OP/SAFE-OP/OP (bits 0..2), write (3..5),
// RxPDO / TxPDO mappable (6, 7). A mappable object the master writes (a set-point) is an output,
// one it only reads (an actual value) an input.
std::uint16_t access_bits(std::uint16_t index, const sub_entry& e) noexcept {
  std::uint16_t bits = 0;
  if (canopen::readable(e.acc)) bits |= 0x0007;
  if (canopen::writable(e.acc)) bits |= static_cast<std::uint16_t>(pdo_configuration(index) ? 0x0008 : 0x0038);
  if (e.pdo_mappable && canopen::writable(e.acc)) bits |= 0x0040;
  if (e.pdo_mappable && !canopen::writable(e.acc)) bits |= 0x0080;
  return bits;
}

std::uint16_t bit_length(const sub_entry& e) noexcept {
  const unsigned size = canopen::type_size(e.type);
  if (size != 0) return static_cast<std::uint16_t>(size * 8);
  const std::size_t text = std::max(e.capacity, e.default_text.size());
  return static_cast<std::uint16_t>(std::min<std::size_t>(text, 8191) * 8);
}

}  // namespace

bool read_mailbox_header(std::span<const std::uint8_t> mailbox, mailbox_header& out) noexcept {
  if (mailbox.size() < mailbox_header_size) return false;
  out.length = le16(mailbox.data());
  out.address = le16(mailbox.data() + 2);
  out.channel = mailbox[4] & 0x3F;
  out.priority = static_cast<std::uint8_t>(mailbox[4] >> 6);
  out.type = static_cast<mailbox_type>(mailbox[5] & 0x0F);
  out.counter = static_cast<std::uint8_t>((mailbox[5] >> 4) & 0x07);
  return true;
}

void write_mailbox_header(const mailbox_header& h, std::uint8_t* p) noexcept {
  p[0] = static_cast<std::uint8_t>(h.length);
  p[1] = static_cast<std::uint8_t>(h.length >> 8);
  p[2] = static_cast<std::uint8_t>(h.address);
  p[3] = static_cast<std::uint8_t>(h.address >> 8);
  p[4] = static_cast<std::uint8_t>((h.channel & 0x3F) | (h.priority << 6));
  p[5] = static_cast<std::uint8_t>((static_cast<std::uint8_t>(h.type) & 0x0F) | ((h.counter & 0x07) << 4));
}

coe_server::coe_server(canopen::object_access& access, const canopen::object_dictionary& dictionary,
                       std::uint16_t mailbox_size, std::uint16_t station_address)
    : access_(&access),
      dictionary_(&dictionary),
      mailbox_size_(std::max<std::uint16_t>(mailbox_size, 32)),
      station_address_(station_address) {}

void coe_server::reset() noexcept {
  replies_.clear();
  transfer_ = transfer::none;
  buffer_.clear();
}

std::vector<std::uint8_t> coe_server::take_reply() {
  if (replies_.empty()) return {};
  std::vector<std::uint8_t> r = std::move(replies_.front());
  replies_.pop_front();
  return r;
}

void coe_server::reply(mailbox_type type, std::span<const std::uint8_t> body) {
  std::vector<std::uint8_t> m(mailbox_size_, 0);
  const std::size_t n = std::min<std::size_t>(body.size(), mailbox_size_ - mailbox_header_size);
  counter_ = static_cast<std::uint8_t>(counter_ % 7 + 1);  // 1..7; 0 is reserved
  mailbox_header h;
  h.length = static_cast<std::uint16_t>(n);
  h.address = station_address_;
  h.type = type;
  h.counter = counter_;
  write_mailbox_header(h, m.data());
  std::copy_n(body.begin(), n, m.begin() + mailbox_header_size);
  if (replies_.size() >= max_queued) {
    replies_.pop_front();
    ++dropped_;
  }
  replies_.push_back(std::move(m));
}

void coe_server::mailbox_error_reply(mailbox_error e) {
  ++errors_;
  std::vector<std::uint8_t> body;
  put16(body, 0x0001);  // service: mailbox error
  put16(body, static_cast<std::uint16_t>(e));
  reply(mailbox_type::error, body);
}

void coe_server::sdo_reply(std::span<const std::uint8_t> sdo) {
  std::vector<std::uint8_t> body;
  put16(body, static_cast<std::uint16_t>(static_cast<unsigned>(coe_service::sdo_response) << 12));
  body.insert(body.end(), sdo.begin(), sdo.end());
  reply(mailbox_type::coe, body);
}

void coe_server::abort(std::uint16_t index, std::uint8_t sub, sdo_abort code) {
  ++errors_;
  transfer_ = transfer::none;
  std::vector<std::uint8_t> sdo{static_cast<std::uint8_t>(ccs_abort << 5)};
  put16(sdo, index);
  sdo.push_back(sub);
  put32(sdo, static_cast<std::uint32_t>(code));
  sdo_reply(sdo);
}

void coe_server::emergency(std::uint16_t code, std::uint8_t error_register,
                           const std::array<std::uint8_t, 5>& data) {
  std::vector<std::uint8_t> body;
  put16(body, static_cast<std::uint16_t>(static_cast<unsigned>(coe_service::emergency) << 12));
  put16(body, code);
  body.push_back(error_register);
  body.insert(body.end(), data.begin(), data.end());
  reply(mailbox_type::coe, body);
}

void coe_server::on_mailbox(std::span<const std::uint8_t> mailbox) {
  mailbox_header h;
  if (!read_mailbox_header(mailbox, h)) return mailbox_error_reply(mailbox_error::size_too_short);
  if (h.length > mailbox.size() - mailbox_header_size) return mailbox_error_reply(mailbox_error::invalid_size);
  if (h.type != mailbox_type::coe) return mailbox_error_reply(mailbox_error::unsupported_protocol);
  if (h.length < coe_header_size) return mailbox_error_reply(mailbox_error::size_too_short);
  const std::span<const std::uint8_t> coe = mailbox.subspan(mailbox_header_size, h.length);
  const auto service = static_cast<coe_service>(coe[1] >> 4);
  const std::span<const std::uint8_t> rest = coe.subspan(coe_header_size);
  switch (service) {
    case coe_service::sdo_request: return on_sdo(rest);
    case coe_service::sdo_information: return on_sdo_information(rest);
    case coe_service::emergency:
    case coe_service::sdo_response: break;
  }
  mailbox_error_reply(mailbox_error::service_not_supported);
}

void coe_server::on_sdo(std::span<const std::uint8_t> sdo) {
  if (sdo.empty()) return mailbox_error_reply(mailbox_error::size_too_short);
  const std::uint8_t command = sdo[0];
  const std::uint8_t ccs = static_cast<std::uint8_t>(command >> 5);
  if (ccs == ccs_download_segment) return download_segment(sdo);
  if (ccs == ccs_upload_segment) return upload_segment(command);
  if (ccs == ccs_abort) {
    transfer_ = transfer::none;  // the master gave up: no answer (CiA 301)
    return;
  }
  if (sdo.size() < 8) return mailbox_error_reply(mailbox_error::size_too_short);
  const std::uint16_t index = le16(sdo.data() + 1);
  const std::uint8_t sub = sdo[3];
  const bool complete = (command & complete_access_bit) != 0;
  if (complete && sub > 1) return abort(index, sub, sdo_abort::unsupported_access);
  if (ccs == ccs_initiate_upload) return upload(index, sub, complete);
  if (ccs == ccs_initiate_download) return download(sdo);
  abort(index, sub, sdo_abort::command_specifier_invalid);
}

sdo_abort coe_server::upload_complete(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t>& out) {
  const object_entry* o = dictionary_->object(index);
  if (o == nullptr) return sdo_abort::object_does_not_exist;
  if (o->code == object_code::var) return sdo_abort::unsupported_access;
  out.clear();
  for (const sub_entry& e : o->subs) {
    if (e.sub < sub) continue;
    std::vector<std::uint8_t> bytes;
    if (const sdo_abort r = access_->upload(index, e.sub, bytes); r != sdo_abort::none) return r;
    out.insert(out.end(), bytes.begin(), bytes.end());
    // Sub-index 0 travels as 16 bits in a complete access (ETG.1000.6 §5.6.2).
    if (e.sub == 0) out.push_back(0);
  }
  return sdo_abort::none;
}

void coe_server::upload(std::uint16_t index, std::uint8_t sub, bool complete) {
  std::vector<std::uint8_t> value;
  const sdo_abort r = complete ? upload_complete(index, sub, value) : access_->upload(index, sub, value);
  if (r != sdo_abort::none) return abort(index, sub, r);
  std::vector<std::uint8_t> sdo;
  const std::uint8_t ca = complete ? complete_access_bit : 0;
  if (value.size() <= 4 && !complete) {
    // Expedited: the value in the four data bytes, n = 4 - size.
    sdo.push_back(static_cast<std::uint8_t>((ccs_initiate_upload << 5) | ((4 - value.size()) << 2) | 0x03));
    put16(sdo, index);
    sdo.push_back(sub);
    sdo.insert(sdo.end(), value.begin(), value.end());
    sdo.resize(8, 0);
    return sdo_reply(sdo);
  }
  // Normal: the size, then as much of the value as the mailbox holds; segments carry the rest.
  sdo.push_back(static_cast<std::uint8_t>((ccs_initiate_upload << 5) | ca | 0x01));
  put16(sdo, index);
  sdo.push_back(sub);
  put32(sdo, static_cast<std::uint32_t>(value.size()));
  const std::size_t first = std::min(value.size(), sdo_room() - sdo.size());
  sdo.insert(sdo.end(), value.begin(), value.begin() + static_cast<std::ptrdiff_t>(first));
  if (first < value.size()) {
    transfer_ = transfer::uploading;
    index_ = index;
    sub_ = sub;
    toggle_ = 0;
    buffer_ = std::move(value);
    offset_ = first;
  } else {
    transfer_ = transfer::none;
  }
  sdo_reply(sdo);
}

void coe_server::upload_segment(std::uint8_t command) {
  if (transfer_ != transfer::uploading) return abort(index_, sub_, sdo_abort::command_specifier_invalid);
  const std::uint8_t toggle = (command >> 4) & 1u;
  if (toggle != toggle_) return abort(index_, sub_, sdo_abort::toggle_bit_not_alternated);
  const std::size_t room = sdo_room() - 1;
  const std::size_t n = std::min(room, buffer_.size() - offset_);
  const bool last = offset_ + n == buffer_.size();
  std::vector<std::uint8_t> sdo;
  // n (bits 1..3) says how many of 7 bytes carry no data when fewer than 7 are sent.
  const unsigned unused = n < 7 ? static_cast<unsigned>(7 - n) : 0u;
  sdo.push_back(static_cast<std::uint8_t>((toggle << 4) | (unused << 1) | (last ? 1u : 0u)));
  sdo.insert(sdo.end(), buffer_.begin() + static_cast<std::ptrdiff_t>(offset_),
             buffer_.begin() + static_cast<std::ptrdiff_t>(offset_ + n));
  if (sdo.size() < 8) sdo.resize(8, 0);
  offset_ += n;
  toggle_ ^= 1u;
  if (last) transfer_ = transfer::none;
  sdo_reply(sdo);
}

sdo_abort coe_server::download_complete(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data) {
  const object_entry* o = dictionary_->object(index);
  if (o == nullptr) return sdo_abort::object_does_not_exist;
  if (o->code == object_code::var) return sdo_abort::unsupported_access;
  // Split the data by the entries' sizes first: a length that does not fit changes nothing.
  struct piece {
    std::uint8_t sub;
    std::span<const std::uint8_t> bytes;
  };
  std::vector<piece> pieces;
  std::size_t at = 0;
  for (const sub_entry& e : o->subs) {
    if (e.sub < sub) continue;
    const unsigned size = canopen::type_size(e.type);
    if (size == 0) return sdo_abort::unsupported_access;
    if (at + size > data.size()) break;  // a shorter download sets the first entries only
    pieces.push_back({e.sub, data.subspan(at, size)});
    at += size + (e.sub == 0 ? 1 : 0);
  }
  if (pieces.empty() || at < data.size()) return sdo_abort::data_type_length_mismatch;
  // Keep what is there, so a refused entry puts every earlier one back.
  std::vector<std::vector<std::uint8_t>> before(pieces.size());
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    if (const sdo_abort r = access_->upload(index, pieces[i].sub, before[i]); r != sdo_abort::none) {
      before[i].clear();
    }
  }
  // Sub-index 0 of a mapping or an assignment goes to 0 first and to its value last, as a master
  // writing entry by entry does.
  const bool counted = pieces.front().sub == 0;
  const std::uint8_t zero = 0;
  const auto put_back = [&] {
    if (counted) access_->download(index, 0, {&zero, 1}, true);
    for (std::size_t j = counted ? 1 : 0; j < pieces.size(); ++j) {
      if (!before[j].empty()) access_->download(index, pieces[j].sub, before[j], true);
    }
    if (counted && !before[0].empty()) access_->download(index, 0, before[0], true);
  };
  if (counted) {
    if (const sdo_abort r = access_->download(index, 0, {&zero, 1}, true); r != sdo_abort::none) return r;
  }
  for (std::size_t i = counted ? 1 : 0; i < pieces.size(); ++i) {
    if (const sdo_abort r = access_->download(index, pieces[i].sub, pieces[i].bytes, true); r != sdo_abort::none) {
      put_back();
      return r;
    }
  }
  if (counted) {
    if (const sdo_abort r = access_->download(index, 0, pieces.front().bytes, true); r != sdo_abort::none) {
      put_back();
      return r;
    }
  }
  return sdo_abort::none;
}

void coe_server::download(std::span<const std::uint8_t> sdo) {
  const std::uint8_t command = sdo[0];
  const std::uint16_t index = le16(sdo.data() + 1);
  const std::uint8_t sub = sdo[3];
  const bool complete = (command & complete_access_bit) != 0;
  const bool expedited = (command & 0x02) != 0;
  const bool size_indicated = (command & 0x01) != 0;
  transfer_ = transfer::none;
  if (expedited) {
    if (complete) return abort(index, sub, sdo_abort::unsupported_access);
    const std::size_t n = size_indicated ? 4 - ((command >> 2) & 3u) : 4;
    const std::span<const std::uint8_t> data = sdo.subspan(4, n);
    if (const sdo_abort r = access_->check_download(index, sub, n, size_indicated); r != sdo_abort::none) {
      return abort(index, sub, r);
    }
    if (const sdo_abort r = access_->download(index, sub, data, size_indicated); r != sdo_abort::none) {
      return abort(index, sub, r);
    }
  } else {
    if (!size_indicated) return abort(index, sub, sdo_abort::command_specifier_invalid);
    const std::size_t size = le32(sdo.data() + 4);
    if (size > max_download) return abort(index, sub, sdo_abort::out_of_memory);
    if (!complete) {
      if (const sdo_abort r = access_->check_download(index, sub, size, true); r != sdo_abort::none) {
        return abort(index, sub, r);
      }
    }
    const std::span<const std::uint8_t> first = sdo.subspan(8, std::min(size, sdo.size() - 8));
    if (first.size() < size) {
      // The rest follows in download segments.
      transfer_ = transfer::downloading;
      index_ = index;
      sub_ = sub;
      complete_access_ = complete;
      toggle_ = 0;
      size_ = size;
      buffer_.assign(first.begin(), first.end());
    } else {
      const sdo_abort r = complete ? download_complete(index, sub, first) : access_->download(index, sub, first, true);
      if (r != sdo_abort::none) return abort(index, sub, r);
    }
  }
  std::vector<std::uint8_t> reply{static_cast<std::uint8_t>(0x60 | (complete ? complete_access_bit : 0))};
  put16(reply, index);
  reply.push_back(sub);
  reply.resize(8, 0);
  sdo_reply(reply);
}

void coe_server::download_segment(std::span<const std::uint8_t> sdo) {
  if (transfer_ != transfer::downloading) return abort(index_, sub_, sdo_abort::command_specifier_invalid);
  const std::uint8_t command = sdo[0];
  const std::uint8_t toggle = (command >> 4) & 1u;
  if (toggle != toggle_) return abort(index_, sub_, sdo_abort::toggle_bit_not_alternated);
  const bool last = (command & 1u) != 0;
  std::size_t n = sdo.size() - 1;
  if (n <= 7) n = 7 - ((command >> 1) & 7u);
  n = std::min(n, sdo.size() - 1);
  if (buffer_.size() + n > size_) return abort(index_, sub_, sdo_abort::data_type_length_too_high);
  buffer_.insert(buffer_.end(), sdo.begin() + 1, sdo.begin() + 1 + static_cast<std::ptrdiff_t>(n));
  toggle_ ^= 1u;
  if (last) {
    transfer_ = transfer::none;
    if (buffer_.size() != size_) return abort(index_, sub_, sdo_abort::data_type_length_too_low);
    const sdo_abort r = complete_access_ ? download_complete(index_, sub_, buffer_)
                                         : access_->download(index_, sub_, buffer_, true);
    if (r != sdo_abort::none) return abort(index_, sub_, r);
  }
  std::vector<std::uint8_t> reply{static_cast<std::uint8_t>((1u << 5) | (toggle << 4))};
  reply.resize(8, 0);
  sdo_reply(reply);
}

void coe_server::on_sdo_information(std::span<const std::uint8_t> info) {
  if (info.size() < 4) return mailbox_error_reply(mailbox_error::size_too_short);
  const std::uint8_t opcode = info[0] & 0x7F;
  const std::span<const std::uint8_t> request = info.subspan(4);
  // Each response: the information header (opcode, incomplete bit, fragments left), then data that
  // is cut into as many mailboxes as it needs.
  const auto respond = [&](std::uint8_t op, const std::vector<std::uint8_t>& data) {
    const std::size_t room = sdo_room() - 4;
    const std::size_t fragments = data.empty() ? 1 : (data.size() + room - 1) / room;
    for (std::size_t f = 0; f < fragments; ++f) {
      std::vector<std::uint8_t> body;
      put16(body, static_cast<std::uint16_t>(static_cast<unsigned>(coe_service::sdo_information) << 12));
      const std::size_t left = fragments - 1 - f;
      body.push_back(static_cast<std::uint8_t>(op | (left > 0 ? 0x80 : 0)));
      body.push_back(0);
      put16(body, static_cast<std::uint16_t>(left));
      const std::size_t from = f * room;
      const std::size_t to = std::min(data.size(), from + room);
      body.insert(body.end(), data.begin() + static_cast<std::ptrdiff_t>(from),
                  data.begin() + static_cast<std::ptrdiff_t>(to));
      reply(mailbox_type::coe, body);
    }
  };
  const auto error = [&](sdo_abort code) {
    ++errors_;
    std::vector<std::uint8_t> data;
    put32(data, static_cast<std::uint32_t>(code));
    respond(info_error, data);
  };
  const std::vector<object_entry>& table = dictionary_->table();
  switch (opcode) {
    case info_od_list_request: {
      if (request.size() < 2) return error(sdo_abort::general_error);
      const std::uint16_t list = le16(request.data());
      const auto in_list = [&](const object_entry& o, std::uint16_t which) {
        const auto any = [&](auto pred) { return std::any_of(o.subs.begin(), o.subs.end(), pred); };
        switch (which) {
          case 1: return true;
          case 2: return any([](const sub_entry& e) { return e.pdo_mappable && canopen::writable(e.acc); });
          case 3: return any([](const sub_entry& e) { return e.pdo_mappable && !canopen::writable(e.acc); });
          default: return false;  // nothing is stored to backup memory or settings
        }
      };
      std::vector<std::uint8_t> data;
      put16(data, list);
      if (list == 0) {
        for (std::uint16_t which = 1; which <= 5; ++which) {
          put16(data, static_cast<std::uint16_t>(
                          std::count_if(table.begin(), table.end(), [&](const auto& o) { return in_list(o, which); })));
        }
      } else if (list <= 5) {
        for (const object_entry& o : table) {
          if (in_list(o, list)) put16(data, o.index);
        }
      } else {
        return error(sdo_abort::general_error);
      }
      return respond(info_od_list_response, data);
    }
    case info_object_request: {
      if (request.size() < 2) return error(sdo_abort::general_error);
      const object_entry* o = dictionary_->object(le16(request.data()));
      if (o == nullptr || o->subs.empty()) return error(sdo_abort::object_does_not_exist);
      std::vector<std::uint8_t> data;
      put16(data, o->index);
      const sub_entry& typed = o->subs.size() > 1 ? o->subs[1] : o->subs[0];
      put16(data, o->code == object_code::record ? 0 : static_cast<std::uint16_t>(typed.type));
      data.push_back(o->subs.back().sub);
      data.push_back(static_cast<std::uint8_t>(o->code));
      data.insert(data.end(), o->name.begin(), o->name.end());
      return respond(info_object_response, data);
    }
    case info_entry_request: {
      if (request.size() < 4) return error(sdo_abort::general_error);
      const std::uint16_t index = le16(request.data());
      const std::uint8_t sub = request[2];
      const object_entry* o = dictionary_->object(index);
      if (o == nullptr) return error(sdo_abort::object_does_not_exist);
      const auto e = std::find_if(o->subs.begin(), o->subs.end(), [&](const sub_entry& s) { return s.sub == sub; });
      if (e == o->subs.end()) return error(sdo_abort::sub_index_does_not_exist);
      std::vector<std::uint8_t> data;
      put16(data, index);
      data.push_back(sub);
      data.push_back(0);  // value info: name only (no unit, default, minimum or maximum)
      put16(data, static_cast<std::uint16_t>(e->type));
      put16(data, bit_length(*e));
      put16(data, access_bits(index, *e));
      data.insert(data.end(), e->name.begin(), e->name.end());
      return respond(info_entry_response, data);
    }
    default: break;
  }
  error(sdo_abort::command_specifier_invalid);
}

}  // namespace cia402::ethercat
