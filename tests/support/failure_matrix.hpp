// The failure matrix's vocabulary (S20), shared by its runs over the fake link (tests/axis), the CAN
// link (tests/canopen) and the EtherCAT link (tests/ethercat): the motion commands, the failures
// injected, what an error may name for each, how a command is started on a session, and the one
// run with its checks that every bus makes.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cia402/axis/session.hpp"

namespace cia402::failure_matrix {

enum class kind { move, velocity, jog, csp, home, torque };
enum class failure { cancel, link_lost, fault, sto, dc_link_lost, refused_sdo };
inline constexpr kind kinds[] = {kind::move, kind::velocity, kind::jog, kind::csp, kind::home, kind::torque};
inline constexpr failure failures[] = {failure::cancel, failure::link_lost, failure::fault,
                                       failure::sto,    failure::dc_link_lost, failure::refused_sdo};

inline const char* name(kind k) {
  switch (k) {
    case kind::move: return "move";
    case kind::velocity: return "velocity";
    case kind::jog: return "jog";
    case kind::csp: return "csp stream";
    case kind::home: return "home";
    case kind::torque: return "torque";
  }
  return "?";
}

inline const char* name(failure f) {
  switch (f) {
    case failure::cancel: return "cancel";
    case failure::link_lost: return "link lost";
    case failure::fault: return "fault";
    case failure::sto: return "STO";
    case failure::dc_link_lost: return "DC link lost";
    case failure::refused_sdo: return "refused SDO";
  }
  return "?";
}

// What the error may name for each failure, once the request had not ended before it: the failure
// itself, or what the drive showed of it (STO before the enable is a transition that does not come,
// with the warning bit; a DC link gone before it is a refusal). A lost link is said in each bus's
// words: `link_lost`.
inline std::vector<std::string> cause_words(failure f, const std::string& link_lost) {
  switch (f) {
    case failure::cancel: return {"the client gave up"};
    case failure::link_lost: return {link_lost};
    case failure::fault: return {"error code 0x7121"};
    case failure::sto: return {"FAULT", "safe torque off"};
    case failure::dc_link_lost: return {"FAULT", "no DC link"};
    case failure::refused_sdo: return {"SDO abort 0x06090030"};
  }
  return {};
}

inline bool names_one(const std::string& error, const std::vector<std::string>& words) {
  for (const std::string& w : words) {
    if (error.find(w) != std::string::npos) return true;
  }
  return false;
}

// The same command of each kind on every bus.
inline void start(axes::session& s, kind k, axes::completion done) {
  switch (k) {
    case kind::move: s.move({2'000'000, false, 3000u}, std::move(done)); break;
    case kind::velocity: s.velocity(3000, std::move(done)); break;
    case kind::jog: s.jog(1500, 10'000'000, std::move(done)); break;
    case kind::csp: s.csp_stream(2'000'000, 1200, std::move(done)); break;
    case kind::home: s.home({std::int8_t{17}, 0}, std::move(done)); break;
    case kind::torque: s.torque(100, std::move(done)); break;
  }
}

// The moments of a run over a real bus: every 10 ms to `set_up_until_ms`, where the link and the
// session set the drive up and enable it, then every 50 ms from `running_from_ms` to 400 ms, where
// the command runs.
inline std::vector<int> moments(int set_up_until_ms, int running_from_ms) {
  std::vector<int> at;
  for (int ms = 0; ms <= set_up_until_ms; ms += 10) at.push_back(ms);
  for (int ms = running_from_ms; ms <= 400; ms += 50) at.push_back(ms);
  return at;
}

// The whole matrix: every command of every kind against every failure at every moment.
template <typename Run>
void for_every_case(const std::vector<int>& moments, Run run_one) {
  for (const kind k : kinds) {
    for (const failure f : failures) {
      for (const int at : moments) run_one(k, f, at);
    }
  }
}

// A bench's clock in steps of 1 ms over its own tick() (the session's poll and the drive's time).
template <typename Bench>
struct ms_clock {
  /// Ticks until `done` says so, at most `ms`; true if it did.
  bool run_until(const std::function<bool()>& done, int ms) {
    for (int i = 0; i < ms; ++i) {
      self().tick();
      if (done()) return true;
    }
    return false;
  }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) self().tick();
  }
  /// Issues a request and runs until it has ended; the result (end failed with "no end" if never).
  axes::result finish(const std::function<void(axes::completion)>& request, int ms = 20000) {
    std::optional<axes::result> got;
    request([&got](const axes::result& r) { got = r; });
    if (!run_until([&] { return got.has_value(); }, ms)) {
      axes::result r;
      r.end = axes::outcome::failed;
      r.error = "no end within the test's time";
      return r;
    }
    return *got;
  }

 private:
  Bench& self() { return static_cast<Bench&>(*this); }
};

// What differs between the buses' runs.
struct bus_traits {
  std::string link_lost_words;     // how this bus says a lost link
  int end_slack_ms;                // beyond the failure stop's three stages, the time to say the end
  int quick_standstill_ms;         // where the session stopped the shaft (cancel, refused SDO)
  bool drive_seen_after_link_loss; // the bus lets the test watch the drive stop on its own
};

// One run on a fresh bench `b`: the command of kind `k`, the failure `f` after `at_ms`, then the
// checks. Whatever happens, the request ends within the bound, its error names the cause, the shaft
// ends at standstill wherever the bus still reaches the drive, and a drive that did not fault takes
// the next command without a reset. The bench offers `s` (the session), run_ms(), run_until(),
// finish(), view() (the virtual drive) and clear_refusals(); `inject(b, f)` makes the failure.
template <typename Bench, typename Inject>
void check_run(Bench& b, kind k, failure f, int at_ms, const bus_traits& on, Inject inject) {
  std::optional<axes::result> got;
  start(*b.s, k, [&](const axes::result& res) { got = res; });
  b.run_ms(at_ms);
  const bool ended_before = got.has_value();
  const bool enabled = b.view().current() == state::operation_enabled;
  inject(b, f);
  // The bound: the failure stop's three stages, and the time to say it.
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 3 * 10'000 + on.end_slack_ms))
      << "the request never ended";
  if (ended_before || got->ok()) return;  // the failure came after the end, or changed nothing the command needed
  EXPECT_TRUE(names_one(got->error, cause_words(f, on.link_lost_words))) << got->error;
  if (f == failure::link_lost) {
    // What the drive does then, said where the command had it enabled.
    if (enabled) EXPECT_NE(got->error.find("0x6007"), std::string::npos) << got->error;
    // Out of the session's hands: the drive stops as its 0x6007 says, where the test can see it.
    if (enabled && on.drive_seen_after_link_loss) {
      EXPECT_TRUE(b.run_until([&] { return std::abs(b.view().velocity_rpm()) <= 1; }, 30'000))
          << got->error << " (" << b.view().velocity_rpm() << " rpm)";
    }
    return;
  }
  // At standstill: at once where the session stopped it; after the drive's own fault reaction (or a
  // coast under STO) where the drive took over.
  const bool session_stopped = f == failure::cancel || f == failure::refused_sdo;
  const bool stands = b.run_until([&] { return std::abs(b.view().velocity_rpm()) <= 1; },
                                  session_stopped ? on.quick_standstill_ms : 30'000);
  EXPECT_TRUE(stands) << got->error << " (" << b.view().velocity_rpm() << " rpm)";
  if (session_stopped) {
    EXPECT_NE(b.view().current(), state::fault) << got->error;
    b.clear_refusals();
    // The next command runs without a reset.
    const axes::result next = b.finish([&](axes::completion d) { return b.s->velocity(100, std::move(d)); });
    EXPECT_TRUE(next.ok()) << next.error;
  }
}

// The trace of one run.
inline std::string where(kind k, failure f, int at_ms) {
  return std::string(name(k)) + ", " + name(f) + " at " + std::to_string(at_ms) + " ms";
}

}  // namespace cia402::failure_matrix
