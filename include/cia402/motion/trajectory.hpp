// The motion side of a drive in the position modes: exact kinematics on virtual time and the
// profile position mode's set-point handshake and trapezoidal profile (CiA 402-2 profile position,
// objects 0x607A, 0x6081..0x6084, 0x6067, 0x6068; control-word bits 4, 5, 6, 8, 9; status-word
// bits 10 and 12). Integers only, so the same inputs give the same trace on every machine; no heap,
// no exceptions, bounded work per cycle. The state machine (cia402::step) decides whether motion is
// enabled; this decides how the shaft moves while it is.
//
// Units: positions in increments (0x608F gives increments per revolution, 10,000 by default),
// velocities in rpm at the interface and micro-rpm inside, accelerations in rpm/s, time in
// microseconds. An acceleration in rpm/s over a cycle in microseconds is a velocity change in
// micro-rpm, exactly.
#pragma once

#include <cstdint>
#include <climits>

namespace cia402::motion {

/// The kinematic state of the shaft: position in whole increments plus a fraction, velocity in
/// micro-rpm. The fraction keeps every cycle's travel exact, so no rounding drifts.
struct shaft {
  std::int64_t position = 0;  ///< increments
  std::int64_t fraction = 0;  ///< [0, fraction_unit): parts of an increment
  std::int64_t velocity = 0;  ///< micro-rpm, signed

  /// One increment in fraction units: 120e12, so that (v0 + v1) * resolution * dt_us / 120e12 is
  /// the trapezoid-rule travel in increments of a cycle in which the velocity goes from v0 to v1.
  static constexpr std::int64_t fraction_unit = 120'000'000'000'000;
};

/// Moves the shaft through one cycle of `dt_us` microseconds while its velocity changes linearly
/// to `velocity_end` (micro-rpm): the exact trapezoid-rule travel, the remainder kept in `fraction`.
void advance(shaft& s, std::int64_t velocity_end, std::uint32_t dt_us,
             std::uint32_t increments_per_rev) noexcept;

/// The highest speed (micro-rpm) from which the shaft can still stop (or slow to `end_speed`) within
/// `distance` increments at `deceleration` rpm/s: from v^2 = 2 a s, in these units
/// sqrt(end^2 + deceleration * distance * fraction_unit / resolution).
std::int64_t braking_speed(std::int64_t distance_increments, std::uint32_t deceleration_rpm_s,
                           std::int64_t end_speed, std::uint32_t increments_per_rev) noexcept;

/// The fastest the shaft may move towards `target` at the end of a cycle of `dt_us` (micro-rpm, 0
/// if it cannot stop there any more) so that, after that cycle's travel, it can still stop at the
/// target at `deceleration_rpm_s`: the speed profile position brakes into its target with, for a
/// mode that must not pass a place (a software position limit).
std::int64_t stopping_speed(const shaft& s, std::int64_t target, std::uint32_t deceleration_rpm_s,
                            std::uint32_t dt_us, std::uint32_t increments_per_rev) noexcept;

/// The profile position mode's parameters (0x6081, 0x6082, 0x6083, 0x6084, 0x6067, 0x6068).
struct pp_parameters {
  std::uint32_t profile_velocity_rpm = 1000;   ///< 0x6081
  std::uint32_t end_velocity_rpm = 0;          ///< 0x6082
  std::uint32_t acceleration_rpm_s = 1000;     ///< 0x6083, at least 1
  std::uint32_t deceleration_rpm_s = 1000;     ///< 0x6084, at least 1; also the halt ramp
  std::uint32_t position_window = 10;          ///< 0x6067, increments
  std::uint32_t position_window_time_ms = 0;   ///< 0x6068
  std::uint32_t increments_per_rev = 10000;    ///< 0x608F
  /// 0x607D: a set-point beyond a limit is taken as the limit (status bit 11 says so).
  std::int64_t min_position = INT64_MIN;
  std::int64_t max_position = INT64_MAX;
};

/// What the master commands in profile position mode this cycle.
struct pp_command {
  bool new_setpoint = false;        ///< control-word bit 4: its 0->1 edge offers 0x607A
  bool change_immediately = false;  ///< bit 5: the offered set-point replaces the running one now
  bool relative = false;            ///< bit 6: the target adds to the previous target
  bool halt = false;                ///< bit 8: stop on the deceleration ramp, keep the target
  bool change_on_setpoint = false;  ///< bit 9: pass the running target at speed into the next
  std::int64_t target = 0;          ///< 0x607A, increments
};

/// What the mode shows in the status word.
struct pp_status {
  bool setpoint_acknowledge = false;  ///< bit 12: the offered set-point was taken (or is queued)
  bool target_reached = false;        ///< bit 10: at the target (within the window for its time),
                                      ///< or at standstill after a halt
  std::int64_t demand = 0;            ///< 0x6062 position demand, increments
  bool limited = false;               ///< bit 11: the running set-point was cut to 0x607D
};

/// Profile position mode: a trapezoidal profile to each set-point, one set-point queued behind the
/// running one (bit 5 = 0), or replacing it (bit 5 = 1). The shaft follows the demand exactly: a
/// plant with lag or a load compares its actual position with `status.demand` itself.
class profile_position {
 public:
  /// Starts at rest at `position` with no set-point (as when the mode is entered).
  void reset(std::int64_t position) noexcept;
  /// Takes over a shaft in whatever motion it is (a mode change while moving): no set-point, so the
  /// profile brakes it to rest on the deceleration ramp, and bit 12 is 0. `new_setpoint_now` is
  /// control bit 4 as it is now: it counts as the previous value, so only a 0->1 edge after it offers
  /// a set-point (entering the mode with bit 4 already 1 is no edge).
  void reset(const shaft& s, bool new_setpoint_now = false) noexcept;

  pp_status step(const pp_command& cmd, const pp_parameters& par, std::uint32_t dt_us) noexcept;

  const shaft& state() const noexcept { return shaft_; }
  bool moving() const noexcept { return active_ || shaft_.velocity != 0; }
  /// The set-point the profile runs to now, if any.
  bool has_target() const noexcept { return active_; }
  std::int64_t target() const noexcept { return target_; }
  /// Control bit 4 as the last step (or reset) saw it: the value its next edge is judged against.
  bool new_setpoint_seen() const noexcept { return last_new_setpoint_; }

 private:
  shaft shaft_;
  std::int64_t target_ = 0;        // the running set-point
  std::int64_t queued_ = 0;        // the set-point behind it
  std::uint32_t in_window_us_ = 0; // how long the shaft has been within the window at rest
  bool active_ = false;            // a set-point is running
  bool queued_valid_ = false;
  bool queued_blends_ = false;     // bit 9 with the queued set-point: do not stop at the running one
  bool last_new_setpoint_ = false;
  bool acknowledge_ = false;
  bool limited_ = false;           // the running set-point was cut to a software limit
  bool queued_limited_ = false;
};

}  // namespace cia402::motion
