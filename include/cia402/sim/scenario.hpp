// Scenarios: one virtual drive, a header (profile, cycle, plant, objects written at power-up),
// timed events and expectations, read from TOML. A scenario is a test: run_scenario() checks every
// expectation and says which failed. The format is described in examples/scenarios/README.md.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"
#include "cia402/sim/plant.hpp"
#include "cia402/sim/trace.hpp"
#include "cia402/state.hpp"

namespace cia402::sim {

/// Why a scenario file was refused: 1-based line and column (0 = the whole file) and a reason.
struct scenario_error {
  int line = 0;
  int column = 0;
  std::string reason;
  std::string source_name;
  /// "quick-stop.toml:12:5: unknown state 'operaton_enabled'".
  std::string message() const;
};

/// One action at one cycle. An event of the file may hold several; they run in a fixed order of
/// kinds (examples/scenarios/README.md): writes, then power and connection, then faults.
struct scenario_event {
  enum class kind : std::uint8_t {
    write,          ///< index, value through write_object (cw, target_velocity, write = {...}, ...)
    inject_fault,   ///< code, fault_class
    clear_fault,    ///< code
    clear_faults,
    dc_link,        ///< flag: voltage present
    sto,            ///< flag: STO active
    connection_lost ///< flag
  };
  std::uint64_t cycle = 0;
  int line = 0;
  kind what = kind::write;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::int64_t value = 0;
  std::uint16_t code = 0;
  std::uint8_t fault_class = 2;
  bool flag = false;
  /// For writes: the abort the scenario expects (sdo_abort::none = success expected).
  sdo_abort expected_abort = sdo_abort::none;
};

/// Physics and safety rules an `always` expectation checks on every cycle.
enum class invariant : std::uint8_t {
  /// Torque goes off at the end of a ramped stop only once the brake has engaged (a coast, STO or a
  /// Disable voltage that interrupts the stop is exempt: it removes torque at once by design).
  brake_engaged_before_torque_off,
  /// The speed never grows while the brake was holding at the start of the cycle.
  motion_waits_for_brake_release,
  /// In a cycle that coasts (ramp coast) or has STO active, torque is off.
  coast_removes_torque_at_once,
};

/// "brake_engaged_before_torque_off", ...; never null.
const char* invariant_name(invariant i) noexcept;

/// Whether a rule holds at `row`, given the row before it (nullptr for the first cycle); if not,
/// `why` says what broke it.
bool invariant_holds(invariant rule, const profile& p, const trace_row* previous,
                     const trace_row& row, std::string& why);

/// One checked claim about the run.
struct expectation {
  enum class kind : std::uint8_t {
    state, velocity, statusword, torque, brake, error_code, transition, always, position, mode
  };
  enum class compare : std::uint8_t { equal, below, above, within };
  int line = 0;
  int column = 0;
  kind what = kind::state;
  /// The cycles it looks at: [first, last]. `at` gives first == last; `between` a window, in which a
  /// transition must happen at least once and every other claim must hold throughout.
  std::uint64_t first_cycle = 0;
  std::uint64_t last_cycle = 0;
  bool window = false;
  state expected_state = state::start;
  compare how = compare::equal;
  std::int64_t low = 0;     ///< micro-rpm (velocity), increments (position), or the value
  std::int64_t high = 0;    ///< micro-rpm (velocity within), or the mask (statusword)
  bool flag = false;        ///< torque on / brake engaged
  std::uint8_t transition = 0;
  invariant rule = invariant::brake_engaged_before_torque_off;
};

/// A parsed, checked scenario: ready to run, nothing left to refuse.
struct scenario {
  std::string name;
  std::string source_name;
  custom_profile drive_profile;
  plant_config plant;
  bool dc_link_at_start = true;
  bool sto_at_start = false;
  /// Objects written before power-up (option codes, ramps, 0x60FF), already known to succeed.
  struct object_write {
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    std::int64_t value = 0;
  };
  std::vector<object_write> initial_writes;
  /// Cycles run: times 0, cycle, ..., duration.
  std::uint64_t cycles = 0;
  std::vector<scenario_event> events;  ///< sorted by cycle, then file order
  std::vector<expectation> expectations;
};

using scenario_load_result = std::variant<scenario, scenario_error>;

/// Parses a scenario. `base_dir` resolves a relative `profile_file`. Every mistake (TOML syntax,
/// unknown or repeated keys, wrong types, unknown names, times that are not a multiple of the cycle
/// or lie past the duration, objects at power-up the drive refuses) is refused with its line.
scenario_load_result load_scenario_toml(std::string_view text, std::string_view source_name,
                                        const std::string& base_dir = ".");
scenario_load_result load_scenario_file(const std::string& path);

/// One line of the run's log.
struct log_entry {
  enum class kind : std::uint8_t { event, transition, expectation, note };
  std::uint64_t time_us = 0;
  kind what = kind::note;
  bool failed = false;  ///< an expectation or an event that did not go as the scenario says
  std::string text;
};

struct run_result {
  std::vector<trace_row> trace;  ///< one row per cycle (empty unless asked for)
  std::vector<log_entry> log;
  int checks = 0;    ///< expectations and expected-abort checks evaluated
  int failures = 0;
  bool passed() const noexcept { return failures == 0; }
};

struct run_options {
  bool record_trace = true;
};

/// Runs the scenario on a fresh virtual drive from power-up.
run_result run_scenario(const scenario& s, const run_options& options = {});

/// The log line as `cia402 simulate` prints it: "   0.600 s  T11  OPERATION_ENABLED -> ...".
std::string format_log_entry(const log_entry& e);

}  // namespace cia402::sim
