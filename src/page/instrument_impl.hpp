// The virtual drive behind the instrument page, inside: shared by instrument.cpp (the drive, its
// commands and snapshots) and instrument_commissioning.cpp (one-click enable, stop and jog).
#pragma once

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
#include "commissioning.hpp"
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

  // One-click enable and stop, and the jog (commissioning.hpp): at most one of each at a time.
  std::optional<detail::enable_walk> walk;
  struct stop_run {
    std::uint64_t id = 0;
    bool quick_stop_sent = false;  // Disable voltage follows once the drive left OPERATION ENABLED
    std::uint64_t until = 0;       // cycle after which it is reported as it stands
    std::vector<int> transitions;
  };
  std::optional<stop_run> stopping;
  std::optional<detail::jog_run> jogging;

  // --- under the lock ------------------------------------------------------------------------

  void apply_word(std::uint16_t word) {
    control_word = word;
    // The object interface takes any 16-bit control word.
    drive->write(sim::object::control_word, 0, word);
  }

  // Logs a command or bit toggle and gives its word to the drive from the next cycle on.
  std::uint64_t change_word(const detail::word_change& w) {
    end_walk("refused", "refused: interrupted by " + w.action);
    end_stop("interrupted by " + w.action);
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


  // --- one-click enable and stop, jog ---------------------------------------------------------

  state shown() const {
    state s = state::start;
    return decode_status(*table, drive->view().outputs().status_word, s) ? s : state::start;
  }

  std::string blocker(state s) const {
    const sim::drive_view v = drive->view();
    return detail::enable_blocker(s, v.outputs().error_code, v.sto(), v.dc_link());
  }

  void end_walk(const std::string& outcome, const std::string& text) {
    if (!walk) return;
    // A walk that stops short leaves no Enable operation in the word: it would act by itself once
    // the blocker (STO, DC link) is gone, a restart nobody asked for.
    std::uint16_t word = 0;
    if (outcome != "done" && table->decode(control_word) == command::enable_operation &&
        encode_command(*table, command::switch_on, control_word, word)) {
      apply_word(word);
    }
    log.update({walk->id, "ENABLE", outcome, text, walk->transitions});
    walk.reset();
  }

  // Each cycle: the status word confirms the last step before the next goes out (S17 paths).
  void walk_cycle() {
    if (!walk) return;
    const state s = shown();
    std::string steps;
    for (int t : walk->transitions) steps += (steps.empty() ? "T" : ", T") + std::to_string(t);
    if (s == state::operation_enabled) {
      return end_walk("done", "done: " + steps + " -> OPERATION_ENABLED, each step confirmed by the status word");
    }
    if (const std::string b = blocker(s); !b.empty()) {
      return end_walk("refused", "refused in " + std::string(state_name(s)) + ": " + b);
    }
    if (walk->expected && s != *walk->expected) {
      if (drive->cycle() < walk->deadline) return;
      return end_walk("refused", "refused: the status word shows " + std::string(state_name(s)) +
                                     ", not " + state_name(*walk->expected) + ", " +
                                     std::to_string(detail::enable_step_wait_us / 1000) +
                                     " ms after its command" + blocking_conditions());
    }
    const detail::walk_step next =
        detail::next_enable_step(*table, drive->view().state_of_axis().core, s, control_word);
    if (!next.refusal.empty()) return end_walk("refused", "refused: " + next.refusal);
    apply_word(next.word);
    walk->expected = next.after;
    const std::uint64_t cycle_us = drive->constants().cycle_us ? drive->constants().cycle_us : 1;
    walk->deadline = drive->cycle() + detail::enable_step_wait_us / cycle_us;
  }

  void end_stop(const std::string& why) {
    if (!stopping) return;
    log.update({stopping->id, "STOP", "refused",
                "refused: " + why + "; the drive is in " + state_name(drive->view().current()),
                stopping->transitions});
    stopping.reset();
  }

  // Quick stop until the drive left OPERATION ENABLED and stands, then Disable voltage; over in
  // SWITCH ON DISABLED, or in FAULT, where the power is off too.
  void stop_cycle() {
    if (!stopping) return;
    const state s = drive->view().current();
    if (s == state::switch_on_disabled || s == state::fault) {
      std::string steps;
      for (int t : stopping->transitions) steps += (steps.empty() ? "T" : ", T") + std::to_string(t);
      log.update({stopping->id, "STOP", "done",
                  "done: " + (steps.empty() ? std::string("no transition") : steps) + " -> " +
                      state_name(s),
                  stopping->transitions});
      stopping.reset();
      return;
    }
    // Disable voltage in QUICK STOP ACTIVE is T12 at once (the power goes, the shaft coasts): it
    // waits until the quick stop's ramp has brought the shaft to rest.
    const sim::drive_view v = drive->view();
    const bool at_rest = !cia402::stop_running(v.state_of_axis().core) && v.inputs().standstill;
    std::uint16_t word = 0;
    if (stopping->quick_stop_sent && s != state::operation_enabled && at_rest &&
        encode_command(*table, command::disable_voltage, control_word, word)) {
      apply_word(word);
      stopping->quick_stop_sent = false;
    }
    if (drive->cycle() > stopping->until) end_stop("not in SWITCH_ON_DISABLED in time" + blocking_conditions());
  }

  void end_jog(const std::string& why) {
    if (!jogging) return;
    (void)drive->write(sim::object::target_velocity, 0, 0);
    log.update({jogging->id, jogging->action, "done",
                "done: ran " + std::to_string((drive->time_us() - jogging->started_us) / 1000) +
                    " ms; 0x60FF = 0: " + why,
                {}});
    jogging.reset();
  }

  // The dead-man: 0x60FF = 0 in the first cycle at or after the keep-alive's time-to-live.
  void jog_cycle() {
    if (!jogging) return;
    if (drive->view().current() != state::operation_enabled) {
      end_jog("the drive left OPERATION_ENABLED");
    } else if (drive->time_us() >= jogging->expires_us) {
      end_jog("no keep-alive for " + std::to_string(jogging->time_to_live_us / 1000) + " ms");
    }
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
    jog_cycle();
    walk_cycle();
    stop_cycle();
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
      if (walk) walk->transitions.push_back(out.transition);
      if (stopping) stopping->transitions.push_back(out.transition);
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

}  // namespace cia402::page
