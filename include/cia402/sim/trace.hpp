// Traces of a virtual drive, one row per cycle, and the files made from them: CSV, JSON Lines, VCD
// (for GTKWave) and an SVG plot. CSV, JSONL and VCD print integers only (velocities are exact
// micro-rpm printed as decimals); the SVG's layout is computed in floating point from the same
// rows with fixed rounding. Equal traces give equal bytes in every format.
#pragma once

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "cia402/sim/plant.hpp"

namespace cia402::sim {

/// One cycle: the inputs the drive sampled at time_us and what it decided from them.
struct trace_row {
  std::uint64_t time_us = 0;
  std::int64_t velocity = 0;          ///< micro-rpm, as sampled at time_us (0x606C x 1e6)
  std::int32_t target_velocity = 0;   ///< 0x60FF as written
  std::uint16_t control_word = 0;     ///< 0x6040 the drive read
  std::uint16_t status_word = 0;      ///< 0x6041 it answered
  std::uint16_t error_code = 0;       ///< 0x603F
  std::uint16_t fault_cause = 0;      ///< the injected cause the drive saw, 0 = none
  state current = state::start;       ///< the state after this cycle
  std::uint8_t transition = no_transition;
  stop_ramp ramp = stop_ramp::none;
  bool torque = false;
  bool brake_released = false;        ///< the drive's command to the brake
  bool brake_engaged = true;          ///< the brake holds (as the drive read it)
  bool dc_link = true;
  bool sto = false;
  // The operation modes, as sampled at time_us.
  std::int64_t position = 0;          ///< 0x6064, increments
  std::int64_t position_demand = 0;   ///< 0x6062
  std::int32_t torque_permille = 0;   ///< 0x6077, permille of rated torque
  std::int8_t mode = 3;               ///< 0x6061
  /// 0x60FD: the limit switches (bits 0, 1), the home switch (bit 2) and an index pulse reached in
  /// the cycle before (bit 16), as sampled at time_us (the VCD's input wires).
  std::uint32_t digital_inputs = 0;
};

/// The row for the cycle about to run at time_us: call before step_axis() with the axis, then
/// complete it with complete_row() from the outputs.
trace_row begin_row(std::uint64_t time_us, const plant_constants& k, const axis_state& a) noexcept;
void complete_row(trace_row& row, const drive_outputs& out) noexcept;

/// "1500", "-2.5", "0.000125": micro-rpm as an exact decimal number of rpm.
std::string format_rpm(std::int64_t micro_rpm);
/// "1.250000": microseconds as seconds with six decimals.
std::string format_seconds(std::uint64_t time_us);

/// Which rows a decimated trace keeps: every `every`-th row, plus every row where anything but the
/// velocity changed, plus the last. every = 1 keeps all.
std::vector<std::size_t> kept_rows(const std::vector<trace_row>& rows, std::size_t every);

/// What a file says about where the trace comes from.
struct trace_info {
  std::string title;         ///< e.g. the scenario's name
  std::string profile_name;
  std::uint32_t cycle_us = 1000;
  bool brake_fitted = true;  ///< without a brake the plot's brake lane says so
  /// VCD: state and ramp as 8-bit integer codes (named in a $comment) instead of GTKWave's
  /// `$var string`, so viewers that keep to IEEE 1364 read the file.
  bool vcd_standard = false;
};

/// CSV with a header line: time_us, controlword, statusword, state, transition, velocity_rpm,
/// target_rpm, torque, brake_released, brake_engaged, ramp, error_code, fault_cause, dc_link, sto,
/// then (added with the operation modes, so tools that read the first fifteen keep working)
/// position, position_demand, torque_permille, mode.
void write_csv(std::ostream& out, const std::vector<trace_row>& rows, std::size_t every = 1);
/// One JSON object per line with the same fields (transition null when none was taken).
void write_jsonl(std::ostream& out, const std::vector<trace_row>& rows, std::size_t every = 1);
/// Value change dump, timescale 1 us, for GTKWave: scope `drive` with controlword, statusword,
/// velocity_rpm and target_rpm (real), state and ramp (GTKWave's string type: `$var string`, or
/// with info.vcd_standard 8-bit integer codes the header's $comment names),
/// last_transition (integer) with a transition_taken pulse in the cycle one is taken, torque,
/// brake_released, brake_engaged, dc_link, sto (wires), error_code, position and position_demand
/// (32-bit vectors, two's complement as 0x6064 travels), torque_permille (16), mode (8),
/// negative_limit_switch, positive_limit_switch, home_switch and index_pulse (wires, 0x60FD);
/// sub-scopes `cw` and `sw` with one wire per control-word and status-word bit, named by number and
/// meaning (cw.0_switch_on ... sw.10_target_reached). Only changes are written.
void write_vcd(std::ostream& out, const std::vector<trace_row>& rows, const trace_info& info);
/// A self-contained SVG: velocity (and 0x60FF dashed) over time, the state as labelled coloured
/// bands behind it, a numbered mark at every transition, torque and brake as lanes below, axes with
/// ticks and units, and a legend.
void write_svg_plot(std::ostream& out, const std::vector<trace_row>& rows, const trace_info& info);

}  // namespace cia402::sim
