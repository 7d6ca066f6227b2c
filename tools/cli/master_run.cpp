// `cia402 master`'s runner: one axis session per drive, the steps in order (each on every drive,
// the next when all are through), the bus's clock, SIGINT and SIGTERM, and the end: each session
// closed so its link puts back what it changed (on a signal the drives are first stopped as their
// 0x6007 says, as a lapsed lease would).
#include <cstdlib>
#include <memory>
#include <ostream>

#include "cia402/axis/session.hpp"
#include "cli/common.hpp"
#include "cli/master.hpp"
#include "cli/master_buses.hpp"
#include "cli/master_output.hpp"
#include "cli/master_steps.hpp"

namespace cia402::cli {
namespace {

constexpr int usage_error = 2;
constexpr int failed = 1;
// How long closing may take: a stop to standstill and the writes that put the node back.
constexpr std::uint64_t close_limit_us = 10'000'000;

bool stop_signal() { return stop_signals::flag() != 0; }

class runner {
 public:
  runner(const master_args& a, const profile& p, master_bus& bus, master_output& out) : a_(a), bus_(bus), out_(out) {
    axes::session_config c;
    c.drive_profile = &p;
    for (const master_bus::drive& d : bus.drives()) {
      auto r = std::make_unique<running>();
      r->d = d;
      r->session = std::make_unique<axes::session>(*d.link, c);
      watch_events(*r);
      drives_.push_back(std::move(r));
    }
  }

  int run(const std::vector<master_step>& steps) {
    for (const master_step& s : steps) {
      if (!run_step(s)) break;
    }
    if (status_ == 0 && a_.hold) {
      while (!stop_signal()) (void)pump();
    }
    close_all(stop_signal());
    bus_.finish(out_);
    return status_;
  }

 private:
  struct running {
    master_bus::drive d;
    std::unique_ptr<axes::session> session;
    bool pending = false;
    std::optional<std::int64_t> velocity_shown;
  };

  void watch_events(running& r) {
    axes::session& s = *r.session;
    const drive_tag tag = r.d.tag;
    s.on_state = [this, tag, &s](state, state to, std::uint16_t sw) { out_.state(tag, to, sw, s.error_code()); };
    s.on_emergency = [this, tag](std::uint16_t code, std::uint8_t reg, std::span<const std::uint8_t> bytes) {
      out_.emergency(tag, code, reg, !bytes.empty());
    };
    s.on_link = [this, tag, &s](axes::link_event e, const std::string& text) {
      if (e == axes::link_event::cyclic) return out_.started(tag, s.link());
      if (e == axes::link_event::failed || e == axes::link_event::restarted) {
        out_.drive(tag, {{"event", "link"}, {"phase", e == axes::link_event::failed ? "failed" : "restarted"}, {"text", text}}, text);
      }
    };
    s.on_progress = [this, tag, &s](axes::progress_kind kind, const axes::result& res) {
      out_.progress(tag, kind, res, bus_.stream_words(s.link().cycle_us()), s.link().cycle_us());
    };
  }

  // One pass: wait for the next thing to do, every session's work, an in-process drive's answer
  // and the sessions again. The microseconds that passed.
  std::uint32_t pump() {
    const std::uint32_t elapsed = bus_.wait(next_us_);
    std::uint32_t next = 0xFFFFFFFFu;
    for (auto& r : drives_) next = std::min(next, r->session->poll(elapsed));
    bus_.settle();
    for (auto& r : drives_) next = std::min(next, r->session->poll(0));
    next_us_ = next;
    if (watching_) show_velocities();
    return elapsed;
  }

  // While watching: a line when the velocity moved by 10 rpm or more since the last one, or stopped.
  void show_velocities() {
    for (auto& r : drives_) {
      const auto v = r->session->actual(object_index::velocity_actual_value);
      if (!v || (r->velocity_shown && (*r->velocity_shown == *v || (std::abs(*v - *r->velocity_shown) < 10 && *v != 0)))) {
        continue;
      }
      r->velocity_shown = *v;
      out_.drive(r->d.tag, {{"event", "velocity"}, {"velocity_rpm", *v}}, "velocity " + std::to_string(*v) + " rpm");
    }
  }

  bool run_step(const master_step& s) {
    if (s.verb == "wait") return pass_time(s, static_cast<std::uint64_t>(s.number) * 1000, false);
    if (s.verb == "nmt") {
      for (auto& r : drives_) {
        if (const auto why = bus_.nmt(r->d, s.nmt)) return fail(r->d.tag, s, *why, usage_error);
        out_.drive(r->d.tag, {{"event", "nmt"}, {"command", s.nmt}}, "NMT " + s.nmt + " sent");
      }
      (void)pump();
      return true;
    }
    for (auto& r : drives_) {
      if (!start(*r, s)) return false;
    }
    if (!until_done(s)) return false;
    if (s.verb == "watch") {
      watching_ = true;
      const bool ok = pass_time(s, std::uint64_t{a_.timeout_ms} * 1000, true);
      watching_ = false;
      return ok;
    }
    return true;
  }

  // Keeps the sessions running for `us` (0 with `until_signal`: until a signal); a signal ends a
  // watch as it is meant to end, and interrupts a wait.
  bool pass_time(const master_step& s, std::uint64_t us, bool until_signal) {
    std::uint64_t passed = 0;
    while (us == 0 ? until_signal : passed < us) {
      if (stop_signal()) {
        if (until_signal) break;
        return interrupted(s);
      }
      passed += pump();
    }
    for (auto& r : drives_) {
      out_.drive(r->d.tag, {{"event", s.verb == "watch" ? "watched" : "waited"}, {"ms", passed / 1000}},
                 (s.verb == "watch" ? "watched " : "waited ") + std::to_string(passed / 1000) + " ms");
    }
    return true;
  }

  bool start(running& r, const master_step& s) {
    axes::session& ss = *r.session;
    r.pending = true;
    auto done = [this, &r, s](const axes::result& res) {
      r.pending = false;
      if (res.ok()) return out_.result(r.d.tag, s, res);
      fail(r.d.tag, s, res.error, res.bad_input ? usage_error : failed);
    };
    const std::string& v = s.verb;
    if (v == "state") ss.read_state(done);
    else if (v == "enable") ss.go_to(state::operation_enabled, done);
    else if (v == "disable") ss.go_to(state::switch_on_disabled, done);
    else if (v == "quick-stop") ss.quick_stop(done);
    else if (v == "reset") ss.reset(done);
    else if (v == "halt") ss.halt(s.on, done);
    else if (v == "mode") ss.set_mode(s.mode, done);
    else if (v == "move") ss.move({static_cast<std::int32_t>(s.number), s.relative, s.velocity ? std::optional<std::uint32_t>(static_cast<std::uint32_t>(*s.velocity)) : std::nullopt}, done);
    else if (v == "velocity") ss.velocity(static_cast<std::int32_t>(s.number), done);
    else if (v == "torque") ss.torque(static_cast<std::int16_t>(s.number), done);
    else if (v == "home") {
      axes::home_request h;
      if (s.method) h.method = static_cast<std::int8_t>(*s.method);
      if (s.offset) h.offset = static_cast<std::int32_t>(*s.offset);
      ss.home(h, done);
    } else if (v == "jog") ss.jog(static_cast<std::int32_t>(s.number), static_cast<std::uint64_t>(s.number2) * 1000, done);
    else if (v == "csp-stream") ss.csp_stream(static_cast<std::int32_t>(*s.to), static_cast<std::uint32_t>(*s.velocity), done);
    else if (v == "watch") ss.watch(done);
    else if (v == "sdo read") ss.read_object(s.index, s.sub, done);
    else if (v == "sdo write") {
      std::string why;
      const auto value = axes::parse_value(s.value, ss.format_of(s.index, s.sub), why);
      if (!value) {
        r.pending = false;
        return fail(r.d.tag, s, why, usage_error);
      }
      ss.write_object(s.index, s.sub, *value, done);
    }
    return true;
  }

  bool until_done(const master_step& s) {
    const std::uint64_t limit = std::uint64_t{a_.timeout_ms} * 1000;
    std::uint64_t passed = 0;
    const auto busy = [this] {
      for (auto& r : drives_) {
        if (r->pending) return true;
      }
      return false;
    };
    while (busy()) {
      if (stop_signal()) return interrupted(s);
      if (limit != 0 && passed >= limit && s.verb != "watch") {
        // S20: the session stops what the step set moving, then ends it with the cause and what it did.
        for (auto& r : drives_) {
          if (r->pending) r->session->cancel("did not finish within " + std::to_string(a_.timeout_ms) + " ms (" + situation(*r->session) + ")");
        }
        drain(s, "its stop did not end");
        return false;
      }
      passed += pump();
    }
    return status_ == 0;
  }

  static std::string situation(const axes::session& s) {
    if (s.link().phase() != axes::link_phase::running) return s.link().phase_text();
    if (!s.status_known()) return "no status word yet";
    std::string t = std::string("the drive shows ") + state_name(s.observed()) + ", statusword " + hex(s.status_word(), 4);
    if (s.error_code() != 0) t += ", error code " + hex(s.error_code(), 4);
    return t;
  }

  bool interrupted(const master_step& s) {
    for (auto& r : drives_) {
      if (r->pending) r->session->cancel("interrupted");
      else fail(r->d.tag, s, "interrupted", failed);
    }
    drain(s, "interrupted, and its stop did not end");
    return false;
  }

  // Runs the sessions until every cancelled step has ended (its stop has a bound of its own, three
  // stages of stop_timeout_us); one that still has not is reported as it stands.
  void drain(const master_step& s, const std::string& why) {
    const std::uint64_t limit = 3 * axes::session_config{}.stop_timeout_us + 1'000'000;
    for (std::uint64_t passed = 0; passed < limit;) {
      bool any = false;
      for (auto& r : drives_) any |= r->pending;
      if (!any) return;
      passed += pump();
    }
    for (auto& r : drives_) {
      if (!r->pending) continue;
      r->pending = false;
      fail(r->d.tag, s, why + " (" + situation(*r->session) + ")", failed);
    }
  }

  bool fail(const drive_tag& tag, const master_step& s, const std::string& why, int status) {
    out_.failure(tag, s.text, why);
    if (status_ != usage_error) status_ = status;
    return false;
  }

  void close_all(bool stop_first) {
    for (auto& r : drives_) r->session->close(stop_first);
    std::uint64_t passed = 0;
    const auto open = [this] {
      for (auto& r : drives_) {
        if (!r->session->closed()) return true;
      }
      return false;
    };
    while (open() && passed < close_limit_us) passed += pump();
    for (auto& r : drives_) {
      out_.closed(r->d.tag, r->session->closing());
      if (!r->session->closed()) {
        out_.failure(r->d.tag, "close", "did not finish putting the node back within " +
                                            std::to_string(close_limit_us / 1000) + " ms");
      }
    }
  }

  const master_args& a_;
  master_bus& bus_;
  master_output& out_;
  std::vector<std::unique_ptr<running>> drives_;
  std::uint32_t next_us_ = 0;
  bool watching_ = false;
  int status_ = 0;
};

}  // namespace

int run_master(const master_args& a, std::ostream& out, std::ostream& err) {
  master_output output(out, err, a.json);
  profile_choice choice;
  if (!choice.resolve(a.profile, a.profile_file, err)) return usage_error;
  std::string why;
  const auto steps = parse_master_steps(a.raw, why);
  if (!steps) {
    output.error(why);
    return usage_error;
  }
  if (!a.ecat.empty()) {
    for (const master_step& s : *steps) {
      if (s.verb == "nmt") {
        output.error("nmt is CANopen's: on EtherCAT the master keeps the line in OP (AL states), no NMT");
        return usage_error;
      }
    }
  }
  int status = 0;
  std::unique_ptr<master_bus> bus =
      a.ecat.empty() ? open_can_bus(a, choice.get(), *steps, output, status) : open_ecat_bus(a, choice.get(), output, status);
  if (!bus) return status;

  const stop_signals stop;
  runner r(a, choice.get(), *bus, output);
  return r.run(*steps);
}

}  // namespace cia402::cli
