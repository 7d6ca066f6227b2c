// The page's requests, each handed to the axis session (axis_page.hpp): the buttons' and bit
// toggles' words (session::send_word), Enable (session::go_to), Stop (session::quick_stop, then
// Disable voltage), the jog and its dead-man (session::jog, renew_jog), object writes
// (session::write_object), and for a drive in this process the plant's inputs. The decisions shared
// with the page's other parts are commissioning.hpp's and word_change.hpp's.
#include "axis_page_impl.hpp"

#include <limits>
#include <memory>

#include "cia402/manufacturer_objects.hpp"
#include "cia402/objects.hpp"
#include "cia402/words.hpp"
#include "commissioning.hpp"
#include "page_json.hpp"
#include "page_names.hpp"

namespace cia402::page {
namespace {

using detail::abort_text;
using detail::hex;

constexpr const char* not_remote = "not available on a remote drive";

std::string steps_text(const std::vector<int>& transitions) {
  std::string steps;
  for (int t : transitions) steps += (steps.empty() ? "T" : ", T") + std::to_string(t);
  return steps;
}

}  // namespace

std::optional<refused> axis_page::impl::not_running() const {
  if (running()) return std::nullopt;
  return refused{503, link_text().empty() ? session->link().short_name() + " is not ready yet" : link_text()};
}

void axis_page::impl::send_word(std::uint16_t word, bool reset_edge) {
  requested_word = word;
  if (reset_edge) reset_sent_since_change = true;
  session->send_word(word, reset_edge, [this, word](const axes::result&) {
    if (requested_word == word) requested_word.reset();
  });
}

// Logs a command or bit toggle and gives its word to the session.
std::uint64_t axis_page::impl::change_word(const detail::word_change& w) {
  offering.reset();  // a word given by hand ends the handshake: bit 4 as the word has it
  const std::uint16_t before = word_base();
  const std::uint64_t id = w.tracked ? log.track(w.action, true, observed, now_us, w.expect_in(*table, before, observed))
                                     : log.report_now(w.action, "done", w.text);
  send_word(w.word, w.fault_reset_edge);
  return id;
}

std::string axis_page::impl::enable_blocker(state s) const {
  if (plant) return plant->enable_blocker(s);
  // On a bus STO and the DC link are not the drive's objects (bit 4 says voltage enabled, which a
  // drive may show only once switched on): only what the status word says for certain.
  const bool remote = !session->status_known() || (session->status_word() & status_bit::remote) != 0;
  return detail::enable_blocker(s, session->error_code(), false, true, remote);
}

// Enable or Stop is over: the session's result, with the transitions seen on the way.
void axis_page::impl::end_operation(std::optional<operation>& op, const axes::result& r,
                                    const std::string& done_text) {
  if (!op) return;
  const state now = r.shown.value_or(observed.value_or(state::start));
  if (r.ok()) {
    log.update({op->id, op->action, "done", "done: " + (op->transitions.empty() ? std::string("no transition") : steps_text(op->transitions)) + " -> " + state_name(now) + done_text, op->transitions});
  } else {
    std::string why = r.error;
    if (const std::string b = enable_blocker(now); op->action == "ENABLE" && !b.empty()) why = b;
    log.update({op->id, op->action, "refused", "refused in " + std::string(state_name(now)) + ": " + why, op->transitions});
  }
  op.reset();
}

void axis_page::impl::end_jog(const axes::result& r) {
  if (!jogging) return;
  const std::string ran = "ran " + std::to_string((now_us - jogging->started_us) / 1000) + " ms";
  if (r.ok() || r.end == axes::outcome::superseded) {
    const std::string why = !jogging->why_ended.empty() ? jogging->why_ended
                            : r.ok() ? "no keep-alive for " + std::to_string(jogging->time_to_live_us / 1000) + " ms"
                                     : r.error.empty() ? std::string("ended by another request") : r.error;
    log.update({jogging->id, jogging->action, "done", "done: " + ran + "; 0x60FF = 0: " + why, {}});
  } else {
    log.update({jogging->id, jogging->action, "refused", "refused: " + r.error, {}});
  }
  jogging.reset();
}

std::optional<axes::result> axis_page::impl::await(std::unique_lock<std::mutex>& lock,
                                                   const std::function<void(axes::completion)>& start) {
  auto out = std::make_shared<std::optional<axes::result>>();
  start([this, out](const axes::result& r) {
    *out = r;
    answered.notify_all();
  });
  // A drive in this process answers without time passing, and a request refused before anything is
  // sent at once; the rest comes with the cycle thread's polls.
  if (!*out) (void)session->poll_until_idle();
  answered.wait_for(lock, config.request_timeout, [&] { return out->has_value() || board.closed(); });
  return *out;
}

reply axis_page::impl::write_reply(const std::optional<axes::result>& r, const std::string& action,
                                   std::optional<std::uint64_t> tracked) {
  const auto refuse = [&](int status, const std::string& why, sdo_abort abort) -> reply {
    if (tracked) {
      log.refuse_pending("refused: " + why);
    } else {
      log.report_now(action, "refused", "refused: " + why);
    }
    return refused{status, action + ": " + why, abort};
  };
  if (!r) return refuse(504, "no answer from " + session->link().short_name() + " in time", sdo_abort::none);
  if (r->abort != sdo_abort::none) {
    return refuse(r->abort == sdo_abort::sdo_protocol_timed_out ? 504 : 422, abort_text(r->abort), r->abort);
  }
  if (!r->ok()) return refuse(r->bad_input ? 422 : 503, r->error, sdo_abort::none);
  if (tracked) return accepted{*tracked};
  return accepted{log.report_now(action, "done", "done")};
}

// --- the backend interface: requests ----------------------------------------------------------

reply axis_page::command(page_command c) {
  std::lock_guard lock(impl_->mutex);
  if (auto no = impl_->not_running()) return *no;
  const auto change = detail::press_button(*impl_->table, c, impl_->word_base());
  if (const refused* no = std::get_if<refused>(&change)) return *no;
  return accepted{impl_->change_word(std::get<detail::word_change>(change))};
}

reply axis_page::toggle_control_bit(int bit) {
  if (bit < 0 || bit > 15) return refused{400, "bit must be 0..15"};
  std::lock_guard lock(impl_->mutex);
  if (auto no = impl_->not_running()) return *no;
  detail::word_change w = detail::flip_bit(*impl_->table, impl_->word_base(), bit);
  // A bit the profile leaves to the mode means what the mode the drive runs makes of it.
  const auto mode = impl_->value_of(object_index::modes_of_operation_display);
  const char* name = mode ? mode_bit_name(*impl_->table, true, bit, *mode) : nullptr;
  if (!w.tracked && name != nullptr) {
    w.text = "done: " + std::string(name) + " (bit " + std::to_string(bit) + " in mode " + std::to_string(*mode) + ")";
  }
  return accepted{impl_->change_word(w)};
}

reply axis_page::new_setpoint() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  // The mode the drive shows; before the first read of 0x6061, the one asked for.
  std::optional<std::int64_t> mode = m.value_of(object_index::modes_of_operation_display);
  if (!mode) mode = m.value_of(object_index::modes_of_operation);
  if (auto no = detail::new_setpoint_refusal(*m.table, mode)) return *no;
  const std::uint16_t word = m.word_base();
  // The session raises bit 4 (down first if it was up), holds it until status bit 12, then drops it.
  m.requested_word.reset();
  auto sid = std::make_shared<std::uint64_t>(0);
  *sid = m.session->offer_set_point(word, [&m, sid](const axes::result& r) {
    if (m.offering != *sid) return;  // superseded: the request after it has the word
    m.offering.reset();
    if (!r.ok()) m.log.report_now("NEW_SET-POINT", "refused", "refused: " + r.error + m.conditions());
  });
  if (*sid != 0) m.offering = *sid;
  std::string options;
  if ((word & control_bit::change_set_immediately) != 0) options += ", change set immediately";
  if ((word & control_bit::relative) != 0) options += ", relative";
  if ((word & control_bit::change_on_set_point) != 0) options += ", change on set-point";
  const auto target = m.value_of(object_index::target_position);
  return accepted{m.log.report_now(
      "NEW_SET-POINT", "done",
      "done" + (target ? ": 0x607A = " + std::to_string(*target) : std::string()) + options +
          "; bit 4 up until the drive acknowledges (status bit 12), then down")};
}

reply axis_page::enable() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  const state s = m.observed.value_or(state::start);
  if (s == state::operation_enabled) {
    return accepted{m.log.report_now("ENABLE", "nothing to do", "nothing to do: already OPERATION_ENABLED")};
  }
  if (const std::string why = m.enable_blocker(s); !why.empty()) {
    const std::string text = "refused in " + std::string(state_name(s)) + ": " + why;
    m.log.report_now("ENABLE", "refused", text);
    return refused{409, text};
  }
  m.offering.reset();
  if (m.enabling) {
    m.log.update({m.enabling->id, "ENABLE", "refused", "refused: Enable pressed again", m.enabling->transitions});
    m.enabling.reset();
  }
  const std::uint64_t id = m.log.report_now("ENABLE", "pending", "walking to OPERATION_ENABLED");
  m.enabling = impl::operation{id, "ENABLE", {}};
  m.session->go_to(state::operation_enabled, [&m, id](const axes::result& r) {
    if (m.enabling && m.enabling->id == id) m.end_operation(m.enabling, r, ", each step confirmed by the status word");
  });
  return accepted{id};
}

reply axis_page::stop() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  if (m.jogging) m.jogging->why_ended = "Stop pressed";
  m.offering.reset();
  if (m.stopping) {
    m.log.update({m.stopping->id, "STOP", "refused", "refused: Stop pressed again", m.stopping->transitions});
    m.stopping.reset();
  }
  const state s = m.observed.value_or(state::start);
  const bool quick = s == state::operation_enabled;
  const std::uint64_t id =
      m.log.report_now("STOP", "pending", quick ? "QUICK_STOP, then DISABLE_VOLTAGE once stopped" : "DISABLE_VOLTAGE");
  m.stopping = impl::operation{id, "STOP", {}};
  auto disable = [&m, id](const axes::result& r) {
    if (!m.stopping || m.stopping->id != id) return;
    const state now = r.shown.value_or(m.observed.value_or(state::start));
    // In FAULT the power is off already: the stop is over there too.
    if (!r.ok() || now == state::switch_on_disabled || now == state::fault) return m.end_operation(m.stopping, r, "");
    m.session->go_to(state::switch_on_disabled, [&m, id](const axes::result& r2) {
      if (m.stopping && m.stopping->id == id) m.end_operation(m.stopping, r2, "");
    });
  };
  if (quick) {
    m.session->quick_stop(disable);
  } else {
    axes::result here;
    here.shown = s;
    disable(here);
  }
  return accepted{id};
}

reply axis_page::jog(std::int64_t velocity_rpm, std::uint64_t time_to_live_us) {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  if (velocity_rpm == 0) {
    if (!m.jogging) return accepted{m.log.report_now("JOG RELEASE", "nothing to do", "nothing to do: no jog runs")};
    const std::uint64_t id = m.jogging->id;
    m.jogging->why_ended = "released";
    if (!m.jogging->turning) {
      // Released before it turned (the mode switch still under way): the jog must not start.
      m.session->stop([](const axes::result&) {});
    } else {
      m.session->renew_jog(0);  // the session's dead-man ends it in its next poll: 0x60FF = 0
    }
    // A drive in this process has 0x60FF = 0 before the reply; on a bus it goes with the next cycle.
    (void)m.session->poll_until_idle();
    // Reported at once, as the button's release is: the session ramps the shaft to rest meanwhile.
    if (m.jogging) m.end_jog(axes::result{});
    return accepted{id};
  }
  const state now = m.observed.value_or(state::start);
  if (now != state::operation_enabled) {
    return refused{409, "jog refused: the drive is in " + std::string(state_name(now)) +
                            ", not OPERATION_ENABLED (press Enable first)"};
  }
  if (velocity_rpm < std::numeric_limits<std::int32_t>::min() || velocity_rpm > std::numeric_limits<std::int32_t>::max()) {
    return refused{422, "JOG " + std::to_string(velocity_rpm) + " rpm: " + abort_text(sdo_abort::invalid_value),
                   sdo_abort::invalid_value};
  }
  // The keep-alive of the jog that runs; a jog released (or ending) is not renewed but started anew.
  if (m.jogging && m.jogging->why_ended.empty() && m.now_us < m.jogging->expires_us &&
      m.jogging->velocity_rpm == velocity_rpm && m.jogging->time_to_live_us == time_to_live_us) {
    m.session->renew_jog(time_to_live_us);
    m.jogging->expires_us = m.now_us + time_to_live_us;
    return accepted{m.jogging->id};
  }
  if (m.jogging && m.jogging->why_ended.empty()) m.jogging->why_ended = "another jog velocity";
  const std::string action = "JOG " + std::to_string(velocity_rpm) + " rpm";
  const std::uint64_t id = m.log.report_now(
      action, "pending", "running in profile velocity while renewed within " + std::to_string(time_to_live_us / 1000) + " ms");
  impl::jog_run j{id, 0, action, velocity_rpm, time_to_live_us, m.now_us, m.now_us + time_to_live_us, ""};
  j.session_id = m.session->jog(static_cast<std::int32_t>(velocity_rpm), time_to_live_us, [&m, id](const axes::result& r) {
    if (m.jogging && m.jogging->id == id) m.end_jog(r);
  });
  m.jogging = j;
  return accepted{id};
}

reply axis_page::select_profile(std::string_view name) {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (!m.plant) {
    return refused{409, "profile " + std::string(name) +
                            ": a drive on a bus keeps the profile `cia402 serve --profile` gave it"};
  }
  const profile* chosen = nullptr;
  std::string names;
  for (const profile* p : m.config.selectable) {
    if (chosen == nullptr && name == p->name) chosen = p;  // the page's own profile is first
    names += (names.empty() ? "" : ", ") + std::string(p->name);
  }
  if (chosen == nullptr) return refused{400, "no profile '" + std::string(name) + "' here (" + names + ")"};
  if (m.log.pending()) m.log.finish_pending("the profile was changed");
  m.enabling.reset();
  m.stopping.reset();
  m.jogging.reset();
  m.offering.reset();
  m.requested_word.reset();
  m.observed.reset();
  m.last_transition.reset();
  m.recording.clear();
  m.samples.clear();
  m.transition_for_sample.reset();
  m.transition_for_row.reset();
  m.session.reset();  // before the link it uses
  m.drive = m.connect(*chosen);
  m.plant = detail::local_plant::of(m.drive);
  m.start_session(*chosen);
  return accepted{m.log.report_now("PROFILE " + std::string(chosen->name), "done",
                                   std::string("done: ") + chosen->title + ", from power-up")};
}

reply axis_page::write_object(std::uint16_t index, std::int64_t value) {
  if (index == object_index::control_word) {
    return refused{400, "the control word is set by commands and bit toggles, not written here"};
  }
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  const std::string action = "WRITE " + hex(index, 4) + " = " + std::to_string(value);
  const auto r = m.await(lock, [&m, index, value](axes::completion done) {
    m.session->write_object(index, 0, axes::object_value::of_integer(value), std::move(done));
  });
  if (r && r->ok()) m.objects[index] = value;
  return m.write_reply(r, action);
}

reply axis_page::change_plant(const plant_change& change) {
  if (change.fault && *change.fault && (change.fault_code == 0 || change.fault_class > 4)) {
    return refused{400, "a fault needs a code 0x0001..0xFFFF and a class 0..4"};
  }
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (!m.plant) return m.change_bus_plant(lock, change);
  std::string action;
  auto add = [&action](const std::string& what) { action += (action.empty() ? "" : ", ") + what; };
  if (change.target_velocity) {
    // The one part the drive can refuse: first, so a refusal leaves everything as it was.
    const std::string what = "WRITE 0x60FF = " + std::to_string(*change.target_velocity);
    const std::int64_t v = *change.target_velocity;
    const auto r = m.await(lock, [&m, v](axes::completion done) {
      m.session->write_object(object_index::target_velocity, 0, axes::object_value::of_integer(v), std::move(done));
    });
    if (!r || !r->ok()) return m.write_reply(r, what);
    add("TARGET_VELOCITY=" + std::to_string(v));
  }
  for (const std::string& input : m.plant->change_inputs(change)) add(input);
  if (action.empty()) return refused{400, "nothing to change"};
  // A plant input is never refused; the page learns which transitions it caused.
  return accepted{m.log.track(action, false, m.observed, m.now_us)};
}

// A drive on a bus: the target velocity (0x60FF) or, on a `cia402 bus` node, a fault through its
// 0x2001; DC link and STO are the drive's own.
reply axis_page::impl::change_bus_plant(std::unique_lock<std::mutex>& lock, const plant_change& change) {
  if (change.dc_link || change.sto) return refused{409, std::string("DC-link voltage and STO are ") + not_remote};
  if (change.target_velocity && change.fault) {
    return refused{400, "on a remote drive the target velocity and a fault go in separate requests"};
  }
  if (!change.target_velocity && !change.fault) return refused{400, "nothing to change"};
  if (auto no = not_running()) return *no;
  if (change.target_velocity) {
    const std::int64_t v = *change.target_velocity;
    const std::uint64_t id = log.track("TARGET_VELOCITY=" + std::to_string(v), false, observed, now_us);
    const auto r = await(lock, [this, v](axes::completion done) {
      session->write_object(object_index::target_velocity, 0, axes::object_value::of_integer(v), std::move(done));
    });
    if (r && r->ok()) objects[object_index::target_velocity] = v;
    return write_reply(r, "WRITE 0x60FF = " + std::to_string(v), id);
  }
  if (session->device_name() != virtual_drive_device_name) {
    return refused{409, std::string("fault injection is ") + not_remote + " (" + session->link().short_name() +
                            " has no fault-injection object 0x2001 of cia402 bus)"};
  }
  const std::uint16_t code = *change.fault ? change.fault_code : 0;
  std::string action = *change.fault ? "FAULT " + hex(code, 4) + " ON" : std::string("FAULT OFF");
  // 0x2001 takes an error code only; the drive raises it with its default class.
  if (*change.fault && table->error_classes) action += " (class not sent: 0x2001 takes a code)";
  // Tracked from before it is sent: the drive may answer and fault in the same cycle.
  const std::uint64_t id = log.track(action, false, observed, now_us);
  const auto r = await(lock, [this, code](axes::completion done) {
    session->write_object(fault_injection_index, 0, axes::object_value::of_integer(code), std::move(done));
  });
  if (r && r->ok()) injected_fault = code;
  return write_reply(r, action, id);
}

void axis_page::renew_lease() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  // A fresh serve that no page has opened yet lost no sign of life: the lease starts here.
  if (!m.lease_armed && m.config.lease_us != 0) {
    m.lease_armed = true;
    m.session->set_lease(m.config.lease_us);
  }
  m.session->renew("the page");
}

}  // namespace cia402::page
