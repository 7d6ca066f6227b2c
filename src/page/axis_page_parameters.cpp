// The page's parameter list and parameter files (docs/instrument-page.md, "Parameter list and
// parameter files"): every entry of the CiA 402 object table (objects.hpp, the one table) and what
// the composition knows beyond it, read through the session's object jobs (SDO on a bus) in one
// pass; writes by index and sub-index; a parameter set saved to and loaded from the file format
// `cia402 serve` gives (CiA 306 DCF), each write's refusal with its SDO abort code and text.
#include "axis_page_impl.hpp"

#include <algorithm>
#include <memory>

#include "cia402/objects.hpp"
#include "page_json.hpp"
#include "page_names.hpp"
#include "json_text.hpp"

namespace cia402::page {
namespace {

using detail::abort_text;
using detail::hex;
using json = nlohmann::ordered_json;

const char* access_key(object_access a) {
  switch (a) {
    case object_access::read_only: return "ro";
    case object_access::write_only: return "wo";
    case object_access::read_write: return "rw";
  }
  return "ro";
}

bool writable(const parameter_entry& e) { return e.access == "rw" || e.access == "wo"; }
bool readable(const parameter_entry& e) { return e.access != "wo"; }

// The table's entries, then the composition's beyond them, in index order.
std::vector<parameter_entry> catalog(const std::vector<parameter_entry>& beyond) {
  std::vector<parameter_entry> out;
  for (std::size_t i = 0; i < drive_object_count(); ++i) {
    const object_description& o = drive_object(i);
    parameter_entry e;
    e.index = o.index;
    e.sub = o.sub;
    e.name = o.name;
    e.data_type = static_cast<std::uint16_t>(o.type);
    e.access = access_key(o.access);
    e.pdo_mappable = o.pdo_mappable;
    e.low = o.low;
    e.high = o.high;
    e.default_number = o.default_value;
    e.unit = o.unit;
    out.push_back(std::move(e));
  }
  for (const parameter_entry& e : beyond) {
    if (find_drive_object(e.index, e.sub) == nullptr) out.push_back(e);
  }
  std::stable_sort(out.begin(), out.end(), [](const parameter_entry& a, const parameter_entry& b) {
    return a.index != b.index ? a.index < b.index : a.sub < b.sub;
  });
  return out;
}

// As the core's data types read it (CiA 301 §7.1.6); a type code it does not know has no format.
std::optional<axes::value_format> format_of(const parameter_entry& e) {
  const auto t = static_cast<data_type>(e.data_type);
  if (type_size(t) == 0 && t != data_type::visible_string) return std::nullopt;
  return axes::format_of(t);
}

std::string key_of(std::uint16_t index, std::uint8_t sub) { return hex(index, 4) + ":" + std::to_string(sub); }

// The value a read gave, as the entry's type reads it (a link that knew no type gave bytes).
std::optional<axes::object_value> value_of(const std::optional<axes::result>& r, const parameter_entry& e) {
  if (!r || !r->ok() || !r->value) return std::nullopt;
  const auto f = format_of(e);
  if (r->value->what == axes::value_format::kind::bytes && f) return axes::decode_value(r->value->bytes, f);
  return *r->value;
}

bool differs(const axes::object_value& v, const parameter_entry& e) {
  if (v.what == axes::value_format::kind::integer) return e.default_number && v.number != *e.default_number;
  if (v.what == axes::value_format::kind::text) return v.text != e.default_text;
  return false;
}

document error_document(int status, const std::string& why) { return {status, detail::json_text(json{{"error", why}})}; }

json abort_json(sdo_abort a) {
  return json{{"abort", hex(static_cast<std::uint32_t>(a), 8)}, {"abort_text", sdo_abort_text(a)}};
}

}  // namespace

// Every readable entry read at once (the session runs them one after the other), waited for
// together: nothing for an entry not read, or when the time ran out.
std::vector<std::optional<axes::result>> axis_page::impl::read_entries(std::unique_lock<std::mutex>& lock,
                                                                       const std::vector<parameter_entry>& entries) {
  auto results = std::make_shared<std::vector<std::optional<axes::result>>>(entries.size());
  auto left = std::make_shared<std::size_t>(0);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    if (!readable(entries[i])) continue;
    ++*left;
    session->read_object(entries[i].index, entries[i].sub, [this, results, left, i](const axes::result& r) {
      (*results)[i] = r;
      if (--*left == 0) answered.notify_all();
    });
  }
  // A drive in this process answers them all without time passing; on a bus the cycle thread's
  // polls bring them.
  if (*left > 0) (void)session->poll_until_idle();
  answered.wait_for(lock, config.request_timeout, [&] { return *left == 0 || board.closed(); });
  return *results;
}

// The entries of this drive with their values: an entry the drive answers "object does not exist"
// (0x06020000, 0x06090011) for is not the drive's and is left out.
axis_page::impl::entry_values axis_page::impl::entries_read(std::unique_lock<std::mutex>& lock) {
  entry_values out;
  std::vector<parameter_entry> all = catalog(config.parameters);
  std::vector<std::optional<axes::result>> read = read_entries(lock, all);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const sdo_abort a = read[i] ? read[i]->abort : sdo_abort::none;
    if (a == sdo_abort::object_does_not_exist || a == sdo_abort::sub_index_does_not_exist) continue;
    out.entries.push_back(std::move(all[i]));
    out.results.push_back(std::move(read[i]));
  }
  return out;
}

reply axis_page::write_entry(std::uint16_t index, std::uint8_t sub, std::string_view value) {
  if (index == object_index::control_word) {
    return refused{400, "the control word is set by commands and bit toggles, not written here"};
  }
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  std::optional<axes::value_format> f = m.session->format_of(index, sub);
  for (const parameter_entry& e : m.config.parameters) {
    if (!f && e.index == index && e.sub == sub) f = format_of(e);
  }
  std::string why;
  const auto v = axes::parse_value(value, f, why);
  if (!v) return refused{400, key_of(index, sub) + ": " + why};
  const std::string action = "WRITE " + key_of(index, sub) + " = " + std::string(value);
  const auto r = m.await(lock, [&m, index, sub, &v](axes::completion done) {
    m.session->write_object(index, sub, *v, std::move(done));
  });
  if (r && r->ok() && sub == 0 && v->what == axes::value_format::kind::integer) m.objects[index] = v->number;
  return m.write_reply(r, action);
}

document axis_page::parameters() {
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return error_document(no->http_status, no->reason);
  const impl::entry_values read = m.entries_read(lock);
  json list = json::array();
  for (std::size_t i = 0; i < read.entries.size(); ++i) {
    const parameter_entry& e = read.entries[i];
    const auto f = format_of(e);
    json j{{"key", key_of(e.index, e.sub)}, {"index", hex(e.index, 4)}, {"sub", e.sub}, {"name", e.name},
           {"type", f ? f->type_name() : hex(e.data_type, 4)}, {"unit", e.unit}, {"access", e.access},
           {"pdo_mapping", e.pdo_mappable}, {"writable", writable(e)}};
    j["low"] = e.low ? json(*e.low) : json(nullptr);
    j["high"] = e.high ? json(*e.high) : json(nullptr);
    // Where a write is a choice (an option code, the mode, the homing method) the values the drive
    // takes, not the range of its type.
    if (e.sub == 0) {
      if (const std::vector<std::int64_t> v = accepted_values(*m.table, e.index); !v.empty()) j["values"] = v;
    }
    j["default"] = e.default_number ? json(*e.default_number) : f && f->what == axes::value_format::kind::text ? json(e.default_text) : json(nullptr);
    const auto& r = read.results[i];
    if (const auto v = value_of(r, e)) {
      j["value"] = json::parse(axes::value_json(*v, f));
      j["differs"] = differs(*v, e);
    } else {
      j["value"] = nullptr;
      j["differs"] = false;
      if (!readable(e)) {
        j["error"] = "write-only";
      } else if (!r) {
        j["error"] = "no answer from " + m.session->link().short_name() + " in time";
      } else {
        j["error"] = r->abort != sdo_abort::none ? abort_text(r->abort) : r->error;
        if (r->abort != sdo_abort::none) j.update(abort_json(r->abort));
      }
    }
    list.push_back(std::move(j));
  }
  json out{{"axis", m.session->link().short_name()}, {"entries", std::move(list)}};
  out["file"] = m.config.parameter_file.write ? json(m.config.parameter_file.extension) : json(nullptr);
  return {200, detail::json_text(out)};
}

document axis_page::parameter_file() {
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (!m.config.parameter_file.write) return error_document(409, "this page offers no parameter files");
  if (auto no = m.not_running()) return error_document(no->http_status, no->reason);
  const impl::entry_values read = m.entries_read(lock);
  std::vector<std::optional<std::string>> values;
  for (std::size_t i = 0; i < read.entries.size(); ++i) {
    const auto v = value_of(read.results[i], read.entries[i]);
    if (!v || v->what == axes::value_format::kind::bytes) {
      values.emplace_back();
    } else {
      values.emplace_back(v->what == axes::value_format::kind::text ? v->text : std::to_string(v->number));
    }
  }
  return {200, m.config.parameter_file.write(read.entries, values, m.config.node)};
}

// Why a value of a file is not written: a read-only entry, the control word, what the link sets up
// (CiA 301 communication objects 0x1000..0x1FFF) and process data (the link's cyclic outputs: the
// page's controls set them); "" where it is written.
std::string axis_page::impl::not_loaded(const parameter_entry& e) const {
  if (!writable(e)) return "read-only";
  if (e.index == object_index::control_word) return "the control word: set by the page's commands";
  if (e.index >= 0x1000 && e.index <= 0x1FFF) return "a communication object: the link sets it up";
  for (const axes::cyclic_object& c : session->link().cyclic_outputs()) {
    if (c.index == e.index && c.sub == e.sub) return "process data: set by the page's controls";
  }
  return "";
}

document axis_page::load_parameter_file(std::string_view text) {
  const parameter_file_format& format = impl_->config.parameter_file;
  if (!format.read) return error_document(409, "this page offers no parameter files");
  auto parsed = format.read(text);
  if (const auto* bad = std::get_if<parameter_file_error>(&parsed)) {
    json j{{"error", "line " + std::to_string(bad->line) + ": " + bad->reason}, {"line", bad->line},
           {"reason", bad->reason}};
    return {400, detail::json_text(j)};
  }
  const std::vector<parameter_entry> all = catalog(impl_->config.parameters);
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return error_document(no->http_status, no->reason);
  // Every value is checked before the first goes out: a file with one that its entry cannot take
  // changes nothing.
  struct planned {
    const parameter_value* given;
    axes::object_value value;
  };
  std::vector<planned> writes;
  json skipped = json::array();
  for (const parameter_value& v : std::get<std::vector<parameter_value>>(parsed)) {
    const auto e = std::find_if(all.begin(), all.end(),
                                [&v](const parameter_entry& x) { return x.index == v.index && x.sub == v.sub; });
    const std::string why = e == all.end() ? "not an entry the page knows" : m.not_loaded(*e);
    if (!why.empty()) {
      skipped.push_back(json{{"key", key_of(v.index, v.sub)}, {"value", v.value}, {"reason", why}});
      continue;
    }
    std::string bad;
    auto value = axes::parse_value(v.value, format_of(*e), bad);
    if (!value) return error_document(400, key_of(v.index, v.sub) + " = " + v.value + ": " + bad);
    writes.push_back({&v, std::move(*value)});
  }
  json written = json::array(), refused_list = json::array();
  std::string stopped;  // why the writes stopped: no answer in time, or the drive went away
  for (const planned& w : writes) {
    const std::uint16_t index = w.given->index;
    const std::uint8_t sub = w.given->sub;
    if (stopped.empty()) {
      if (auto no = m.not_running()) stopped = no->reason;
    }
    if (!stopped.empty()) {
      skipped.push_back(json{{"key", key_of(index, sub)}, {"value", w.given->value}, {"reason", "not sent: " + stopped}});
      continue;
    }
    const auto r = m.await(lock, [&m, &w, index, sub](axes::completion done) {
      m.session->write_object(index, sub, w.value, std::move(done));
    });
    json item{{"key", key_of(index, sub)}, {"value", w.given->value}};
    if (r && r->ok()) {
      if (sub == 0 && w.value.what == axes::value_format::kind::integer) m.objects[index] = w.value.number;
      written.push_back(std::move(item));
      continue;
    }
    if (!r) stopped = "no answer from " + m.session->link().short_name() + " in time";
    if (r && r->abort != sdo_abort::none) item.update(abort_json(r->abort));
    item["error"] = !r ? "no answer from " + m.session->link().short_name() + " in time"
                       : r->abort != sdo_abort::none ? abort_text(r->abort) : r->error;
    refused_list.push_back(std::move(item));
  }
  m.log.report_now("LOAD parameter set", refused_list.empty() ? "done" : "refused",
                   std::to_string(written.size()) + " written, " + std::to_string(refused_list.size()) +
                       " refused, " + std::to_string(skipped.size()) + " skipped");
  json out{{"written", std::move(written)}, {"refused", std::move(refused_list)}, {"skipped", std::move(skipped)}};
  return {200, detail::json_text(out)};
}

}  // namespace cia402::page
