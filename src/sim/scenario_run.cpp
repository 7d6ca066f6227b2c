// Running a scenario: one virtual drive from power-up, the events applied at the start of their
// cycle, every expectation checked against the cycle it names, and a log a person can read.
#include <string>

#include "cia402/objects.hpp"
#include "cia402/sdo_abort.hpp"
#include "cia402/sim/scenario.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/support/text.hpp"
#include "cia402/words.hpp"

namespace cia402::sim {
namespace {

using support::hex;

std::string short_seconds(std::uint64_t us) {
  const std::string full = format_seconds(us);  // "1.250000"
  return us % 1000 == 0 ? full.substr(0, full.size() - 3) : full;
}

std::string describe_control_word(const profile& p, std::uint16_t cw) {
  std::string s = "cw " + hex(cw, 4) + " (" + command_name(p.decode(cw));
  if (cw & control_bit::fault_reset) s += " + FAULT_RESET bit";
  if (cw & control_bit::halt) s += " + HALT";
  return s + ")";
}

std::string describe_write(const profile& p, std::uint16_t index, std::int64_t value) {
  switch (index) {
    case object::control_word:
      return value >= 0 && value <= 0xFFFF
                 ? describe_control_word(p, static_cast<std::uint16_t>(value))
                 : "cw " + std::to_string(value);
    case object::target_velocity: return "target velocity 0x60FF = " + std::to_string(value) + " rpm";
    case object::target_position: return "target position 0x607A = " + std::to_string(value);
    case object::target_torque: return "target torque 0x6071 = " + std::to_string(value) + " permille";
    case object::modes_of_operation:
      return "mode 0x6060 = " + std::to_string(value) + " (" + mode::short_name(value) + ")";
    case object::profile_acceleration:
      return "acceleration 0x6083 = " + std::to_string(value) + " rpm/s";
    case object::profile_deceleration:
      return "deceleration 0x6084 = " + std::to_string(value) + " rpm/s";
    case object::quick_stop_deceleration:
      return "quick-stop deceleration 0x6085 = " + std::to_string(value) + " rpm/s";
    default: return "write " + hex(index, 4) + " = " + std::to_string(value);
  }
}

std::string when(const scenario& s, const expectation& e) {
  const std::uint64_t c = s.plant.cycle_us;
  if (!e.window) return "at " + short_seconds(e.first_cycle * c) + " s";
  return "between " + short_seconds(e.first_cycle * c) + " s and " +
         short_seconds(e.last_cycle * c) + " s";
}

std::string velocity_claim(const expectation& e) {
  switch (e.how) {
    case expectation::compare::equal: return "velocity = " + format_rpm(e.low) + " rpm";
    case expectation::compare::below: return "velocity < " + format_rpm(e.low) + " rpm";
    case expectation::compare::above: return "velocity > " + format_rpm(e.low) + " rpm";
    case expectation::compare::within:
      return "velocity within [" + format_rpm(e.low) + ", " + format_rpm(e.high) + "] rpm";
  }
  return "velocity";
}

std::string claim(const expectation& e) {
  switch (e.what) {
    case expectation::kind::state: return std::string("state ") + state_name(e.expected_state);
    case expectation::kind::velocity: return velocity_claim(e);
    case expectation::kind::statusword:
      return e.high == 0xFFFF ? "statusword " + hex(static_cast<std::uint32_t>(e.low), 4)
                              : "statusword & " + hex(static_cast<std::uint32_t>(e.high), 4) +
                                    " = " + hex(static_cast<std::uint32_t>(e.low), 4);
    case expectation::kind::torque: return e.flag ? "torque on" : "torque off";
    case expectation::kind::brake: return e.flag ? "brake engaged" : "brake released";
    case expectation::kind::error_code:
      return "error code " + hex(static_cast<std::uint32_t>(e.low), 4);
    case expectation::kind::transition: return "transition T" + std::to_string(e.transition);
    case expectation::kind::position:
      return e.how == expectation::compare::within
                 ? "position within [" + std::to_string(e.low) + ", " + std::to_string(e.high) + "]"
                 : "position " + std::to_string(e.low);
    case expectation::kind::mode: return "mode " + std::to_string(e.low) + " (" + mode::short_name(e.low) + ")";
    case expectation::kind::always: return std::string("always ") + invariant_name(e.rule);
  }
  return "?";
}

// Whether a row satisfies a claim (not for transitions and rules), and what it shows instead.
bool holds(const expectation& e, const trace_row& r, std::string& actual) {
  switch (e.what) {
    case expectation::kind::state:
      actual = std::string("state is ") + state_name(r.current);
      return r.current == e.expected_state;
    case expectation::kind::velocity: {
      actual = "velocity is " + format_rpm(r.velocity) + " rpm";
      switch (e.how) {
        case expectation::compare::equal: return r.velocity == e.low;
        case expectation::compare::below: return r.velocity < e.low;
        case expectation::compare::above: return r.velocity > e.low;
        case expectation::compare::within: return r.velocity >= e.low && r.velocity <= e.high;
      }
      return false;
    }
    case expectation::kind::statusword:
      actual = "statusword is " + hex(r.status_word, 4);
      return (r.status_word & e.high) == e.low;
    case expectation::kind::torque:
      actual = r.torque ? "torque is on" : "torque is off";
      return r.torque == e.flag;
    case expectation::kind::brake:
      actual = r.brake_engaged ? "brake is engaged" : "brake is released";
      return r.brake_engaged == e.flag;
    case expectation::kind::error_code:
      actual = "error code is " + hex(r.error_code, 4);
      return r.error_code == e.low;
    case expectation::kind::position:
      actual = "position is " + std::to_string(r.position);
      return e.how == expectation::compare::within ? r.position >= e.low && r.position <= e.high
                                                   : r.position == e.low;
    case expectation::kind::mode:
      actual = "mode is " + std::to_string(r.mode);
      return r.mode == e.low;
    case expectation::kind::transition:
    case expectation::kind::always: break;
  }
  return false;
}

bool ramped(stop_ramp r) {
  return r == stop_ramp::slow_down || r == stop_ramp::quick_stop ||
         r == stop_ramp::current_limit || r == stop_ramp::voltage_limit;
}

std::int64_t magnitude(std::int64_t v) { return v < 0 ? -v : v; }

}  // namespace

bool invariant_holds(invariant rule, const profile& p, const trace_row* prev, const trace_row& r,
                     std::string& why) {
  switch (rule) {
    case invariant::brake_engaged_before_torque_off:
      if (prev && prev->torque && !r.torque && ramped(prev->ramp) && r.ramp != stop_ramp::coast &&
          !r.sto && p.decode(r.control_word) != command::disable_voltage && !r.brake_engaged) {
        why = std::string("torque went off after a ") + stop_ramp_name(prev->ramp) +
              " stop while the brake was not engaged";
        return false;
      }
      return true;
    case invariant::motion_waits_for_brake_release:
      if (prev && prev->brake_engaged && magnitude(r.velocity) > magnitude(prev->velocity)) {
        why = "the speed grew from " + format_rpm(prev->velocity) + " to " +
              format_rpm(r.velocity) + " rpm while the brake was engaged";
        return false;
      }
      return true;
    case invariant::coast_removes_torque_at_once:
      if ((r.ramp == stop_ramp::coast || r.sto) && r.torque) {
        why = r.sto ? "torque is on with STO active" : "torque is on in a coasting cycle";
        return false;
      }
      return true;
  }
  return true;
}

namespace {

struct tracker {
  enum class status : std::uint8_t { pending, passed, failed };
  status now = status::pending;
};

class runner {
 public:
  runner(const scenario& s, const run_options& o)
      : s_(s), p_(s.drive_profile.get()), drive_(p_, s.plant), options_(o),
        trackers_(s.expectations.size()) {}

  run_result run() {
    drive_view v = drive_.view();
    for (const scenario::object_write& w : s_.initial_writes) v.write(w.index, w.sub, w.value);
    v.set_dc_link(s_.dc_link_at_start);
    v.set_sto(s_.sto_at_start);
    if (options_.record_trace) result_.trace.reserve(static_cast<std::size_t>(s_.cycles));

    std::size_t next_event = 0;
    trace_row prev;
    for (std::uint64_t c = 0; c < s_.cycles; ++c) {
      const std::uint64_t t = drive_.time_us();
      while (next_event < s_.events.size() && s_.events[next_event].cycle == c) {
        apply(s_.events[next_event++], t);
      }
      const state before = v.current();
      trace_row row = begin_row(t, drive_.constants(), v.state_of_axis());
      const drive_outputs out = drive_.step();
      complete_row(row, out);
      if (out.transition != no_transition) log_transition(row, before, t);
      check(c, row, c > 0 ? &prev : nullptr);
      if (options_.record_trace) result_.trace.push_back(row);
      prev = row;
    }
    const std::uint64_t end = (s_.cycles - 1) * s_.plant.cycle_us;
    for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
      if (trackers_[i].now == tracker::status::pending) {
        const expectation& e = s_.expectations[i];
        finish(i, e.what == expectation::kind::always, end, "");
      }
    }
    return std::move(result_);
  }

 private:
  void log(std::uint64_t t, log_entry::kind k, bool failed, std::string text) {
    result_.log.push_back({t, k, failed, std::move(text)});
  }

  void apply(const scenario_event& e, std::uint64_t t) {
    drive_view v = drive_.view();
    const std::string at_line = " (line " + std::to_string(e.line) + ")";
    switch (e.what) {
      case scenario_event::kind::write: {
        const sdo_abort r = v.write(e.index, e.sub, e.value);
        std::string text = describe_write(p_, e.index, e.value);
        const std::string got = sdo_abort_words(r).c_str();
        const std::string expected = sdo_abort_words(e.expected_abort).c_str();
        bool failed = false;
        if (e.expected_abort != sdo_abort::none) {
          ++result_.checks;
          if (r == e.expected_abort) {
            text += ": refused as expected, " + got;
          } else {
            failed = true;
            text += r == sdo_abort::none ? ": accepted, but the scenario expects " + expected
                                         : ": refused with " + got + ", but the scenario expects " + expected;
          }
        } else if (r != sdo_abort::none) {
          ++result_.checks;
          failed = true;
          text += ": refused, " + got;
        }
        if (failed) ++result_.failures;
        log(t, log_entry::kind::event, failed, text + at_line);
        return;
      }
      case scenario_event::kind::inject_fault: {
        const bool kept = v.inject_fault(e.code, e.fault_class);
        std::string text = "fault cause " + hex(e.code, 4);
        if (p_.error_classes) text += " (class " + std::to_string(e.fault_class) + ")";
        if (!kept) text += "; the oldest cause was dropped (at most " +
                           std::to_string(max_fault_causes) + " at once)";
        log(t, log_entry::kind::event, false, text + at_line);
        return;
      }
      case scenario_event::kind::clear_fault: {
        const bool was = v.clear_fault(e.code);
        log(t, log_entry::kind::event, false,
            "fault cause " + hex(e.code, 4) + (was ? " cleared" : " cleared (it was not present)") +
                at_line);
        return;
      }
      case scenario_event::kind::clear_faults:
        v.clear_faults();
        log(t, log_entry::kind::event, false, "every fault cause cleared" + at_line);
        return;
      case scenario_event::kind::dc_link:
        v.set_dc_link(e.flag);
        log(t, log_entry::kind::event, false,
            std::string(e.flag ? "DC-link voltage present" : "DC-link voltage lost") + at_line);
        return;
      case scenario_event::kind::sto:
        v.set_sto(e.flag);
        log(t, log_entry::kind::event, false,
            std::string(e.flag ? "STO active (safe torque off)" : "STO released") + at_line);
        return;
      case scenario_event::kind::connection_lost:
        v.set_connection_lost(e.flag);
        log(t, log_entry::kind::event, false,
            std::string(e.flag ? "fieldbus connection lost" : "fieldbus connection restored") +
                at_line);
        return;
    }
  }

  void log_transition(const trace_row& r, state before, std::uint64_t t) {
    std::string text = std::string(state_name(before)) + " -> " + state_name(r.current) + "  sw " +
                       hex(r.status_word, 4) + "  v " + format_rpm(r.velocity) + " rpm  torque " +
                       (r.torque ? "on" : "off") + "  brake " +
                       (r.brake_engaged ? "engaged" : "released") +
                       (r.ramp != stop_ramp::none ? std::string("  ramp ") + stop_ramp_name(r.ramp)
                                                  : std::string());
    if (r.error_code != 0) text += "  error " + hex(r.error_code, 4);
    result_.log.push_back({t, log_entry::kind::transition, false,
                           "T" + std::to_string(r.transition) + "\t" + text});
  }

  void finish(std::size_t i, bool pass, std::uint64_t t, const std::string& detail) {
    const expectation& e = s_.expectations[i];
    trackers_[i].now = pass ? tracker::status::passed : tracker::status::failed;
    ++result_.checks;
    if (!pass) ++result_.failures;
    std::string text = claim(e);
    if (e.what != expectation::kind::always) text += " " + when(s_, e);
    text += " (line " + std::to_string(e.line) + ")";
    if (!detail.empty()) text += ": " + detail;
    log(t, log_entry::kind::expectation, !pass, text);
  }

  void check(std::uint64_t c, const trace_row& r, const trace_row* prev) {
    const std::uint64_t t = r.time_us;
    for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
      if (trackers_[i].now != tracker::status::pending) continue;
      const expectation& e = s_.expectations[i];
      if (c < e.first_cycle || c > e.last_cycle) continue;
      if (e.what == expectation::kind::always) {
        std::string why;
        if (!invariant_holds(e.rule, p_, prev, r, why)) finish(i, false, t, why);
        continue;
      }
      if (e.what == expectation::kind::transition) {
        if (r.transition == e.transition) {
          finish(i, true, t, e.window ? "taken at " + short_seconds(t) + " s" : "");
        } else if (c == e.last_cycle) {
          finish(i, false, t,
                 e.window ? "not taken in the window" : "not taken then" +
                     (r.transition != no_transition ? " (T" + std::to_string(r.transition) + " was)"
                                                    : std::string()));
        }
        continue;
      }
      std::string actual;
      if (!holds(e, r, actual)) {
        finish(i, false, t, e.window ? actual + " at " + short_seconds(t) + " s" : actual);
      } else if (c == e.last_cycle) {
        finish(i, true, t, "");
      }
    }
  }

  const scenario& s_;
  const profile& p_;
  virtual_drive drive_;
  run_options options_;
  std::vector<tracker> trackers_;
  run_result result_;
};

}  // namespace

run_result run_scenario(const scenario& s, const run_options& options) {
  return runner(s, options).run();
}

std::string format_log_entry(const log_entry& e) {
  std::string time = short_seconds(e.time_us) + " s";
  if (time.size() < 11) time.insert(0, 11 - time.size(), ' ');
  std::string tag;
  std::string text = e.text;
  switch (e.what) {
    case log_entry::kind::event: tag = e.failed ? "FAIL" : "event"; break;
    case log_entry::kind::transition: {
      const std::size_t tab = text.find('\t');
      tag = text.substr(0, tab);
      text = text.substr(tab + 1);
      break;
    }
    case log_entry::kind::expectation: tag = e.failed ? "FAIL" : "pass"; break;
    case log_entry::kind::note: tag = "note"; break;
  }
  tag.resize(6, ' ');
  return time + "  " + tag + text;
}

}  // namespace cia402::sim
