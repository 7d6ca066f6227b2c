// Our master's mailbox and SDO transfers: every mailbox it writes is built, and every one it reads is
// parsed, by the CoE codec (ethercat/coe), which checks each length the slave gives before it reads
// what the length covers. Expedited, normal and segmented upload and download; aborts both ways;
// emergencies met on the way are kept with the slave. SDO information: the slave's dictionary.
#include <algorithm>
#include <utility>

#include "cia402/ethercat/coe/mailbox.hpp"
#include "cia402/ethercat/coe/sdo.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "master_text.hpp"

namespace cia402::ethercat {
namespace {

using detail::hex;
using detail::mailbox_us;
using detail::poll_us;
using detail::slave_text;

// A slave that keeps sending what is not the answer (emergencies, stale replies) is given a bounded
// number of mailboxes, not the master's whole life.
constexpr int max_unrelated_replies = 64;

std::string object_text(std::uint16_t index, std::uint8_t sub) { return hex(index, 4) + ":" + std::to_string(sub); }

// While a transfer runs the cycles go on (outputs stay valid, no watchdog expires), but they leave the
// send mailbox to the transfer: its answer is there.
class mailbox_owner {
 public:
  explicit mailbox_owner(bool& flag) : flag_(flag), before_(flag) { flag_ = true; }
  ~mailbox_owner() { flag_ = before_; }
  mailbox_owner(const mailbox_owner&) = delete;
  mailbox_owner& operator=(const mailbox_owner&) = delete;

 private:
  bool& flag_;
  bool before_;
};

}  // namespace

bool ecat_master::mailbox_send(ecat_slave& s, const std::vector<std::uint8_t>& coe, bool* answered) {
  s.mailbox_counter = next_mailbox_counter(s.mailbox_counter);
  mailbox_header h;
  h.type = mailbox_type::coe;
  h.counter = s.mailbox_counter;
  // The whole mailbox: its last byte hands it over.
  const std::vector<std::uint8_t> m = make_mailbox(h, coe, s.sii.mailbox_out_size);
  if (m.empty()) return false;
  for (const std::uint64_t start = link_->now_us();;) {
    const single r = one(command::fpwr, s.station | (static_cast<std::uint32_t>(s.sii.mailbox_out_start) << 16), m);
    if (r.ok && answered != nullptr) *answered = true;
    if (r.ok && r.wkc == 1) return true;  // 0: the slave has not read the one before yet
    if (link_->now_us() - start > mailbox_us) return false;
    pause(poll_us);
  }
}

std::optional<std::vector<std::uint8_t>> ecat_master::mailbox_receive(ecat_slave& s) {
  for (const std::uint64_t start = link_->now_us();;) {
    const single r = one(command::fprd, s.station | (static_cast<std::uint32_t>(s.sii.mailbox_in_start) << 16),
                         std::vector<std::uint8_t>(s.sii.mailbox_in_size, 0));
    if (r.ok && r.wkc == 1) return r.data;  // 0: nothing in the mailbox yet
    // No answer at all: the read may have emptied the mailbox on its way, so the reply is asked for
    // again rather than waited for until the time runs out.
    if (!r.ok && !request_mailbox_repeat(s)) return std::nullopt;
    if (link_->now_us() - start > mailbox_us) return std::nullopt;
    pause(poll_us);
  }
}

bool ecat_master::request_mailbox_repeat(ecat_slave& s) {
  // ETG.1000.4 mailbox repeat: toggle SM1's repeat request (activate 0x080E bit 1, the enable bit
  // written as it is), then the slave has put its last reply back when its repeat acknowledge (PDI
  // control 0x080F bit 1) equals the request.
  constexpr std::uint16_t sm1_activate = 0x0800 + 8 + 6;
  constexpr std::uint16_t sm1_pdi_control = sm1_activate + 1;
  constexpr std::uint8_t repeat_bit = 0x02;
  const single before = read_register(s, sm1_activate, 1);
  if (!before.ok || before.wkc != 1 || before.data.size() != 1) return false;
  const auto request = static_cast<std::uint8_t>(before.data[0] ^ repeat_bit);
  if (!write_register(s, sm1_activate, {request})) return false;
  for (const std::uint64_t start = link_->now_us(); link_->now_us() - start <= mailbox_us;) {
    const single ack = read_register(s, sm1_pdi_control, 1);
    if (ack.ok && ack.wkc == 1 && ack.data.size() == 1 && (ack.data[0] & repeat_bit) == (request & repeat_bit)) return true;
    pause(poll_us);
  }
  return false;  // the slave never acknowledged: the caller's transfer ends as unanswered
}

void ecat_master::note_emergency(ecat_slave& s, std::span<const std::uint8_t> mailbox) {
  const std::optional<mailbox_view> m = parse_mailbox(mailbox);
  if (!m || m->header.type != mailbox_type::coe) return;
  const std::optional<coe_view> c = parse_coe(m->data);
  if (!c || c->service != coe_service::emergency) return;
  if (const std::optional<emergency_message> e = parse_emergency(c->body)) s.emergencies.push_back(e->code);
}

ecat_slave* ecat_master::sdo_slave(std::size_t i, ecat_sdo_result& result) {
  if (i >= slaves_.size()) {
    result.error = "no slave " + std::to_string(i) + ": the line has " + std::to_string(slaves_.size());
    return nullptr;
  }
  ecat_slave& s = slaves_[i];
  if (!s.mailbox) {
    result.error = slave_text(s) + " has no CoE mailbox";
    return nullptr;
  }
  return &s;
}

std::optional<sdo_frame> ecat_master::sdo_exchange(ecat_slave& s, const std::vector<std::uint8_t>& request,
                                                   std::uint16_t index, std::uint8_t sub, sdo_command expected,
                                                   std::vector<std::uint8_t>& reply, ecat_sdo_result& result) {
  bool answered = false;
  if (!mailbox_send(s, request, &answered)) {
    // A full mailbox answers with a working counter of 0; a line that brings no frame back is no
    // full mailbox (a cable pulled mid-transfer), and is said as such.
    result.error = slave_text(s) + (answered ? ": its receive mailbox stays full"
                                             : ": the line does not answer: no frame came back within " +
                                                   std::to_string(mailbox_us / 1000) + " ms");
    return std::nullopt;
  }
  const bool initiate = expected == sdo_command::initiate_upload || expected == sdo_command::initiate_download;
  for (int looked = 0; looked < max_unrelated_replies; ++looked) {
    pause(0);
    std::optional<std::vector<std::uint8_t>> got = mailbox_receive(s);
    if (!got) {
      result.error = slave_text(s) + ": no SDO answer for " + object_text(index, sub);
      return std::nullopt;
    }
    reply = std::move(*got);
    // Every length is the slave's word: the reply must hold its own header and what it claims.
    const std::optional<mailbox_view> m = parse_mailbox(reply);
    if (!m || m->data.size() < coe_header_size) continue;
    if (m->header.type == mailbox_type::error) {
      const std::optional<std::uint16_t> code = parse_mailbox_error(m->data);
      result.error = slave_text(s) + " answered with a mailbox error " + (code ? hex(*code, 4) : std::string("without a code"));
      return std::nullopt;
    }
    if (m->header.type != mailbox_type::coe) continue;
    const std::optional<coe_view> c = parse_coe(m->data);
    if (!c) continue;
    if (c->service == coe_service::emergency) {  // an emergency on the way: note it, go on
      if (const std::optional<emergency_message> e = parse_emergency(c->body)) s.emergencies.push_back(e->code);
      continue;
    }
    const std::optional<sdo_frame> f = parse_sdo_response(c->service, c->body);
    if (!f) continue;
    if (f->command == sdo_command::abort) {
      if (f->index != index || f->sub != sub) continue;  // another transfer's
      result.aborted = true;
      result.abort = static_cast<sdo_abort>(f->abort_code);
      result.error = slave_text(s) + " aborted " + object_text(index, sub) + ": " + hex(f->abort_code, 8) + " (" +
                     sdo_abort_text(result.abort) + ")";
      return std::nullopt;
    }
    if (f->command != expected || (initiate && (f->index != index || f->sub != sub))) continue;  // not ours
    return f;
  }
  result.error = slave_text(s) + ": no answer to the SDO for " + object_text(index, sub) + " among " +
                 std::to_string(max_unrelated_replies) + " mailboxes it sent";
  return std::nullopt;
}

void ecat_master::give_up(ecat_slave& s, std::uint16_t index, std::uint8_t sub, sdo_abort code, std::string why,
                          ecat_sdo_result& result) {
  (void)mailbox_send(s, sdo_abort_request(index, sub, static_cast<std::uint32_t>(code)));  // no answer comes
  result.error = slave_text(s) + ": " + object_text(index, sub) + ": " + std::move(why);
}

bool ecat_master::upload_segments(ecat_slave& s, std::uint16_t index, std::uint8_t sub, const sdo_frame& first,
                                  ecat_sdo_result& result) {
  const std::size_t limit = first.size_indicated ? first.size : max_sdo_upload;
  std::vector<std::uint8_t> reply;
  // Every segment but the last brings a byte at least, so the size bounds the exchanges.
  for (bool toggle = false;; toggle = !toggle) {
    const std::optional<sdo_frame> seg =
        sdo_exchange(s, sdo_upload_segment_request(toggle), index, sub, sdo_command::upload_segment, reply, result);
    if (!seg) return false;
    if (seg->toggle != toggle) {
      give_up(s, index, sub, sdo_abort::toggle_bit_not_alternated, "an upload segment did not alternate its toggle bit",
              result);
      return false;
    }
    if (result.data.size() + seg->data.size() > limit) {
      give_up(s, index, sub, sdo_abort::data_type_length_mismatch,
              "its segments bring more than the " + std::to_string(limit) + " bytes " +
                  (first.size_indicated ? "it announced" : "this master reads"),
              result);
      return false;
    }
    result.data.insert(result.data.end(), seg->data.begin(), seg->data.end());
    if (seg->last) break;
    if (seg->data.empty()) {
      give_up(s, index, sub, sdo_abort::general_error, "an empty upload segment that is not the last", result);
      return false;
    }
  }
  if (first.size_indicated && result.data.size() != first.size) {
    result.error = slave_text(s) + ": " + object_text(index, sub) + ": its last segment came after " +
                   std::to_string(result.data.size()) + " of the " + std::to_string(first.size) + " bytes it announced";
    return false;
  }
  return true;
}

ecat_sdo_result ecat_master::sdo_read(std::size_t i, std::uint16_t index, std::uint8_t sub) {
  ecat_sdo_result result;
  ecat_slave* s = sdo_slave(i, result);
  if (s == nullptr) return result;
  const mailbox_owner owner(in_mailbox_);
  std::vector<std::uint8_t> reply;
  const std::optional<sdo_frame> f =
      sdo_exchange(*s, sdo_upload_request(index, sub), index, sub, sdo_command::initiate_upload, reply, result);
  if (!f) return result;
  if (!f->expedited && f->size_indicated && f->size > max_sdo_upload) {
    give_up(*s, index, sub, sdo_abort::out_of_memory,
            "it announces " + std::to_string(f->size) + " bytes; this master reads at most " +
                std::to_string(max_sdo_upload),
            result);
    return result;
  }
  result.data.assign(f->data.begin(), f->data.end());
  // A normal upload whose first mailbox does not hold the value goes on in segments.
  if (!f->expedited && !(f->size_indicated && result.data.size() == f->size) &&
      !upload_segments(*s, index, sub, *f, result)) {
    result.data.clear();
    return result;
  }
  result.ok = true;
  return result;
}

ecat_sdo_result ecat_master::sdo_write(std::size_t i, std::uint16_t index, std::uint8_t sub, std::int64_t value,
                                       unsigned bytes) {
  bytes = std::clamp(bytes, 1u, 4u);
  std::vector<std::uint8_t> data(bytes);
  for (unsigned b = 0; b < bytes; ++b) data[b] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(value) >> (8 * b));
  return sdo_write_bytes(i, index, sub, data);
}

ecat_sdo_result ecat_master::sdo_write_bytes(std::size_t i, std::uint16_t index, std::uint8_t sub,
                                             std::span<const std::uint8_t> data) {
  ecat_sdo_result result;
  ecat_slave* s = sdo_slave(i, result);
  if (s == nullptr) return result;
  const mailbox_owner owner(in_mailbox_);
  std::vector<std::uint8_t> reply;
  if (!data.empty() && data.size() <= 4) {
    result.ok = sdo_exchange(*s, sdo_download_expedited(index, sub, data), index, sub, sdo_command::initiate_download,
                             reply, result)
                    .has_value();
    return result;
  }
  // Normal: the size and what the first mailbox holds, then segments with the rest.
  const std::size_t first = std::min(data.size(), sdo_initiate_room(s->sii.mailbox_out_size));
  const std::vector<std::uint8_t> initiate =
      sdo_download_normal(index, sub, false, static_cast<std::uint32_t>(data.size()), data.first(first));
  if (!sdo_exchange(*s, initiate, index, sub, sdo_command::initiate_download, reply, result)) return result;
  bool toggle = false;
  for (std::size_t at = first; at < data.size(); toggle = !toggle) {
    const std::size_t n = std::min(sdo_segment_room(s->sii.mailbox_out_size), data.size() - at);
    if (n == 0) {  // a mailbox smaller than configure_mailbox lets through: never a segment of nothing
      result.error = slave_text(*s) + ": its receive mailbox holds no segment";
      return result;
    }
    const bool last = at + n == data.size();
    const std::optional<sdo_frame> seg = sdo_exchange(*s, sdo_download_segment(toggle, last, data.subspan(at, n)), index,
                                                      sub, sdo_command::download_segment, reply, result);
    if (!seg) return result;
    if (seg->toggle != toggle) {
      give_up(*s, index, sub, sdo_abort::toggle_bit_not_alternated,
              "a download segment's answer did not alternate its toggle bit", result);
      return result;
    }
    at += n;
  }
  result.ok = true;
  return result;
}

// ---- SDO information ----------------------------------------------------------------------------

std::optional<std::vector<std::uint8_t>> ecat_master::sdo_info_exchange(ecat_slave& s, sdo_info_opcode request,
                                                                        std::span<const std::uint8_t> data,
                                                                        sdo_info_opcode expected, std::string& error,
                                                                        std::uint32_t& code) {
  code = 0;
  bool answered = false;
  if (!mailbox_send(s, sdo_info_fragment(request, 0, data), &answered)) {
    error = slave_text(s) + (answered ? ": its receive mailbox stays full" : ": the line does not answer");
    return std::nullopt;
  }
  std::vector<std::uint8_t> whole;
  std::optional<std::uint16_t> left;  // fragments the last one said were to come
  for (int looked = 0; looked < max_unrelated_replies;) {
    pause(0);
    const std::optional<std::vector<std::uint8_t>> got = mailbox_receive(s);
    if (!got) {
      error = slave_text(s) + ": no SDO information answer";
      return std::nullopt;
    }
    const std::optional<mailbox_view> m = parse_mailbox(*got);
    const std::optional<coe_view> c = m && m->header.type == mailbox_type::coe ? parse_coe(m->data) : std::nullopt;
    if (c && c->service == coe_service::emergency) note_emergency(s, *got);
    const std::optional<sdo_info_view> v =
        c && c->service == coe_service::sdo_information ? parse_sdo_information(c->body) : std::nullopt;
    if (!v || (v->opcode != expected && v->opcode != sdo_info_opcode::error)) {
      ++looked;  // not an answer to this request
      continue;
    }
    if (v->opcode == sdo_info_opcode::error) {
      code = v->data.size() >= 4 ? static_cast<std::uint32_t>(v->data[0] | (v->data[1] << 8) |
                                                                                   (v->data[2] << 16)) |
                                                           (static_cast<std::uint32_t>(v->data[3]) << 24)
                                                     : 0;
      error = slave_text(s) + " answered with SDO information error " + hex(code, 8) + " (" +
              sdo_abort_text(static_cast<sdo_abort>(code)) + ")";
      return std::nullopt;
    }
    // Each fragment says one fewer is left than the one before; the data as a whole is bounded.
    if (left && v->fragments_left + 1u != *left) {
      error = slave_text(s) + ": SDO information fragments out of order (" + std::to_string(v->fragments_left) +
              " left after " + std::to_string(*left) + ")";
      return std::nullopt;
    }
    if (whole.size() + v->data.size() > max_sdo_upload) {
      error = slave_text(s) + ": SDO information answer longer than " + std::to_string(max_sdo_upload) + " bytes";
      return std::nullopt;
    }
    whole.insert(whole.end(), v->data.begin(), v->data.end());
    if (!v->incomplete || v->fragments_left == 0) return whole;
    left = v->fragments_left;
  }
  error = slave_text(s) + ": no SDO information answer among " + std::to_string(max_unrelated_replies) +
          " mailboxes it sent";
  return std::nullopt;
}

ecat_dictionary_result ecat_master::read_dictionary(std::size_t i) {
  ecat_dictionary_result result;
  ecat_sdo_result slave_check;
  ecat_slave* s = sdo_slave(i, slave_check);
  if (s == nullptr) {
    result.error = slave_check.error;
    return result;
  }
  const mailbox_owner owner(in_mailbox_);
  const auto le16_at = [](const std::vector<std::uint8_t>& d, std::size_t at) {
    return static_cast<std::uint16_t>(d[at] | (d[at + 1] << 8));
  };
  const std::uint8_t all_objects[2] = {1, 0};
  std::string why;
  std::uint32_t code = 0;
  const std::optional<std::vector<std::uint8_t>> list =
      sdo_info_exchange(*s, sdo_info_opcode::od_list_request, all_objects, sdo_info_opcode::od_list_response, why, code);
  if (!list || list->size() < 2 || list->size() % 2 != 0 || le16_at(*list, 0) != 1) {
    result.error = list ? slave_text(*s) + ": its object list is not a list of all objects" : "the object list: " + why;
    return result;
  }
  for (std::size_t at = 2; at < list->size(); at += 2) {
    const std::uint16_t index = le16_at(*list, at);
    const std::uint8_t ask[2] = {static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8)};
    const std::optional<std::vector<std::uint8_t>> d = sdo_info_exchange(
        *s, sdo_info_opcode::object_description_request, ask, sdo_info_opcode::object_description_response, why, code);
    if (!d || d->size() < 6 || le16_at(*d, 0) != index) {
      result.error = "object " + hex(index, 4) + ": " + (d ? slave_text(*s) + " described another object" : why);
      return result;
    }
    ecat_object_description o;
    o.index = index;
    o.data_type = le16_at(*d, 2);
    o.max_sub = (*d)[4];
    o.object_code = (*d)[5];
    o.name.assign(d->begin() + 6, d->end());
    for (unsigned sub = 0; sub <= o.max_sub; ++sub) {
      const std::uint8_t entry[4] = {ask[0], ask[1], static_cast<std::uint8_t>(sub), 0};  // value info: none
      const std::optional<std::vector<std::uint8_t>> e = sdo_info_exchange(
          *s, sdo_info_opcode::entry_description_request, entry, sdo_info_opcode::entry_description_response, why, code);
      if (!e && code == static_cast<std::uint32_t>(sdo_abort::sub_index_does_not_exist)) continue;  // a gap in the record
      if (!e || e->size() < 10 || le16_at(*e, 0) != index || (*e)[2] != sub) {
        result.error = "entry " + hex(index, 4) + ":" + std::to_string(sub) + ": " +
                       (e ? slave_text(*s) + " described another entry" : why);
        return result;
      }
      o.entries.push_back({static_cast<std::uint8_t>(sub), le16_at(*e, 4), le16_at(*e, 6), le16_at(*e, 8),
                           std::string(e->begin() + 10, e->end())});
    }
    result.objects.push_back(std::move(o));
  }
  result.ok = true;
  return result;
}

}  // namespace cia402::ethercat
