// The simulator's plant: a motor in the operation modes of docs/modes.md (profile velocity, profile
// position, homing, cyclic synchronous position / velocity / torque, profile torque) with a holding
// brake, a DC link and an STO input, stepped on a fixed cycle of virtual time. The state machine is the core's: each cycle the
// plant's feedback goes into cia402::step() and the plant then follows its drive_outputs. Nothing
// here reads a clock, draws a random number or uses floating point, so the same inputs give the
// same trajectory bit for bit on every machine.
//
// Units: velocities in rpm (0x60FF, 0x606C), ramps in rpm/s (0x6083..0x6085), positions in
// increments (0x608F), torque in permille of rated torque, time in microseconds. Inside, the
// velocity is kept in micro-rpm (1e-6 rpm) so that a ramp's change per cycle, rate [rpm/s] x cycle
// [us], is an exact integer, and the position with an exact fraction of an increment.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "cia402/drive.hpp"
#include "cia402/motion/homing.hpp"
#include "cia402/motion/trajectory.hpp"
#include "cia402/objects.hpp"
#include "cia402/profile.hpp"

namespace cia402::sim {

/// Physical parameters shared by every axis of a machine. Every field is documented with what the
/// plant does with it; check_plant_config() says whether a set is usable.
struct plant_config {
  /// The cycle of virtual time, 1 us .. 1 s. The core steps once per cycle.
  std::uint32_t cycle_us = 1000;
  /// A holding brake is fitted. Without one the drive always reads brake_engaged = true and motion
  /// never waits for a brake.
  bool brake_fitted = true;
  /// From drive_outputs.brake_released going false to the brake holding the shaft (at least one
  /// cycle: the drive sees the change in the next cycle at the earliest).
  std::uint32_t brake_engage_delay_us = 20000;
  /// From drive_outputs.brake_released going true to the brake letting go. Until then the shaft is
  /// held: no acceleration while the brake is still engaged or releasing.
  std::uint32_t brake_release_delay_us = 30000;
  /// How fast an engaged brake stops a turning shaft (rpm/s), added to whatever else decelerates it.
  std::uint32_t brake_deceleration = 20000;
  /// Friction: how fast a coasting motor (torque off) slows down (rpm/s). 0 = no friction.
  std::uint32_t coast_deceleration = 300;
  /// |velocity| <= this (rpm) is standstill: drive_inputs.standstill; the power-on value of the
  /// velocity threshold 0x606F (pv status bit 12 "speed 0"), at most 65535.
  std::uint32_t standstill_window_rpm = 1;
  /// The power-on value of the velocity window 0x606D: |velocity - set-point| <= it is target
  /// reached in profile velocity (status bit 10), 0..65535.
  std::uint32_t target_window_rpm = 10;
  /// A stop at the current limit (0x605A/0x605D/0x605E codes 3 and 7) decelerates at this percentage
  /// of the quick-stop deceleration 0x6085: 200 = twice as hard as the quick-stop ramp.
  std::uint32_t current_limit_percent = 200;
  /// A stop at the voltage limit (codes 4 and 8) decelerates at this percentage of the deceleration
  /// 0x6084: the DC link can take back no more energy than the normal slow-down ramp returns.
  std::uint32_t voltage_limit_percent = 100;

  // The motor and machine behind the operation modes other than profile velocity.
  /// The fastest the motor turns (rpm), and the power-on value of 0x6080 max motor speed: no mode
  /// turns it faster, whatever 0x607F and 0x6080 say.
  std::uint32_t max_velocity_rpm = 6000;
  /// The fastest the motor accelerates in csv (rpm/s).
  std::uint32_t max_acceleration_rpm_s = 100000;
  /// Inertia: the acceleration (rpm/s) rated torque (1000 permille) gives the unloaded shaft.
  std::uint32_t torque_acceleration_rpm_s = 20000;
  /// Coulomb friction (permille of rated torque) against the motion; at rest it holds the shaft
  /// until the torque exceeds it.
  std::uint32_t friction_permille = 20;
  /// A constant load torque (permille of rated torque, signed: positive pulls negative).
  std::int32_t load_permille = 0;

  // The machine's switches and the encoder's index pulse: fixed places on the shaft, in the shaft's
  // own increments (0x6064 before any homing run; a run changes what 0x6064 reads, never where they
  // are). Within +-2^40. The drive sees them in 0x60FD and homes on them (homing methods 1..34);
  // outside homing the limit switches only light their bits.
  /// The home switch is fitted, active from home_switch_position up to home_switch_end (both
  /// included; no value: from the negative end / to the positive end of travel).
  bool home_switch_fitted = true;
  std::optional<std::int64_t> home_switch_position = 50000;
  std::optional<std::int64_t> home_switch_end;
  /// The negative limit switch is active below this position, the positive one above this (no
  /// value: not fitted). By default 100 revolutions either side of the start.
  std::optional<std::int64_t> negative_limit_switch = -1'000'000;
  std::optional<std::int64_t> positive_limit_switch = 1'000'000;
  /// An index pulse comes here and every revolution (0x608F) from here.
  std::int64_t index_position = 0;
};

/// nullptr when the configuration is usable, else the reason ("cycle_us must be 1..1000000").
const char* check_plant_config(const plant_config& c) noexcept;

/// Values derived once from a plant_config, in the units the per-cycle code uses.
struct plant_constants {
  std::uint32_t cycle_us = 1000;
  std::int64_t coast_step = 0;        ///< micro-rpm lost per cycle when coasting
  std::int64_t brake_step = 0;        ///< micro-rpm an engaged brake takes per cycle
  std::int64_t standstill_window = 0; ///< micro-rpm
  std::uint16_t standstill_window_rpm = 0;  ///< 0x606F's power-on value
  std::uint16_t target_window_rpm = 0;      ///< 0x606D's power-on value
  std::uint16_t engage_cycles = 1;    ///< cycles from the command to an engaged brake
  std::uint16_t release_cycles = 1;   ///< cycles from the command to a released brake
  std::uint16_t current_limit_percent = 200;
  std::uint16_t voltage_limit_percent = 100;
  bool brake_fitted = true;
  std::int64_t max_velocity = 0;      ///< micro-rpm
  std::int64_t max_acceleration_step = 0;  ///< micro-rpm a cycle
  std::int64_t torque_acceleration = 0;    ///< rpm/s at rated torque
  std::int32_t friction = 0;          ///< permille
  std::int32_t load = 0;              ///< permille
  std::uint32_t max_velocity_rpm = 0;
  /// The switches and index pulses, in the shaft's own increments.
  motion::homing_machine machine;
  /// 0x608F's default and the csp velocity (micro-rpm) of one increment a cycle at it, when that is
  /// an integer (0 if not): csp at that resolution then needs no division.
  std::uint32_t usual_increments_per_rev = 0;
  std::int64_t usual_velocity_per_increment = 0;
  std::int64_t usual_csp_reach = 0;  ///< the most increments a csp cycle travels at it

  /// Requires check_plant_config(c) == nullptr.
  static plant_constants from(const plant_config& c) noexcept;
};

/// plant_constants::from(c), or std::invalid_argument with check_plant_config()'s reason.
plant_constants checked_constants(const plant_config& c);

/// Bits of axis_state::flags.
namespace sim_flag {
inline constexpr std::uint8_t dc_link = 1u << 0;          ///< DC-link voltage present
inline constexpr std::uint8_t sto = 1u << 1;              ///< safe torque off active
inline constexpr std::uint8_t connection_lost = 1u << 2;  ///< fieldbus connection lost (0x6007)
inline constexpr std::uint8_t setpoints_cleared = 1u << 3;  ///< 0x60FF reads as 0 until written
inline constexpr std::uint8_t brake_closed = 1u << 4;     ///< the brake holds the shaft now
inline constexpr std::uint8_t brake_commanded_open = 1u << 5;  ///< last drive_outputs.brake_released
/// The following error (0x8611) is a fault cause until the drive has reached FAULT.
inline constexpr std::uint8_t following_error_raised = 1u << 6;
}  // namespace sim_flag

/// 0x60FD's manufacturer-specific bit of this drive: an index pulse passed (or under the shaft) in
/// the last cycle. Bits 0..2 are CiA 402's (cia402::digital_input).
inline constexpr std::uint32_t index_pulse_input = 1u << 16;

/// The objects of the operation modes (CiA 402-2) as one axis holds them; defaults from the object
/// table (cia402/objects.hpp).
struct mode_objects {
  std::int32_t target_position = 0;            ///< 0x607A
  std::int32_t position_offset = 0;            ///< 0x60B0
  std::int32_t velocity_offset = 0;            ///< 0x60B1
  std::int32_t home_offset = 0;                ///< 0x607C
  std::int32_t min_position = 0;               ///< 0x607D sub 1
  std::int32_t max_position = 0;               ///< 0x607D sub 2
  std::uint32_t profile_velocity = 0;          ///< 0x6081
  std::uint32_t end_velocity = 0;              ///< 0x6082
  std::uint32_t torque_slope = 0;              ///< 0x6087, permille/s
  std::uint32_t following_error_window = 0;    ///< 0x6065; 0xFFFFFFFF = no check
  std::uint32_t position_window = 0;           ///< 0x6067
  std::uint32_t increments_per_rev = 0;        ///< 0x608F sub 1 (sub 2 is 1)
  std::uint32_t homing_switch_speed = 0;       ///< 0x6099 sub 1
  std::uint32_t homing_zero_speed = 0;         ///< 0x6099 sub 2
  std::uint32_t homing_acceleration = 0;       ///< 0x609A
  std::uint32_t max_profile_velocity = 0;      ///< 0x607F, rpm
  std::uint32_t max_motor_speed = 0;           ///< 0x6080, rpm
  /// 0x60C2 as microseconds (value x 10^index s): the period the cyclic modes interpolate over.
  std::uint32_t interpolation_period_us = 0;
  std::uint16_t following_error_time_out = 0;  ///< 0x6066, ms
  std::uint16_t position_window_time = 0;      ///< 0x6068, ms
  std::uint16_t velocity_window = 0;           ///< 0x606D, rpm
  std::uint16_t velocity_window_time = 0;      ///< 0x606E, ms
  std::uint16_t velocity_threshold = 0;        ///< 0x606F, rpm
  std::uint16_t velocity_threshold_time = 0;   ///< 0x6070, ms
  std::uint16_t max_torque = 0;                ///< 0x6072, permille
  std::int16_t target_torque = 0;              ///< 0x6071
  std::int16_t torque_offset = 0;              ///< 0x60B2
  std::int8_t homing_method = 0;               ///< 0x6098
  std::uint8_t interpolation_value = 0;        ///< 0x60C2 sub 1
  std::int8_t interpolation_index = 0;         ///< 0x60C2 sub 2
};

/// The fault cause a following error beyond 0x6065 for longer than 0x6066 raises (CiA 402).
inline constexpr std::uint16_t following_error_code = 0x8611;

/// How many fault causes one axis holds at once.
inline constexpr int max_fault_causes = 4;

/// Everything one virtual axis keeps between cycles: the core's axis, the motion objects, the plant
/// and the injected inputs. Plain data, so a machine keeps N of them in one array.
struct axis_state {
  // The first core_source_bytes, core to operation_mode, are all a cycle's core step depends on:
  // the core's axis and every field plant_inputs() reads. Kept together so that step_axis() sees
  // by one comparison that they are as they were in a cycle whose step changed nothing: the core is
  // a function of its axis and its inputs, so it would decide again what `last` holds.
  axis core;                          ///< the core state machine's memory
  drive_outputs last;                 ///< what the core decided in the last cycle
  std::int64_t velocity = 0;          ///< actual velocity, micro-rpm (0x606C = velocity / 1e6)
  std::int32_t target_velocity = 0;   ///< 0x60FF, rpm
  /// The mode-specific status bits (10..13) this cycle's motion produced, shown by the next cycle.
  std::uint16_t mode_status = 0;
  std::uint16_t control_word = 0;     ///< 0x6040, read by the next cycle
  /// Present fault causes, oldest first; a free slot holds code 0. The newest is the one the drive
  /// sees (drive_inputs.fault_code, fault_class).
  std::uint16_t fault_codes[max_fault_causes] = {};
  std::uint8_t fault_classes[max_fault_causes] = {};
  std::uint8_t flags = sim_flag::dc_link | sim_flag::brake_closed;  ///< sim_flag bits
  std::int8_t operation_mode = cia402::mode::profile_velocity;  ///< 0x6061: the mode it runs

  std::int8_t requested_mode = cia402::mode::profile_velocity;  ///< 0x6060 as written
  /// step_axis() only: the core's sources as the last cycle whose step left the core's axis as it
  /// was found them (valid while settled_valid).
  bool settled_valid = false;
  std::uint8_t settled[62] = {};
  /// step_axis() only: with those bytes the axis is a csp axis running with its brake released, at
  /// the usual resolution, with no interpolation and no speed limit below the motor's (what
  /// step_axis() asks of the settled core before it takes its path with no call).
  bool settled_csp_runs = false;
  /// step_axis() only: the set-point profile velocity follows is cut to the speed limit (see
  /// pv_set_point).
  bool pv_set_point_cut = false;
  /// step_axis() only: the farthest the demand may lie from the shaft for that path: within the
  /// following error window and one cycle's travel at the motor's top speed (at most 100,000 rpm
  /// for a second at 0x608F's default: it fits).
  std::uint32_t settled_csp_reach = 0;
  std::uint32_t acceleration = 1000;  ///< 0x6083, rpm/s
  std::uint32_t deceleration = 1000;  ///< 0x6084, rpm/s: the slow-down ramp
  std::uint32_t quick_stop_deceleration = 10000;  ///< 0x6085, rpm/s
  std::uint16_t brake_timer = 0;      ///< cycles until the brake reaches its command
  /// step_axis() only: an object was written since the core last decided, so what it works out
  /// from the objects (pv_timed, limit_braking_reach, settled_csp_reach) is to be worked out again.
  bool objects_written = true;
  /// step_axis() only: 0x606E or 0x6070 asks profile velocity to time its bits 10 and 12.
  bool pv_timed = false;
  /// step_axis() only: how near (increments) a software limit 0x607D the shaft must be before pv,
  /// csv or a torque mode works out how hard to brake for it: the quick-stop braking distance from
  /// the motor's top speed and a cycle's travel (UINT32_MAX: always). Worked out with the core's
  /// decision.
  std::uint32_t limit_braking_reach = UINT32_MAX;

  // The operation modes. What a running axis reads every cycle first, in the cache lines after the
  // ones above; what homing, the timed pv bits and interpolation add, after the objects.
  std::int64_t position = 0;           ///< 0x6064, increments
  std::int64_t previous_position = 0;  ///< 0x6064 before the last cycle's move
  std::int64_t position_fraction = 0;  ///< parts of an increment (motion::shaft::fraction_unit)
  std::int64_t demand = 0;             ///< 0x6062
  std::int32_t torque = 0;             ///< 0x6077, permille of rated torque
  std::int32_t torque_demand = 0;      ///< the profile torque mode's ramped demand
  std::uint32_t following_error_us = 0;  ///< how long the following error has been beyond 0x6065
  std::uint32_t interpolation_elapsed_us = 0;  ///< how far into the running period (interpolation_to)
  /// step_axis() only: the set-point profile velocity follows (micro-rpm: 0x60FF, 0 after T4, cut to
  /// the speed limit), worked out with the core's decision from fields that stay as they are while
  /// the axis is settled.
  std::int64_t pv_set_point = 0;
  mode_objects objects;
  /// 0x6064 minus the shaft's own position (shaft_position()): what homing set. The switches and
  /// index pulses are places on the shaft; homing changes this, never them.
  std::int64_t home_shift = 0;
  /// Profile velocity: how long |velocity - set-point| has been within 0x606D, and |velocity|
  /// beyond 0x606F.
  std::uint32_t in_velocity_window_us = 0;
  std::uint32_t above_velocity_threshold_us = 0;
  /// The cyclic modes' interpolation over 0x60C2: the set-point the running period starts from and
  /// the one it ends at (position, micro-rpm or permille).
  std::int64_t interpolation_from = 0;
  std::int64_t interpolation_to = 0;
  motion::profile_position pp;
  motion::homing homing;
};

/// The bytes of axis_state a core step depends on (its first ones, core to operation_mode).
inline constexpr std::size_t core_source_bytes = sizeof(axis_state::settled);
static_assert(offsetof(axis_state, operation_mode) + 1 == core_source_bytes,
              "axis_state::settled holds exactly the fields from core to operation_mode");

/// A fresh axis at power-on: the profile's default option codes, the motion objects' defaults (the
/// plant's for 0x606D, 0x606F and 0x6080), DC link present, brake engaged, at rest. Its first
/// cycles take T0 and T1.
axis_state make_axis_state(const profile& p, const plant_constants& k) noexcept;
/// The same on the default plant.
axis_state make_axis_state(const profile& p) noexcept;

/// The feedback the plant gives the drive at the start of a cycle (drive_inputs as the core reads
/// them), from the axis's plant and injected inputs.
drive_inputs plant_inputs(const plant_constants& k, const axis_state& a) noexcept;

/// One cycle of one axis: the plant's feedback into cia402::step(), then the plant follows the
/// outputs for one cycle (velocity, brake). Returns the outputs, kept in a.last.
const drive_outputs& step_axis(const profile& p, const plant_constants& k, axis_state& a) noexcept;

/// The set-point the motion side follows in OPERATION ENABLED: 0x60FF, or 0 after the drive
/// cleared the set-points (T4) until 0x60FF is written again.
inline std::int32_t effective_target(const axis_state& a) noexcept {
  return (a.flags & sim_flag::setpoints_cleared) ? 0 : a.target_velocity;
}

/// The shaft's own position (increments): where the switches and index pulses are. 0x6064 is this
/// plus what homing set (axis_state::home_shift).
inline std::int64_t shaft_position(const axis_state& a) noexcept { return a.position - a.home_shift; }

/// 0x60FD: the limit switches (bits 0, 1) and the home switch (bit 2) where the shaft is now, and
/// an index pulse passed in the last cycle (index_pulse_input).
std::uint32_t digital_inputs(const plant_constants& k, const axis_state& a) noexcept;

/// The drive's speed limit (rpm): the lower of 0x607F, 0x6080 and the motor's top speed.
inline std::uint32_t speed_limit_rpm(const plant_constants& k, const axis_state& a) noexcept {
  std::uint32_t limit = a.objects.max_profile_velocity < a.objects.max_motor_speed ? a.objects.max_profile_velocity
                                                                                   : a.objects.max_motor_speed;
  return limit < k.max_velocity_rpm ? limit : k.max_velocity_rpm;
}

/// 0x60F4: the position demand minus the actual position.
inline std::int64_t following_error(const axis_state& a) noexcept { return a.demand - a.position; }

/// Actual velocity as 0x606C reports it: rpm, rounded towards zero.
inline std::int32_t velocity_rpm(const axis_state& a) noexcept {
  return static_cast<std::int32_t>(a.velocity / 1000000);
}

/// The brake holds the shaft (always true when none is fitted, as the drive reads it).
inline bool brake_engaged(const plant_constants& k, const axis_state& a) noexcept {
  return !k.brake_fitted || (a.flags & sim_flag::brake_closed) != 0;
}

}  // namespace cia402::sim
