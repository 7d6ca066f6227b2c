#include "cia402/ethercat/slave/coe_server.hpp"

#include <algorithm>

namespace cia402::ethercat {
namespace {

using dictionary::object_code;
using dictionary::object_entry;
using dictionary::sub_entry;

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
  if (dictionary::readable(e.acc)) bits |= 0x0007;
  if (dictionary::writable(e.acc)) bits |= static_cast<std::uint16_t>(pdo_configuration(index) ? 0x0008 : 0x0038);
  if (e.pdo_mappable && dictionary::writable(e.acc)) bits |= 0x0040;
  if (e.pdo_mappable && !dictionary::writable(e.acc)) bits |= 0x0080;
  return bits;
}

std::uint16_t bit_length(const sub_entry& e) noexcept {
  const unsigned size = type_size(e.type);
  if (size != 0) return static_cast<std::uint16_t>(size * 8);
  const std::size_t text = std::max(e.capacity, e.default_text.size());
  return static_cast<std::uint16_t>(std::min<std::size_t>(text, 8191) * 8);
}

// Which objects an OD list names (ETG.1000.6 table 42): all, RxPDO-mappable, TxPDO-mappable; none is
// stored to backup memory or taken as a setting.
bool in_list(const object_entry& o, std::uint16_t list) noexcept {
  const auto any = [&](auto pred) { return std::any_of(o.subs.begin(), o.subs.end(), pred); };
  switch (list) {
    case 1: return true;
    case 2: return any([](const sub_entry& e) { return e.pdo_mappable && dictionary::writable(e.acc); });
    case 3: return any([](const sub_entry& e) { return e.pdo_mappable && !dictionary::writable(e.acc); });
    default: return false;
  }
}

std::vector<std::uint8_t> le32_bytes(std::uint32_t v) {
  return {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v >> 16),
          static_cast<std::uint8_t>(v >> 24)};
}

// The data type an object description gives a RECORD (ETG.1000.6's complex types, as the ETG's
// slave code numbers them): identity 0x0023, PDO mapping 0x0021, sync manager parameter 0x0029, any
// other record 0x002A. An ARRAY gives the type of its elements, a VAR its own.
std::uint16_t record_data_type(std::uint16_t index) noexcept {
  if (index == 0x1018) return 0x0023;
  if ((index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF)) return 0x0021;
  if (index >= 0x1C30 && index <= 0x1C4F) return 0x0029;
  return 0x002A;
}

}  // namespace

coe_server::coe_server(dictionary::object_access& access, const dictionary::object_dictionary& dictionary,
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

void coe_server::reply(mailbox_type type, std::span<const std::uint8_t> data) {
  counter_ = next_mailbox_counter(counter_);
  mailbox_header h;
  h.address = station_address_;
  h.type = type;
  h.counter = counter_;
  const std::size_t n = std::min<std::size_t>(data.size(), mailbox_size_ - mailbox_header_size);
  if (replies_.size() >= max_queued) {
    replies_.pop_front();
    ++dropped_;
  }
  replies_.push_back(make_mailbox(h, data.first(n), mailbox_size_));
}

void coe_server::mailbox_error_reply(mailbox_error e) {
  ++errors_;
  reply(mailbox_type::error, mailbox_error_data(e));
}

void coe_server::abort(std::uint16_t index, std::uint8_t sub, sdo_abort code) {
  ++errors_;
  transfer_ = transfer::none;
  reply(mailbox_type::coe, sdo_abort_request(index, sub, static_cast<std::uint32_t>(code)));
}

void coe_server::emergency(std::uint16_t code, std::uint8_t error_register,
                           const std::array<std::uint8_t, 5>& data) {
  reply(mailbox_type::coe, emergency_request({code, error_register, data}));
}

void coe_server::on_mailbox(std::span<const std::uint8_t> mailbox) {
  mailbox_header h;
  if (!read_mailbox_header(mailbox, h)) return mailbox_error_reply(mailbox_error::size_too_short);
  const std::optional<mailbox_view> m = parse_mailbox(mailbox);
  if (!m) return mailbox_error_reply(mailbox_error::invalid_size);
  if (h.type != mailbox_type::coe) return mailbox_error_reply(mailbox_error::unsupported_protocol);
  const std::optional<coe_view> c = parse_coe(m->data);
  if (!c) return mailbox_error_reply(mailbox_error::size_too_short);
  switch (c->service) {
    case coe_service::sdo_request: return on_sdo(c->body);
    case coe_service::sdo_information: return on_sdo_information(c->body);
    default: break;
  }
  mailbox_error_reply(mailbox_error::service_not_supported);
}

void coe_server::on_sdo(std::span<const std::uint8_t> body) {
  const std::optional<sdo_frame> f = parse_sdo_request(body);
  if (!f) return mailbox_error_reply(mailbox_error::size_too_short);
  switch (f->command) {
    case sdo_command::download_segment: return download_segment(*f);
    case sdo_command::upload_segment: return upload_segment(*f);
    case sdo_command::abort: transfer_ = transfer::none; return;  // the master gave up: no answer (CiA 301)
    case sdo_command::other: return abort(f->index, f->sub, sdo_abort::command_specifier_invalid);
    case sdo_command::initiate_upload:
    case sdo_command::initiate_download: break;
  }
  if (f->complete_access && f->sub > 1) return abort(f->index, f->sub, sdo_abort::unsupported_access);
  if (f->command == sdo_command::initiate_upload) return upload(*f);
  download(*f);
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

void coe_server::upload(const sdo_frame& f) {
  std::vector<std::uint8_t> value;
  const sdo_abort r = f.complete_access ? upload_complete(f.index, f.sub, value) : access_->upload(f.index, f.sub, value);
  if (r != sdo_abort::none) return abort(f.index, f.sub, r);
  if (!value.empty() && value.size() <= 4 && !f.complete_access) {
    return reply(mailbox_type::coe, sdo_upload_expedited_response(f.index, f.sub, value));
  }
  // Normal: the size, then as much of the value as the mailbox holds; segments carry the rest. An
  // empty value (a string) is a normal upload of size 0: expedited frames carry 1 to 4 bytes.
  const std::size_t first = std::min(value.size(), sdo_initiate_room(mailbox_size_));
  const std::vector<std::uint8_t> response = sdo_upload_normal_response(
      f.index, f.sub, f.complete_access, static_cast<std::uint32_t>(value.size()), std::span(value).first(first));
  if (first < value.size()) {
    transfer_ = transfer::uploading;
    index_ = f.index;
    sub_ = f.sub;
    toggle_ = false;
    buffer_ = std::move(value);
    offset_ = first;
  } else {
    transfer_ = transfer::none;
  }
  reply(mailbox_type::coe, response);
}

void coe_server::upload_segment(const sdo_frame& f) {
  if (transfer_ != transfer::uploading) return abort(index_, sub_, sdo_abort::command_specifier_invalid);
  if (f.toggle != toggle_) return abort(index_, sub_, sdo_abort::toggle_bit_not_alternated);
  const std::size_t n = std::min(sdo_segment_room(mailbox_size_), buffer_.size() - offset_);
  const bool last = offset_ + n == buffer_.size();
  const std::vector<std::uint8_t> response =
      sdo_upload_segment_response(f.toggle, last, std::span(buffer_).subspan(offset_, n));
  offset_ += n;
  toggle_ = !toggle_;
  if (last) transfer_ = transfer::none;
  reply(mailbox_type::coe, response);
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
    const unsigned size = type_size(e.type);
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

void coe_server::download(const sdo_frame& f) {
  transfer_ = transfer::none;
  if (f.expedited) {
    if (f.complete_access) return abort(f.index, f.sub, sdo_abort::unsupported_access);
    if (const sdo_abort r = access_->check_download(f.index, f.sub, f.data.size(), f.size_indicated); r != sdo_abort::none) {
      return abort(f.index, f.sub, r);
    }
    if (const sdo_abort r = access_->download(f.index, f.sub, f.data, f.size_indicated); r != sdo_abort::none) {
      return abort(f.index, f.sub, r);
    }
  } else {
    if (!f.size_indicated) return abort(f.index, f.sub, sdo_abort::command_specifier_invalid);
    if (f.size > max_download) return abort(f.index, f.sub, sdo_abort::out_of_memory);
    if (!f.complete_access) {
      if (const sdo_abort r = access_->check_download(f.index, f.sub, f.size, true); r != sdo_abort::none) {
        return abort(f.index, f.sub, r);
      }
    }
    if (f.data.size() < f.size) {
      // The rest follows in download segments.
      transfer_ = transfer::downloading;
      index_ = f.index;
      sub_ = f.sub;
      complete_access_ = f.complete_access;
      toggle_ = false;
      size_ = f.size;
      buffer_.assign(f.data.begin(), f.data.end());
    } else {
      const sdo_abort r = f.complete_access ? download_complete(f.index, f.sub, f.data)
                                            : access_->download(f.index, f.sub, f.data, true);
      if (r != sdo_abort::none) return abort(f.index, f.sub, r);
    }
  }
  reply(mailbox_type::coe, sdo_download_response(f.index, f.sub, f.complete_access));
}

void coe_server::download_segment(const sdo_frame& f) {
  if (transfer_ != transfer::downloading) return abort(index_, sub_, sdo_abort::command_specifier_invalid);
  if (f.toggle != toggle_) return abort(index_, sub_, sdo_abort::toggle_bit_not_alternated);
  if (buffer_.size() + f.data.size() > size_) return abort(index_, sub_, sdo_abort::data_type_length_too_high);
  buffer_.insert(buffer_.end(), f.data.begin(), f.data.end());
  toggle_ = !toggle_;
  if (f.last) {
    transfer_ = transfer::none;
    if (buffer_.size() != size_) return abort(index_, sub_, sdo_abort::data_type_length_too_low);
    const sdo_abort r = complete_access_ ? download_complete(index_, sub_, buffer_)
                                         : access_->download(index_, sub_, buffer_, true);
    if (r != sdo_abort::none) return abort(index_, sub_, r);
  }
  reply(mailbox_type::coe, sdo_download_segment_response(f.toggle));
}

// ---- SDO information --------------------------------------------------------------------------

void coe_server::information_reply(sdo_info_opcode op, std::span<const std::uint8_t> data) {
  // The data cut into as many mailboxes as it needs, each saying how many fragments are left.
  const std::size_t room = sdo_info_room(mailbox_size_);
  const std::size_t fragments = data.empty() ? 1 : (data.size() + room - 1) / room;
  for (std::size_t f = 0; f < fragments; ++f) {
    const std::size_t from = f * room;
    const std::size_t to = std::min(data.size(), from + room);
    reply(mailbox_type::coe, sdo_info_fragment(op, static_cast<std::uint16_t>(fragments - 1 - f), data.subspan(from, to - from)));
  }
}

std::vector<std::uint8_t> coe_server::od_list(std::uint16_t list) const {
  const std::vector<object_entry>& table = dictionary_->table();
  std::vector<std::uint8_t> data{static_cast<std::uint8_t>(list), static_cast<std::uint8_t>(list >> 8)};
  const auto put16 = [&](std::size_t v) {
    data.push_back(static_cast<std::uint8_t>(v));
    data.push_back(static_cast<std::uint8_t>(v >> 8));
  };
  if (list == 0) {
    for (std::uint16_t which = 1; which <= 5; ++which) {
      put16(static_cast<std::size_t>(
          std::count_if(table.begin(), table.end(), [&](const object_entry& o) { return in_list(o, which); })));
    }
    return data;
  }
  for (const object_entry& o : table) {
    if (in_list(o, list)) put16(o.index);
  }
  return data;
}

void coe_server::on_sdo_information(std::span<const std::uint8_t> body) {
  const std::optional<sdo_info_view> v = parse_sdo_information(body);
  if (!v) return mailbox_error_reply(mailbox_error::size_too_short);
  const auto error = [&](sdo_abort code) {
    ++errors_;
    information_reply(sdo_info_opcode::error, le32_bytes(static_cast<std::uint32_t>(code)));
  };
  const std::optional<sdo_info_request> request = parse_sdo_info_request(*v);
  switch (v->opcode) {
    case sdo_info_opcode::od_list_request:
      if (!request || request->list_or_index > 5) return error(sdo_abort::general_error);
      return information_reply(sdo_info_opcode::od_list_response, od_list(request->list_or_index));
    case sdo_info_opcode::object_description_request: {
      if (!request) return error(sdo_abort::general_error);
      const object_entry* o = dictionary_->object(request->list_or_index);
      if (o == nullptr || o->subs.empty()) return error(sdo_abort::object_does_not_exist);
      const sub_entry& typed = o->subs.size() > 1 ? o->subs[1] : o->subs[0];
      const std::uint16_t type = o->code == object_code::record ? record_data_type(o->index)
                                                                : static_cast<std::uint16_t>(typed.type);
      return information_reply(sdo_info_opcode::object_description_response,
                               object_description_data(o->index, type, o->subs.back().sub,
                                                       static_cast<std::uint8_t>(o->code), o->name));
    }
    case sdo_info_opcode::entry_description_request: {
      if (!request) return error(sdo_abort::general_error);
      const object_entry* o = dictionary_->object(request->list_or_index);
      if (o == nullptr) return error(sdo_abort::object_does_not_exist);
      const auto e = std::find_if(o->subs.begin(), o->subs.end(), [&](const sub_entry& s) { return s.sub == request->sub; });
      if (e == o->subs.end()) return error(sdo_abort::sub_index_does_not_exist);
      // Value info: the name only (no unit, default, minimum or maximum).
      return information_reply(sdo_info_opcode::entry_description_response,
                               entry_description_data(o->index, e->sub, 0, static_cast<std::uint16_t>(e->type),
                                                      bit_length(*e), access_bits(o->index, *e), e->name));
    }
    default: break;
  }
  error(sdo_abort::command_specifier_invalid);
}

}  // namespace cia402::ethercat
