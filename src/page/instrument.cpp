#include "cia402/page/instrument.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <deque>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "cia402/drive.hpp"
#include "cia402/error_codes.hpp"
#include "cia402/master.hpp"
#include "cia402/words.hpp"
#include "action_log.hpp"
#include "page_json.hpp"
#include "page_names.hpp"
#include "recorder.hpp"
#include "sign_of_life.hpp"
#include "snapshot_board.hpp"
#include "word_change.hpp"

namespace cia402::page {
namespace {

using json = nlohmann::ordered_json;
using detail::abort_text;
using detail::hex;


}  // namespace

struct instrument::impl {
  impl(const profile& p, const instrument_config& c)
      : table(&p),
        config(c),
        drive(std::make_unique<sim::virtual_drive>(p, c.plant)),
        log({c.results_kept, c.settle_quiet, c.settle_limit,
             "still busy when the instrument stopped waiting", ""},
            [this] { return how_it_stands(); }),
        sign(c.lease_us) {
    if (config.publish_every == 0) config.publish_every = 1;
    if (config.selectable.empty()) {
      for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
        config.selectable.push_back(&builtin_profile(i));
      }
    }
    if (std::find(config.selectable.begin(), config.selectable.end(), &p) ==
        config.selectable.end()) {
      config.selectable.insert(config.selectable.begin(), &p);
    }
  }

  const profile* table;  // the profile in use; select_profile() changes it with the drive
  instrument_config config;
  // mutable: views for reading are taken in const snapshots; reads change nothing.
  mutable std::unique_ptr<sim::virtual_drive> drive;

  mutable std::mutex mutex;  // guards all here but the board, which has a lock of its own

  std::uint16_t control_word = 0;
  std::deque<std::uint16_t> scripted;  // words for the next cycles, one each (a fault-reset edge)
  // The set-point handshake of profile position: bit 4 is up (once `scripted` ran out) until status
  // bit 12 acknowledges it or the cycle `handshake_until` passes.
  std::optional<std::uint64_t> handshake_until;
  detail::action_log log;

  struct transition_seen {
    int number = 0;
    state from = state::start;
    state to = state::start;
  };
  std::optional<transition_seen> last_transition;

  detail::snapshot_board board;
  detail::recorder recording;
  detail::sign_of_life sign;

  // --- under the lock ------------------------------------------------------------------------

  void apply_word(std::uint16_t word) {
    control_word = word;
    // The object interface takes any 16-bit control word.
    drive->write(sim::object::control_word, 0, word);
  }

  // Logs a command or bit toggle and gives its word to the drive from the next cycle on.
  std::uint64_t change_word(const detail::word_change& w) {
    handshake_until.reset();  // a word given by hand ends the handshake: bit 4 as the word has it
    const std::uint64_t id =
        w.tracked ? track(w.action, true, w.expect_in(*table, control_word, drive->view().current()))
                  : log.report_now(w.action, "done", w.text);
    scripted.clear();
    if (w.fault_reset_edge) {
      // One word a cycle.
      const fault_reset_words edge = fault_reset_edge(control_word, w.word);
      scripted.insert(scripted.end(), edge.words, edge.words + edge.count);
    } else {
      apply_word(w.word);
    }
    return id;
  }

  std::uint64_t track(std::string action, bool refuse_without_transition,
                      detail::action_log::expectation expect = detail::action_log::expectation::act) {
    return log.track(std::move(action), refuse_without_transition, drive->view().current(),
                     drive->cycle(), expect);
  }

  std::string blocking_conditions() {
    sim::drive_view v = drive->view();
    std::string s;
    auto add = [&s](const char* what) { s += (s.empty() ? " (" : ", ") + std::string(what); };
    if (v.fault_cause() != 0) add(("fault cause " + hex(v.fault_cause(), 4) + " present").c_str());
    if (v.sto()) add("STO asserted");
    if (!v.dc_link()) add("no DC-link voltage");
    if (!s.empty()) s += ")";
    return s;
  }

  detail::action_log::standing how_it_stands() {
    sim::drive_view v = drive->view();
    const state now = v.current();
    std::string waiting_for;
    if (v.sto()) {
      waiting_for = "STO asserted";
    } else if (!v.dc_link()) {
      waiting_for = "no DC-link voltage";
    } else if (stop_running(v.state_of_axis().core)) {
      waiting_for = "a stop is ramping";
    }
    return {now, state_name(now), blocking_conditions(), waiting_for};
  }

  // The lease lapsed: a drive left enabled stops as its 0x6007 says (the word goes in this cycle).
  void stop_for_silence() {
    if (drive->view().current() != state::operation_enabled) return;
    std::int64_t code = table->spec(option::abort_connection).default_value;
    (void)drive->view().read(option_index(option::abort_connection), 0, code);
    const auto w = detail::stop_for_silent_page(*table, control_word, static_cast<int>(code), sign.lease_us());
    if (w) change_word(*w);
  }

  void step_locked() {
    if (sign.lapsed(drive->time_us())) stop_for_silence();
    if (!scripted.empty()) {
      apply_word(scripted.front());
      scripted.pop_front();
    }
    const state before = drive->view().current();
    sim::trace_row row = sim::begin_row(drive->time_us(), drive->constants(),
                                        drive->view().state_of_axis());
    const drive_outputs out = drive->step();
    sim::complete_row(row, out);
    recording.record(row);
    const std::uint64_t now = drive->cycle();
    if (out.transition != no_transition) {
      last_transition = transition_seen{out.transition, before, out.current};
      if (auto* a = log.pending()) a->transitions.push_back(out.transition);
      recording.note_transition({0, row.time_us, int{out.transition}, before, out.current,
                                 row.control_word, out.status_word, false});
    }
    if (handshake_until && scripted.empty()) end_handshake(out, now);
    if (log.pending()) settle(out, now);
    if (now % config.publish_every == 0) {
      board.publish([this](bool with_time) { return snapshot(with_time); });
    }
  }

  // Bit 4 falls once the drive acknowledged the set-point (status bit 12 in a cycle that read bit 4
  // set), or unacknowledged after new_setpoint_wait_us.
  void end_handshake(const drive_outputs& out, std::uint64_t now) {
    constexpr std::uint16_t bit4 = 1u << 4;
    const bool acknowledged = (control_word & bit4) != 0 && (out.status_word & (1u << 12)) != 0;
    if (!acknowledged && now < *handshake_until) return;
    handshake_until.reset();
    if (!acknowledged) {
      log.report_now("NEW_SET-POINT", "refused",
                     "refused: no set-point acknowledge (status bit 12) within " +
                         std::to_string(detail::new_setpoint_wait_us / 1000) +
                         " ms; bit 4 cleared" + blocking_conditions());
    }
    apply_word(static_cast<std::uint16_t>(control_word & ~bit4));
  }

  // Settled: no scripted word left, no transition and no stop running for settle_quiet cycles.
  // A stop the state itself runs (QUICK STOP ACTIVE, FAULT REACTION ACTIVE) counts as running
  // until the shaft stands, so the transition that ends it (T12, T14) is reported with the action.
  void settle(const drive_outputs& out, std::uint64_t now) {
    const sim::drive_view v = drive->view();
    const state_activity act = table->info(out.current).activity;
    const bool stop_running = cia402::stop_running(v.state_of_axis().core) ||
                              ((act == state_activity::quick_stop ||
                                act == state_activity::fault_reaction) &&
                               !v.inputs().standstill);
    log.settle(now, out.transition != no_transition || stop_running || !scripted.empty());
  }

  json snapshot(bool with_time) const {
    const sim::drive_view v = drive->view();
    const drive_outputs& out = v.outputs();
    const state now = v.current();
    json j;
    j["state"] = state_name(now);
    j["status_word"] = hex(out.status_word, 4);
    j["control_word"] = hex(control_word, 4);
    j["decodes_to"] = command_name(table->decode(control_word));
    if (last_transition) {
      j["last_transition"] = {{"number", last_transition->number},
                              {"from", state_name(last_transition->from)},
                              {"to", state_name(last_transition->to)}};
    } else {
      j["last_transition"] = nullptr;
    }
    j["stop_running"] = cia402::stop_running(v.state_of_axis().core);
    j["ramp"] = stop_ramp_name(out.ramp);
    j["error_code"] = hex(out.error_code, 4);
    j["error_text"] = error_code_text(out.error_code);
    j["error_register"] = hex(out.error_register, 2);
    j["velocity"] = v.velocity_rpm();
    j["target_velocity"] = v.target_velocity();
    j["effective_target"] = v.effective_target();
    j["torque"] = out.torque;
    j["brake_engaged"] = v.brake_engaged();
    j["dc_link"] = v.dc_link();
    j["sto"] = v.sto();
    j["fault_cause"] = hex(v.fault_cause(), 4);
    // The operation mode and its actual values (docs/modes.md).
    j["mode"] = v.operation_mode();
    j["requested_mode"] = v.requested_mode();
    j["position"] = v.position();
    j["position_demand"] = v.position_demand();
    j["following_error"] = v.following_error();
    j["torque_actual"] = v.torque();
    json objects = json::object();
    for (const object_name& o : object_names(*table)) {
      std::int64_t value = 0;
      if (v.read(o.index, 0, value) == sdo_abort::none) objects[hex(o.index, 4)] = value;
    }
    j["objects"] = std::move(objects);
    j["results"] = log.results_json();
    j["profile"] = table->name;
    if (with_time) {
      j["cycle"] = drive->cycle();
      j["time_ms"] = drive->time_us() / 1000;
    }
    return j;
  }
};

instrument::instrument(const profile& p, const instrument_config& config)
    : impl_(std::make_unique<impl>(p, config)) {}

instrument::~instrument() { close(); }

void instrument::step() {
  std::lock_guard lock(impl_->mutex);
  impl_->step_locked();
}

std::uint64_t instrument::cycle() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->drive->cycle();
}

reply instrument::command(page_command c) {
  std::lock_guard lock(impl_->mutex);
  const auto change = detail::press_button(*impl_->table, c, impl_->control_word);
  if (const refused* no = std::get_if<refused>(&change)) return *no;
  return accepted{impl_->change_word(std::get<detail::word_change>(change))};
}

reply instrument::toggle_control_bit(int bit) {
  if (bit < 0 || bit > 15) return refused{400, "bit must be 0..15"};
  std::lock_guard lock(impl_->mutex);
  return accepted{impl_->change_word(detail::flip_bit(*impl_->table, impl_->control_word, bit))};
}

reply instrument::new_setpoint() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = detail::new_setpoint_refusal(*m.table, m.drive->view().operation_mode())) return *no;
  constexpr std::uint16_t bit4 = 1u << 4;
  const std::uint16_t word = m.control_word;
  m.scripted.clear();
  // A rising edge: bit 4 low for a cycle first if it was up.
  if ((word & bit4) != 0) m.scripted.push_back(static_cast<std::uint16_t>(word & ~bit4));
  m.scripted.push_back(static_cast<std::uint16_t>(word | bit4));
  const std::uint64_t cycle_us = m.drive->constants().cycle_us;
  m.handshake_until = m.drive->cycle() + m.scripted.size() +
                      detail::new_setpoint_wait_us / (cycle_us ? cycle_us : 1);
  std::string options;
  if ((word & (1u << 5)) != 0) options += ", change set immediately";
  if ((word & (1u << 6)) != 0) options += ", relative";
  if ((word & (1u << 9)) != 0) options += ", change on set-point";
  return accepted{m.log.report_now(
      "NEW_SET-POINT", "done",
      "done: 0x607A = " + std::to_string(m.drive->view().state_of_axis().objects.target_position) + options +
          "; bit 4 up until the drive acknowledges (status bit 12), then down")};
}

reply instrument::select_profile(std::string_view name) {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  const profile* chosen = nullptr;
  std::string names;
  for (const profile* p : m.config.selectable) {
    if (chosen == nullptr && name == p->name) chosen = p;  // the instrument's own profile is first
    names += (names.empty() ? "" : ", ") + std::string(p->name);
  }
  if (chosen == nullptr) {
    return refused{400, "no profile '" + std::string(name) + "' here (" + names + ")"};
  }
  if (m.log.pending()) m.log.finish_pending("the profile was changed");
  m.drive = std::make_unique<sim::virtual_drive>(*chosen, m.config.plant);
  m.table = chosen;
  m.control_word = 0;
  m.scripted.clear();
  m.handshake_until.reset();
  m.last_transition.reset();
  m.recording.clear();
  return accepted{m.log.report_now("PROFILE " + std::string(chosen->name), "done",
                                   std::string("done: ") + chosen->title + ", from power-up")};
}

reply instrument::write_object(std::uint16_t index, std::int64_t value) {
  if (index == sim::object::control_word) {
    return refused{400, "the control word is set by commands and bit toggles, not written here"};
  }
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  const std::string action = "WRITE " + hex(index, 4) + " = " + std::to_string(value);
  const sdo_abort r = m.drive->write(index, 0, value);
  if (r != sdo_abort::none) {
    const std::string text = "refused: " + abort_text(r);
    m.log.report_now(action, "refused", text);
    return refused{422, action + ": " + text, r};
  }
  return accepted{m.log.report_now(action, "done", "done")};
}

reply instrument::change_plant(const plant_change& change) {
  if (change.fault && *change.fault && (change.fault_code == 0 || change.fault_class > 4)) {
    return refused{400, "a fault needs a code 0x0001..0xFFFF and a class 0..4"};
  }
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  sim::drive_view v = m.drive->view();
  std::string action;
  auto add = [&action](const std::string& what) { action += (action.empty() ? "" : ", ") + what; };
  if (change.target_velocity) {
    // The one part the drive can refuse: try it first, so a refusal leaves everything as it was.
    const sdo_abort r = v.write(sim::object::target_velocity, 0, *change.target_velocity);
    if (r != sdo_abort::none) {
      const std::string what = "WRITE 0x60FF = " + std::to_string(*change.target_velocity);
      m.log.report_now(what, "refused", "refused: " + abort_text(r));
      return refused{422, what + ": " + abort_text(r), r};
    }
    add("TARGET_VELOCITY=" + std::to_string(*change.target_velocity));
  }
  if (change.fault) {
    if (*change.fault) {
      v.inject_fault(change.fault_code, change.fault_class);
      add("FAULT " + hex(change.fault_code, 4) + " ON");
    } else {
      v.clear_faults();
      add("FAULT OFF");
    }
  }
  if (change.dc_link) {
    v.set_dc_link(*change.dc_link);
    add(std::string("DC_LINK ") + (*change.dc_link ? "ON" : "OFF"));
  }
  if (change.sto) {
    v.set_sto(*change.sto);
    add(std::string("STO ") + (*change.sto ? "ON" : "OFF"));
  }
  if (action.empty()) return refused{400, "nothing to change"};
  // A plant input is never refused; the page learns which transitions it caused.
  return accepted{m.track(action, false)};
}

void instrument::renew_lease() { impl_->sign.renew(); }

std::string instrument::info_json(bool control, bool token_required) const {
  std::lock_guard lock(impl_->mutex);
  json j = detail::profile_info(*impl_->table);
  j["backend"] = "virtual";
  json profiles = json::array();
  for (const profile* p : impl_->config.selectable) {
    profiles.push_back({{"name", p->name}, {"title", p->title}});
  }
  j["profiles"] = std::move(profiles);
  j["control"] = control;
  j["token_required"] = token_required;
  j["cycle_us"] = impl_->drive->constants().cycle_us;
  j["lease_ms"] = impl_->sign.lease_us() / 1000;
  // Snapshots come at most this often (the plot holds a value across a gap between them).
  j["publish_ms"] = impl_->config.publish_every * impl_->drive->constants().cycle_us / 1000.0;
  // The virtual drive's plant takes every input the page offers.
  j["capabilities"] = {
      {"fault", true}, {"dc_link", true}, {"sto", true}, {"reasons", json::object()}};
  return j.dump();
}

std::string instrument::snapshot_json() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->board.present_json(impl_->snapshot(true));
}

std::string instrument::recording_json(std::uint64_t rows_seen,
                                       std::uint64_t transitions_seen) const {
  std::lock_guard lock(impl_->mutex);
  return impl_->recording.since_json(rows_seen, transitions_seen).dump();
}

std::string instrument::recording_file(recording_format format) const {
  std::lock_guard lock(impl_->mutex);
  sim::trace_info info;
  info.title = "instrument page recording";
  info.profile_name = impl_->table->name;
  info.cycle_us = impl_->drive->constants().cycle_us;
  return impl_->recording.file(format, info);
}

std::optional<published> instrument::wait_for_update(std::uint64_t seen,
                                                     std::chrono::milliseconds timeout) {
  return impl_->board.wait_for_update(seen, timeout);
}

published instrument::latest() const { return impl_->board.latest(); }

void instrument::close() { impl_->board.close(); }

bool instrument::closed() const { return impl_->board.closed(); }

}  // namespace cia402::page
