// The page's recorder: what the drive did, cycle by cycle, kept in memory with a bound, for the
// page's transition history and timeline and for export as CSV and VCD (the simulator's own trace
// formats, sim/trace.hpp, so a recording opens wherever a `cia402 simulate` trace does).
//
// A cycle is kept when anything but the sampled values changed (every transition, word, input and
// mode), and otherwise at most once per `velocity_every_us` while the velocity, the position or the
// torque moves: a drive standing still costs nothing, a ramp or a move about 50 rows a second. The oldest rows go first when the bound is reached;
// the recording says how many went.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cia402/page/backend.hpp"
#include "cia402/sim/trace.hpp"
#include "cia402/state.hpp"

namespace cia402::page::detail {

class recorder {
 public:
  struct limits {
    std::size_t rows = 60000;         ///< about 20 minutes of a ramping drive, ~3 MB
    std::size_t transitions = 10000;  ///< the transition history
    std::uint64_t velocity_every_us = 20000;
  };

  /// One transition as the history shows it. `number` is empty when the observer could not tell
  /// which row fired (a remote drive); `inferred` when the number was inferred, not reported.
  struct transition {
    std::uint64_t seq = 0;
    std::uint64_t time_us = 0;
    std::optional<int> number;
    state from = state::start;
    state to = state::start;
    std::uint16_t control_word = 0;
    std::uint16_t status_word = 0;
    bool inferred = false;
  };

  recorder() : recorder(limits{}) {}
  explicit recorder(limits l) : limits_(l) {}

  /// One cycle. Kept when it differs from the last kept row in anything but the sampled values, or
  /// one of them (velocity, position, demand, torque) changed and velocity_every_us passed.
  void record(const sim::trace_row& row);
  /// A transition for the history (the row that showed it goes through record()).
  void note_transition(transition t);
  /// Forgets everything (a profile switch starts a new recording).
  void clear();

  /// What came after a previous answer's `rows_seen` and `transitions_seen` (0, 0: everything):
  /// {"rows_seen": R, "transitions_seen": T, "dropped_rows": D,
  ///  "rows": [[time_ms, cw, sw, state, transition|null, rpm, position, torque_permille], ...],
  ///  "transitions": [{"seq", "time_ms", "number", "from", "to", "control_word", "status_word",
  ///  "inferred"}, ...]}.
  nlohmann::ordered_json since_json(std::uint64_t row_since, std::uint64_t transition_since) const;
  std::size_t rows() const { return rows_.size(); }
  std::size_t transitions() const { return transitions_.size(); }

  /// The kept rows, with the last cycle recorded at its time so the file ends at "now" (the
  /// simulator's CSV: position, position_demand, torque_permille and mode are its last columns).
  void write_csv(std::ostream& out) const;
  /// IEEE 1364 VCD (state and ramp as integer codes named in a $comment), or with `gtkwave` the
  /// GTKWave form with `$var string`.
  void write_vcd(std::ostream& out, sim::trace_info info, bool gtkwave) const;
  /// The whole recording as a file of that format; `info` names it in a VCD.
  std::string file(recording_format format, const sim::trace_info& info) const;

 private:
  std::vector<sim::trace_row> kept_with_last() const;

  limits limits_;
  std::deque<sim::trace_row> rows_;
  std::uint64_t first_row_seq_ = 1;  // seq of rows_.front()
  std::uint64_t dropped_rows_ = 0;
  std::deque<transition> transitions_;
  std::uint64_t next_transition_seq_ = 1;
  std::optional<sim::trace_row> last_;  // the newest cycle, kept or not
};

}  // namespace cia402::page::detail
