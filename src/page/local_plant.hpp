// A drive simulated in this process, as the page reaches it beside the axis session. The session
// drives it as it drives a drive on a bus; what only the simulator has stays here: the plant's
// inputs (fault causes, DC link, STO), which are no object of the drive, and its own view, which
// tells what a bus cannot (the transition each step took, the plant columns of the recording).
// The page obtains it once per connection (of()): none for a drive on a bus, and each of the page's
// concerns decides there, in one place, whether it asks this or the session alone.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cia402/page/axis_page.hpp"
#include "cia402/sim/trace.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::page::detail {

class local_plant {
 public:
  /// The connection's plant; none for a drive on a bus.
  static std::optional<local_plant> of(const drive_connection& c);
  explicit local_plant(sim::virtual_drive& d) noexcept : drive_(&d) {}

  sim::drive_view view() const noexcept { return drive_->view(); }
  /// An object as the drive has it now; none where it refuses the read.
  std::optional<std::int64_t> read(std::uint16_t index, std::uint8_t sub) const;
  std::uint16_t error_code() const;

  /// The recording's row of the cycle under way, opened before its step (the values the drive reads
  /// as it begins); close_cycle() completes it once the step ran.
  const sim::trace_row& open_cycle();
  struct closed_cycle {
    sim::trace_row row;
    state before = state::start;  // the state the cycle began in
    drive_outputs out;            // what its step gave
  };
  /// None when no cycle is open or its step has not run yet.
  std::optional<closed_cycle> close_cycle();

  /// The plant's inputs that hold the drive back, as the action log words them.
  std::vector<std::string> conditions() const;
  /// What a tracked action waits for before it can settle; empty: nothing.
  std::string waiting_for() const;
  /// A stop still ramps: the drive keeps changing without anything sent.
  bool stop_ramping(const profile& p) const;
  std::string enable_blocker(state shown) const;
  /// The snapshot's drive part, the simulator's own values.
  void show(nlohmann::ordered_json& j, const profile& p) const;
  /// Sets the plant's inputs the change names (not the target velocity, the drive's object), each
  /// as the action log names it.
  std::vector<std::string> change_inputs(const plant_change& change);

 private:
  sim::virtual_drive* drive_;
  std::optional<sim::trace_row> open_row_;
  std::uint64_t open_row_cycle_ = 0;  // the simulator's cycle count when it began
  state open_row_state_ = state::start;
};

}  // namespace cia402::page::detail
