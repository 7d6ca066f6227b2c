#include "cia402/page/instrument.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "cia402/drive.hpp"
#include "cia402/master.hpp"
#include "cia402/words.hpp"
#include "page_json.hpp"
#include "page_names.hpp"

namespace cia402::page {
namespace {

using json = nlohmann::ordered_json;
using detail::abort_text;
using detail::command_entry;
using detail::core_command_of;
using detail::entry_of;
using detail::hex;
using detail::result_entry;

constexpr std::uint16_t bit7 = control_bit::fault_reset;
constexpr std::uint16_t bit8 = control_bit::halt;
constexpr std::uint8_t no_pending_row = 0xFF;

// An action waiting for the drive to settle, so the page learns whether it led anywhere.
struct tracked_action {
  std::uint64_t id = 0;
  std::string action;
  state before = state::start;
  std::uint64_t start_cycle = 0;
  std::uint64_t busy_until = 0;  // last cycle with a transition or a stop running
  std::vector<int> transitions;
  bool refused_without_transition = true;  // commands: yes; plant inputs: a plain report
};

}  // namespace

struct instrument::impl {
  impl(const profile& p, const instrument_config& c) : table(p), config(c), drive(p, c.plant) {
    if (config.publish_every == 0) config.publish_every = 1;
  }

  const profile& table;
  instrument_config config;
  // mutable: views for reading are taken in const snapshots; reads change nothing.
  mutable sim::virtual_drive drive;

  mutable std::mutex mutex;
  std::condition_variable updated;
  bool is_closed = false;

  std::uint16_t control_word = 0;
  std::deque<std::uint16_t> scripted;  // words for the next cycles, one each (a fault-reset edge)
  std::optional<tracked_action> pending;
  std::deque<result_entry> results;
  std::uint64_t next_id = 1;

  struct transition_seen {
    int number = 0;
    state from = state::start;
    state to = state::start;
  };
  std::optional<transition_seen> last_transition;

  std::string published_body;  // the last published snapshot without its time fields
  published newest;

  // --- under the lock ------------------------------------------------------------------------

  std::uint64_t new_id() { return next_id++; }

  void push_result(result_entry r) {
    detail::push_result(results, std::move(r), config.results_kept);
  }

  void apply_word(std::uint16_t word) {
    control_word = word;
    // The object interface takes any 16-bit control word.
    drive.write(sim::object::control_word, 0, word);
  }

  // A new action takes over: the one still waiting is reported as it stands.
  void finish_pending(const char* why_unsettled) {
    if (!pending) return;
    finish(*pending, why_unsettled);
    pending.reset();
  }

  std::string blocking_conditions() {
    sim::drive_view v = drive.view();
    std::string s;
    auto add = [&s](const char* what) { s += (s.empty() ? " (" : ", ") + std::string(what); };
    if (v.fault_cause() != 0) add(("fault cause " + hex(v.fault_cause(), 4) + " present").c_str());
    if (v.sto()) add("STO asserted");
    if (!v.dc_link()) add("no DC-link voltage");
    if (!s.empty()) s += ")";
    return s;
  }

  void finish(const tracked_action& a, const char* why_unsettled) {
    result_entry r;
    r.id = a.id;
    r.action = a.action;
    r.transitions = a.transitions;
    const state now = drive.view().current();
    if (!a.transitions.empty()) {
      r.outcome = "done";
      r.text = detail::transitions_text(a.transitions, now);
    } else if (a.refused_without_transition) {
      r.outcome = "refused";
      r.text = std::string("refused: no transition from ") + state_name(a.before) + " for " +
               a.action + blocking_conditions();
    } else {
      r.outcome = "done";
      r.text = std::string("done: no transition, still ") + state_name(now);
    }
    if (why_unsettled != nullptr) r.text += std::string(" (") + why_unsettled + ")";
    push_result(std::move(r));
  }

  std::uint64_t track(std::string action, bool refuse_without_transition) {
    finish_pending("superseded before it settled");
    tracked_action a;
    a.id = new_id();
    a.action = std::move(action);
    a.before = drive.view().current();
    a.start_cycle = drive.cycle();
    a.busy_until = drive.cycle();
    a.refused_without_transition = refuse_without_transition;
    result_entry r;
    r.id = a.id;
    r.action = a.action;
    r.outcome = "pending";
    r.text = "pending";
    push_result(std::move(r));
    pending = std::move(a);
    return pending->id;
  }

  std::uint64_t report_now(std::string action, std::string outcome, std::string text) {
    finish_pending("superseded before it settled");
    result_entry r;
    r.id = new_id();
    r.action = std::move(action);
    r.outcome = std::move(outcome);
    r.text = std::move(text);
    const std::uint64_t id = r.id;
    push_result(std::move(r));
    return id;
  }

  void step_locked() {
    if (!scripted.empty()) {
      apply_word(scripted.front());
      scripted.pop_front();
    }
    const state before = drive.view().current();
    const drive_outputs out = drive.step();
    const std::uint64_t now = drive.cycle();
    if (out.transition != no_transition) {
      last_transition = transition_seen{out.transition, before, out.current};
      if (pending) pending->transitions.push_back(out.transition);
    }
    if (pending) settle(out, now);
    if (now % config.publish_every == 0) publish();
  }

  // Settled: no scripted word left, no transition and no stop running for settle_quiet cycles.
  // A stop the state itself runs (QUICK STOP ACTIVE, FAULT REACTION ACTIVE) counts as running
  // until the shaft stands, so the transition that ends it (T12, T14) is reported with the action.
  void settle(const drive_outputs& out, std::uint64_t now) {
    const sim::drive_view v = drive.view();
    const state_activity act = table.info(out.current).activity;
    const bool stop_running = v.state_of_axis().core.pending_row != no_pending_row ||
                              ((act == state_activity::quick_stop ||
                                act == state_activity::fault_reaction) &&
                               !v.inputs().standstill);
    if (out.transition != no_transition || stop_running || !scripted.empty()) {
      pending->busy_until = now;
    }
    if (now - pending->busy_until >= config.settle_quiet) {
      finish_pending(nullptr);
    } else if (now - pending->start_cycle >= config.settle_limit) {
      finish_pending("still busy when the instrument stopped waiting");
    }
  }

  json snapshot(bool with_time) const {
    const sim::drive_view v = drive.view();
    const drive_outputs& out = v.outputs();
    const state now = v.current();
    json j;
    j["state"] = state_name(now);
    j["status_word"] = hex(out.status_word, 4);
    j["control_word"] = hex(control_word, 4);
    j["decodes_to"] = command_name(table.decode(control_word));
    if (last_transition) {
      j["last_transition"] = {{"number", last_transition->number},
                              {"from", state_name(last_transition->from)},
                              {"to", state_name(last_transition->to)}};
    } else {
      j["last_transition"] = nullptr;
    }
    j["stop_running"] = v.state_of_axis().core.pending_row != no_pending_row;
    j["ramp"] = stop_ramp_name(out.ramp);
    j["error_code"] = hex(out.error_code, 4);
    j["error_register"] = hex(out.error_register, 2);
    j["velocity"] = v.velocity_rpm();
    j["target_velocity"] = v.target_velocity();
    j["effective_target"] = v.effective_target();
    j["torque"] = out.torque;
    j["brake_engaged"] = v.brake_engaged();
    j["dc_link"] = v.dc_link();
    j["sto"] = v.sto();
    j["fault_cause"] = hex(v.fault_cause(), 4);
    json objects = json::object();
    for (const object_name& o : object_names(table)) {
      std::int64_t value = 0;
      if (v.read(o.index, 0, value) == sdo_abort::none) objects[hex(o.index, 4)] = value;
    }
    j["objects"] = std::move(objects);
    j["results"] = detail::results_json(results);
    if (with_time) {
      j["cycle"] = drive.cycle();
      j["time_ms"] = drive.time_us() / 1000;
    }
    return j;
  }

  void publish() {
    std::string body = snapshot(false).dump();
    if (body == published_body && newest.version != 0) return;
    published_body = std::move(body);
    json j = snapshot(true);
    j["version"] = newest.version + 1;
    newest.version += 1;
    newest.json = j.dump();
    updated.notify_all();
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
  return impl_->drive.cycle();
}

reply instrument::command(page_command c) {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  const command_entry& e = entry_of(c);
  if (c == page_command::halt) {
    const std::uint16_t word = static_cast<std::uint16_t>(m.control_word ^ bit8);
    const bool on = (word & bit8) != 0;
    std::string text = std::string("done: halt bit 8 = ") + (on ? "1" : "0");
    if (!m.table.spec(option::halt).exists()) text += " (this profile has no halt: bit 8 is ignored)";
    const std::uint64_t id = m.report_now(e.action, "done", std::move(text));
    m.scripted.clear();
    m.apply_word(word);
    return accepted{id};
  }
  if (c == page_command::fault_reset) {
    // An edge of bit 7 (S2): set for one cycle after a cycle with it clear, then cleared again.
    const std::uint16_t low = static_cast<std::uint16_t>(m.control_word & ~bit7);
    const std::uint16_t high = static_cast<std::uint16_t>(m.control_word | bit7);
    const std::uint64_t id = m.track(e.action, true);
    m.scripted.clear();
    if ((m.control_word & bit7) != 0) m.scripted.push_back(low);
    m.scripted.push_back(high);
    m.scripted.push_back(low);
    return accepted{id};
  }
  cia402::command core_command{};
  core_command_of(c, core_command);
  std::uint16_t word = 0;
  if (!encode_command(m.table, core_command, m.control_word, word)) {
    return refused{409, std::string("profile ") + m.table.name + " has no control word for " +
                            e.action};
  }
  const std::uint64_t id = m.track(e.action, true);
  m.scripted.clear();
  m.apply_word(word);
  return accepted{id};
}

reply instrument::toggle_control_bit(int bit) {
  if (bit < 0 || bit > 15) return refused{400, "bit must be 0..15"};
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  m.scripted.clear();
  const std::uint16_t old_word = m.control_word;
  const std::uint16_t word = static_cast<std::uint16_t>(old_word ^ (1u << bit));
  const bool value = ((word >> bit) & 1u) != 0;
  const cia402::command was = m.table.decode(old_word);
  const cia402::command now = m.table.decode(word);
  const bool reset_edge = bit == 7 && value;
  std::string action = "BIT_" + std::to_string(bit) + "=" + (value ? "1" : "0");
  std::uint64_t id = 0;
  if (was != now || reset_edge) {
    action += std::string(" (") + (reset_edge ? "FAULT_RESET edge" : command_name(now)) + ")";
    id = m.track(std::move(action), true);
  } else {
    const bool owned = ((owned_control_bits(m.table) >> bit) & 1u) != 0;
    id = m.report_now(action, "done",
                      owned ? std::string("done: still decodes to ") + command_name(now)
                            : std::string("done: the state machine does not read bit ") +
                                  std::to_string(bit));
  }
  m.apply_word(word);
  return accepted{id};
}

reply instrument::write_object(std::uint16_t index, std::int64_t value) {
  if (index == sim::object::control_word) {
    return refused{400, "the control word is set by commands and bit toggles, not written here"};
  }
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  const std::string action = "WRITE " + hex(index, 4) + " = " + std::to_string(value);
  const sdo_abort r = m.drive.write(index, 0, value);
  if (r != sdo_abort::none) {
    const std::string text = "refused: " + abort_text(r);
    m.report_now(action, "refused", text);
    return refused{422, action + ": " + text, r};
  }
  return accepted{m.report_now(action, "done", "done")};
}

reply instrument::change_plant(const plant_change& change) {
  if (change.fault && *change.fault && (change.fault_code == 0 || change.fault_class > 4)) {
    return refused{400, "a fault needs a code 0x0001..0xFFFF and a class 0..4"};
  }
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  sim::drive_view v = m.drive.view();
  std::string action;
  auto add = [&action](const std::string& what) { action += (action.empty() ? "" : ", ") + what; };
  if (change.target_velocity) {
    // The one part the drive can refuse: try it first, so a refusal leaves everything as it was.
    const sdo_abort r = v.write(sim::object::target_velocity, 0, *change.target_velocity);
    if (r != sdo_abort::none) {
      const std::string what = "WRITE 0x60FF = " + std::to_string(*change.target_velocity);
      m.report_now(what, "refused", "refused: " + abort_text(r));
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

std::string instrument::info_json(bool control, bool token_required) const {
  std::lock_guard lock(impl_->mutex);
  json j = detail::profile_info(impl_->table);
  j["backend"] = "virtual";
  j["control"] = control;
  j["token_required"] = token_required;
  j["cycle_us"] = impl_->drive.constants().cycle_us;
  // Snapshots come at most this often (the plot holds a value across a gap between them).
  j["publish_ms"] = impl_->config.publish_every * impl_->drive.constants().cycle_us / 1000.0;
  // The virtual drive's plant takes every input the page offers.
  j["capabilities"] = {
      {"fault", true}, {"dc_link", true}, {"sto", true}, {"reasons", json::object()}};
  return j.dump();
}

std::string instrument::snapshot_json() const {
  std::lock_guard lock(impl_->mutex);
  json j = impl_->snapshot(true);
  j["version"] = impl_->newest.version;
  return j.dump();
}

std::optional<published> instrument::wait_for_update(std::uint64_t seen,
                                                     std::chrono::milliseconds timeout) {
  std::unique_lock lock(impl_->mutex);
  impl_->updated.wait_for(lock, timeout,
                          [&] { return impl_->is_closed || impl_->newest.version > seen; });
  if (impl_->newest.version > seen) return impl_->newest;
  return std::nullopt;
}

published instrument::latest() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->newest;
}

void instrument::close() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->is_closed = true;
  }
  impl_->updated.notify_all();
}

bool instrument::closed() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->is_closed;
}

}  // namespace cia402::page
