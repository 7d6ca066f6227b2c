// What became of the page's actions: the `results` of its snapshots, kept alike by both backends.
// An action is either reported at once, or tracked until the drive settles and then reported with
// the transitions it led to. One action is tracked at a time: a new one reports the tracked one as
// it stands. Not thread-safe: it lives under its backend's lock.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cia402/state.hpp"

namespace cia402::page::detail {

struct result_entry {
  std::uint64_t id = 0;
  std::string action;
  std::string outcome;  // "pending", "done", "nothing to do", "waiting", "refused"
  std::string text;
  std::vector<int> transitions;
};

class action_log {
 public:
  using json = nlohmann::ordered_json;

  /// Times are in the backend's own clock: cycles of the virtual drive, microseconds on the bus.
  struct rules {
    std::size_t kept = 8;           ///< results the page is shown, newest first
    std::uint64_t settle_quiet = 0; ///< settled once nothing went on for this long
    std::uint64_t settle_limit = 0; ///< reported as it stands once tracked for this long
    std::string gave_up_note;       ///< said of an action reported at settle_limit
    std::string transitions_note;   ///< after "done: T3 -> ...", e.g. that the numbers are inferred
  };

  /// How the drive stands when a tracked action is reported: what the report says.
  struct standing {
    state now = state::start;  ///< where the action's transitions led
    std::string now_name;      ///< the present state as the page shows it (maybe "UNKNOWN")
    /// What may have kept a command from acting, " (STO asserted, ...)", or "".
    std::string conditions;
    /// What holds a command back that will act once it is gone: "STO asserted", "no DC-link
    /// voltage", "a stop is ramping"; "" if nothing does.
    std::string waiting_for;
  };

  /// What a command asks of the drive where it is now, judged when it is given.
  enum class expectation : std::uint8_t {
    act,             ///< a transition is expected
    already_there,   ///< the command leads to the present state: nothing to do
    edge,            ///< a fault-reset edge: used once, it does not wait for anything
  };

  /// An action waiting for the drive to settle.
  struct tracked {
    std::uint64_t id = 0;
    std::string action;
    std::optional<state> before;  ///< none: the state was not known
    std::uint64_t started = 0;
    std::uint64_t busy_until = 0;  ///< the last time something went on (transition, stop, ...)
    std::vector<int> transitions;
    bool refused_without_transition = true;  ///< commands: yes; plant inputs: a plain report
    expectation expect = expectation::act;
  };

  /// `how_it_stands` is asked when a tracked action is reported.
  action_log(rules r, std::function<standing()> how_it_stands);

  /// Starts tracking an action (reporting it as pending); returns its id.
  std::uint64_t track(std::string action, bool refuse_without_transition,
                      std::optional<state> before, std::uint64_t now,
                      expectation expect = expectation::act);
  /// Reports an action that is over at once; returns its id.
  std::uint64_t report_now(std::string action, std::string outcome, std::string text);

  /// The action being tracked, or nullptr.
  tracked* pending() { return pending_ ? &*pending_ : nullptr; }
  /// Reports the tracked action as it stands; `why_unsettled` (if any) is added in parentheses.
  void finish_pending(const char* why_unsettled);
  /// Reports the tracked action as refused with `text`: what it asked for never took effect.
  void refuse_pending(std::string text);
  /// Once per cycle: `busy` says something still goes on (it keeps the action from settling).
  void settle(std::uint64_t now, bool busy);

  /// Replaces the result with r's id (an action reported as pending, now over).
  void update(result_entry r) { push(std::move(r)); }
  json results_json() const;

 private:
  void push(result_entry r);

  rules rules_;
  std::function<standing()> how_it_stands_;
  std::optional<tracked> pending_;
  std::deque<result_entry> results_;
  std::uint64_t next_id_ = 1;
};

}  // namespace cia402::page::detail
