// The homing panel and the drive's own error list: POST /api/homing (the parameters through the
// session's object writes, the run through session::home), the snapshot's `homing`, `doing_now`
// (mode_view.hpp) and `drive_errors` (0x1003 read through the session's object jobs: an SDO on a
// bus, the local link's dictionary for a drive in this process).
#include "axis_page_impl.hpp"

#include "cia402/error_codes.hpp"
#include "cia402/objects.hpp"
#include "cia402/words.hpp"
#include "page_json.hpp"
#include "page_names.hpp"

namespace cia402::page {
namespace {

using detail::abort_text;
using detail::hex;

constexpr std::uint16_t pre_defined_error_field = 0x1003;  // CiA 301 §7.5.2.5
constexpr std::size_t error_field_most = 254;              // sub-indices 1..254

std::optional<std::int64_t> integer_of(const axes::result& r) {
  if (!r.value) return std::nullopt;
  if (r.value->what == axes::value_format::kind::integer) return r.value->number;
  if (r.value->what != axes::value_format::kind::bytes || r.value->bytes.empty() || r.value->bytes.size() > 8) {
    return std::nullopt;
  }
  std::uint64_t v = 0;
  for (std::size_t k = r.value->bytes.size(); k-- > 0;) v = (v << 8) | r.value->bytes[k];
  return static_cast<std::int64_t>(v);
}

std::string failure_text(const axes::result& r) {
  return r.abort != sdo_abort::none ? abort_text(r.abort) : r.error;
}

}  // namespace

void axis_page::impl::keep_views_read() {
  if (!running()) return;
  if (!plant && !homing_read_asked) {
    homing_read_asked = true;
    for (const std::uint8_t sub : {std::uint8_t{1}, std::uint8_t{2}}) {
      session->read_object(object_index::homing_speeds, sub, [this, sub](const axes::result& r) {
        if (const auto v = integer_of(r); r.ok() && v) (sub == 1 ? switch_speed_read : zero_speed_read) = *v;
      });
    }
    // And the mode panel's profile parameters, which no PDO carries and the page shows beside the
    // set-points (0x6081, 0x6083..0x6085): read once, then the page's own writes keep them.
    for (const std::uint16_t index : {object_index::homing_method, object_index::homing_acceleration,
                                      object_index::home_offset, object_index::profile_velocity,
                                      object_index::profile_acceleration, object_index::profile_deceleration,
                                      object_index::quick_stop_deceleration}) {
      session->read_object(index, 0, [this, index](const axes::result& r) {
        // A value the page wrote meanwhile stays: it is newer than this read.
        if (const auto v = integer_of(r); r.ok() && v) objects.emplace(index, *v);
      });
    }
  }
  if (error_field.stale && !error_field.reading) {
    error_field.stale = false;
    error_field.reading = true;
    read_error_field(0, {});
  }
}

// Sub 0 (the number of errors), then each entry from sub 1 (the newest) on.
void axis_page::impl::read_error_field(std::size_t sub, std::vector<std::uint32_t> so_far) {
  session->read_object(pre_defined_error_field, static_cast<std::uint8_t>(sub),
                       [this, sub, so_far = std::move(so_far)](const axes::result& r) mutable {
    const auto v = integer_of(r);
    if (!r.ok() || !v) return end_error_field_read(r.ok() ? "0x1003 answered no number" : failure_text(r));
    if (sub == 0) {
      // A count the drive reports is checked before it is used: at most the 254 sub-indices there are.
      if (*v < 0 || static_cast<std::size_t>(*v) > error_field_most) {
        return end_error_field_read("0x1003 sub 0 reports " + std::to_string(*v) + " errors (at most 254)");
      }
      so_far.resize(static_cast<std::size_t>(*v));  // filled entry by entry
      if (*v == 0) {
        error_field.entries.clear();
        return end_error_field_read("");
      }
    } else {
      so_far[sub - 1] = static_cast<std::uint32_t>(*v);
    }
    if (sub == so_far.size()) {
      error_field.entries = std::move(so_far);
      return end_error_field_read("");
    }
    read_error_field(sub + 1, std::move(so_far));
  });
}

void axis_page::impl::end_error_field_read(std::string error) {
  error_field.reading = false;
  error_field.read_at_us = now_us;
  error_field.error = std::move(error);
  auto waiting = std::move(error_field.waiting);
  error_field.waiting.clear();
  for (auto& w : waiting) w();
}

std::optional<std::int64_t> axis_page::impl::shown_value(std::uint16_t index, std::uint8_t sub) const {
  if (plant) return plant->read(index, sub);
  if (index == object_index::homing_speeds) return sub == 1 ? switch_speed_read : zero_speed_read;
  return value_of(index);
}

detail::mode_reading axis_page::impl::mode_reading_now() const {
  detail::mode_reading r;
  const bool live = plant || session->link().phase() == axes::link_phase::running;
  if (!live) return r;
  r.enabled = observed == state::operation_enabled;
  r.status_word = session->status_word();
  r.control_word = word_shown();
  r.mode = shown_value(object_index::modes_of_operation_display, 0);
  r.velocity_rpm = shown_value(object_index::velocity_actual_value, 0);
  r.digital_inputs = shown_value(object_index::digital_inputs, 0);
  r.target_position = shown_value(object_index::target_position, 0);
  r.target_velocity = shown_value(object_index::target_velocity, 0);
  r.target_torque = shown_value(object_index::target_torque, 0);
  r.homing_method = shown_value(object_index::homing_method, 0);
  r.switch_speed_rpm = shown_value(object_index::homing_speeds, 1);
  r.zero_speed_rpm = shown_value(object_index::homing_speeds, 2);
  return r;
}

axis_page::impl::json axis_page::impl::homing_json() const {
  const auto number = [](const std::optional<std::int64_t>& v) { return v ? json(*v) : json(nullptr); };
  const detail::mode_reading r = mode_reading_now();
  json j;
  j["method"] = number(r.homing_method);
  j["fast"] = number(r.switch_speed_rpm);
  j["slow"] = number(r.zero_speed_rpm);
  j["acceleration"] = number(shown_value(object_index::homing_acceleration, 0));
  j["offset"] = number(shown_value(object_index::home_offset, 0));
  // Inferred from the status bits and the speed (mode_view.hpp), so a bus drive reads the same.
  j["phase"] = r.mode == mode::homing ? json(detail::homing_phase_text(r)) : json(nullptr);
  j["running"] = homing_run.has_value();
  return j;
}

axis_page::impl::json axis_page::impl::drive_errors_json() const {
  json entries = json::array();
  for (std::size_t k = 0; k < error_field.entries.size(); ++k) {
    const std::uint32_t e = error_field.entries[k];
    const auto code = static_cast<std::uint16_t>(e & 0xFFFFu);
    entries.push_back({{"sub", k + 1}, {"value", hex(e, 8)}, {"code", hex(code, 4)}, {"text", error_code_text(code)}});
  }
  json j;
  j["count"] = error_field.read_at_us && error_field.error.empty() ? json(error_field.entries.size()) : json(nullptr);
  j["entries"] = std::move(entries);
  j["read_ms"] = error_field.read_at_us ? json(*error_field.read_at_us / 1000) : json(nullptr);
  j["reading"] = error_field.reading;
  j["error"] = error_field.error.empty() ? json(nullptr) : json(error_field.error);
  return j;
}

void axis_page::impl::end_homing(const axes::result& r) {
  if (!homing_run) return;
  const operation run = *homing_run;
  homing_run.reset();
  if (r.ok()) {
    log.update({run.id, run.action, "done",
                "done: homing attained" + (r.position ? ", 0x6064 = " + std::to_string(*r.position) : std::string()),
                run.transitions});
  } else if (r.end == axes::outcome::superseded) {
    log.update({run.id, run.action, "refused", "refused: interrupted by another request before homing was attained",
                run.transitions});
  } else {
    log.update({run.id, run.action, "refused", "refused: " + failure_text(r), run.transitions});
  }
}

// --- the backend interface ---------------------------------------------------------------------

reply axis_page::home(const homing_request& request) {
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  if (request.start && *request.start && !left_to_mode(*m.table, true, 4)) {
    return refused{409, std::string("profile ") + m.table->name + " names control bit 4 \"" +
                            bit_names_of(*m.table).control[4] + "\": no homing operation start on it"};
  }
  struct parameter {
    std::uint16_t index;
    std::uint8_t sub;
    std::optional<std::int64_t> value;
    const char* name;
  };
  const parameter writes[] = {
      {object_index::homing_method, 0, request.method, "0x6098"},
      {object_index::homing_speeds, 1, request.switch_speed, "0x6099:1"},
      {object_index::homing_speeds, 2, request.zero_speed, "0x6099:2"},
      {object_index::homing_acceleration, 0, request.acceleration, "0x609A"},
      {object_index::home_offset, 0, request.offset, "0x607C"},
  };
  // Each value against the one object table before anything is sent: a bad one changes nothing.
  for (const parameter& p : writes) {
    if (!p.value) continue;
    const object_description* d = find_drive_object(p.index, p.sub);
    const sdo_abort no = d != nullptr ? check_write(*d, *p.value) : sdo_abort::object_does_not_exist;
    if (no != sdo_abort::none) {
      const std::string why = std::string(p.name) + " = " + std::to_string(*p.value) + ": " + abort_text(no);
      m.log.report_now("HOMING", "refused", "refused: " + why);
      return refused{422, "HOMING: " + why, no};
    }
  }
  std::string written;
  for (const parameter& p : writes) {
    if (!p.value) continue;
    const std::string what = std::string(p.name) + " = " + std::to_string(*p.value);
    const auto r = m.await(lock, [&m, &p](axes::completion done) {
      m.session->write_object(p.index, p.sub, axes::object_value::of_integer(*p.value), std::move(done));
    });
    if (!r || !r->ok()) {
      // What went before stays written: say so with the refusal.
      return m.write_reply(r, "HOMING " + what + (written.empty() ? "" : " (written before it: " + written + ")"));
    }
    if (p.index == object_index::homing_speeds) {
      (p.sub == 1 ? m.switch_speed_read : m.zero_speed_read) = *p.value;
    } else {
      m.objects[p.index] = *p.value;
    }
    written += (written.empty() ? "" : ", ") + what;
  }
  if (!request.start) {
    return accepted{m.log.report_now("HOMING PARAMETERS", "done", "done: " + written), written};
  }
  if (m.jogging) m.jogging->why_ended = "homing started";
  m.offering.reset();
  if (m.homing_run) {
    m.log.update({m.homing_run->id, m.homing_run->action, "refused", "refused: superseded by another homing request", {}});
    m.homing_run.reset();
  }
  if (!*request.start) {
    const std::uint64_t id = m.log.report_now("HOMING STOP", "pending", "stopping: bit 4 down, halt");
    m.homing_run = impl::operation{id, "HOMING STOP", {}};
    m.session->stop([&m, id](const axes::result& r) {
      if (!m.homing_run || m.homing_run->id != id) return;
      m.homing_run.reset();
      m.log.update({id, "HOMING STOP", r.ok() ? "done" : "refused", r.ok() ? "done: stopped" : "refused: " + failure_text(r), {}});
    });
    return accepted{id, written};
  }
  const auto method = m.shown_value(object_index::homing_method, 0);
  const std::string action = "HOMING" + (method ? " method " + std::to_string(*method) : std::string());
  const std::uint64_t id = m.log.report_now(
      action, "pending",
      (written.empty() ? std::string() : written + "; ") +
          "0x6060 = 6, OPERATION ENABLED, bit 4 (homing operation start) up until status bits 12 and 10");
  m.homing_run = impl::operation{id, action, {}};
  m.session->home(axes::home_request{}, [&m, id](const axes::result& r) {
    if (m.homing_run && m.homing_run->id == id) m.end_homing(r);
  });
  return accepted{id, written};
}

reply axis_page::read_error_field() {
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  bool done = false;
  m.error_field.waiting.push_back([&done] { done = true; });
  if (!m.error_field.reading) {
    m.error_field.reading = true;
    m.error_field.stale = false;
    m.read_error_field(0, {});
  }
  // A drive in this process answers the whole chain of reads without time passing.
  if (!done) (void)m.session->poll_until_idle();
  m.answered.wait_for(lock, m.config.request_timeout, [&] { return done || m.board.closed(); });
  if (!done) {
    m.error_field.waiting.clear();
    return refused{504, "0x1003: no answer from " + m.session->link().short_name() + " in time"};
  }
  if (!m.error_field.error.empty()) return refused{422, "0x1003: " + m.error_field.error};
  const std::string text = "0x1003 holds " + std::to_string(m.error_field.entries.size()) + " error(s)";
  return accepted{m.log.report_now("READ 0x1003", "done", "done: " + text), text};
}

reply axis_page::clear_error_field() {
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  const auto r = m.await(lock, [&m](axes::completion done) {
    m.session->write_object(pre_defined_error_field, 0, axes::object_value::of_integer(0), std::move(done));
  });
  if (r && r->ok()) m.error_field.stale = true;  // read again: the list the drive keeps now
  return m.write_reply(r, "CLEAR 0x1003 (sub 0 = 0)");
}

}  // namespace cia402::page
