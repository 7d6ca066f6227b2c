// The plant's configuration: which configurations are usable, the constants the per-cycle code
// derives from one, and a fresh axis at power-on with the object table's defaults.
#include "cia402/sim/plant.hpp"

#include "cia402/sim/virtual_drive.hpp"
#include "plant_internal.hpp"

namespace cia402::sim {
namespace {

using detail::csp_velocity_scale;
using detail::micro;

// Cycles a delay takes, at least one: the drive sees a change in the next cycle at the earliest.
std::uint16_t delay_cycles(std::uint32_t delay_us, std::uint32_t cycle_us) noexcept {
  const std::uint64_t cycles = (std::uint64_t{delay_us} + cycle_us - 1) / cycle_us;
  return static_cast<std::uint16_t>(cycles < 1 ? 1 : cycles);
}

}  // namespace

const char* check_plant_config(const plant_config& c) noexcept {
  if (c.cycle_us < 1 || c.cycle_us > 1000000) return "cycle must be 1 us .. 1 s";
  if (std::uint64_t{c.brake_engage_delay_us} > std::uint64_t{c.cycle_us} * 65535) {
    return "brake engage delay must be at most 65535 cycles";
  }
  if (std::uint64_t{c.brake_release_delay_us} > std::uint64_t{c.cycle_us} * 65535) {
    return "brake release delay must be at most 65535 cycles";
  }
  if (c.brake_deceleration < 1) return "brake deceleration must be at least 1 rpm/s";
  if (c.current_limit_percent < 1 || c.current_limit_percent > 1000) {
    return "current limit percent must be 1..1000";
  }
  if (c.voltage_limit_percent < 1 || c.voltage_limit_percent > 1000) {
    return "voltage limit percent must be 1..1000";
  }
  if (c.standstill_window_rpm > 1000000) return "standstill window must be at most 1000000 rpm";
  if (c.target_window_rpm > 65535) return "target window must be at most 65535 rpm (0x606D is UNSIGNED16)";
  if (c.max_velocity_rpm < 1 || c.max_velocity_rpm > 100000) return "max velocity must be 1..100000 rpm";
  if (c.max_acceleration_rpm_s < 1 || c.max_acceleration_rpm_s > 100000000) {
    return "max acceleration must be 1..100000000 rpm/s";
  }
  if (c.torque_acceleration_rpm_s < 1 || c.torque_acceleration_rpm_s > 100000000) {
    return "torque acceleration must be 1..100000000 rpm/s";
  }
  if (c.friction_permille > 1000) return "friction must be 0..1000 permille";
  if (c.load_permille < -1000 || c.load_permille > 1000) return "load must be -1000..1000 permille";
  constexpr std::int64_t reach = std::int64_t{1} << 40;
  const auto out_of_reach = [](const std::optional<std::int64_t>& at) { return at && (*at < -reach || *at > reach); };
  if (out_of_reach(c.home_switch_position) || out_of_reach(c.home_switch_end) ||
      out_of_reach(c.negative_limit_switch) || out_of_reach(c.positive_limit_switch) ||
      c.index_position < -reach || c.index_position > reach) {
    return "switch and index positions must be within +-2^40 increments";
  }
  if (c.home_switch_position && c.home_switch_end && *c.home_switch_end < *c.home_switch_position) {
    return "the home switch must end at or above where it begins";
  }
  if (c.negative_limit_switch && c.positive_limit_switch && *c.positive_limit_switch < *c.negative_limit_switch) {
    return "the positive limit switch must lie at or above the negative one";
  }
  return nullptr;
}

plant_constants plant_constants::from(const plant_config& c) noexcept {
  plant_constants k;
  k.cycle_us = c.cycle_us;
  k.coast_step = std::int64_t{c.coast_deceleration} * c.cycle_us;
  k.brake_step = std::int64_t{c.brake_deceleration} * c.cycle_us;
  k.standstill_window = std::int64_t{c.standstill_window_rpm} * micro;
  k.target_window_rpm = static_cast<std::uint16_t>(c.target_window_rpm);
  k.standstill_window_rpm = static_cast<std::uint16_t>(c.standstill_window_rpm < 65535 ? c.standstill_window_rpm : 65535);
  k.engage_cycles = delay_cycles(c.brake_engage_delay_us, c.cycle_us);
  k.release_cycles = delay_cycles(c.brake_release_delay_us, c.cycle_us);
  k.current_limit_percent = static_cast<std::uint16_t>(c.current_limit_percent);
  k.voltage_limit_percent = static_cast<std::uint16_t>(c.voltage_limit_percent);
  k.brake_fitted = c.brake_fitted;
  k.max_velocity = std::int64_t{c.max_velocity_rpm} * micro;
  k.max_velocity_rpm = c.max_velocity_rpm;
  k.max_acceleration_step = std::int64_t{c.max_acceleration_rpm_s} * c.cycle_us;
  k.torque_acceleration = c.torque_acceleration_rpm_s;
  k.friction = static_cast<std::int32_t>(c.friction_permille);
  k.load = c.load_permille;
  motion::homing_machine& m = k.machine;
  m.negative_limit = c.negative_limit_switch.value_or(motion::homing_machine::none_below);
  m.positive_limit = c.positive_limit_switch.value_or(motion::homing_machine::none_above);
  m.home_switch_low = c.home_switch_fitted ? c.home_switch_position.value_or(motion::homing_machine::none_below)
                                           : motion::homing_machine::none_above;
  m.home_switch_high = c.home_switch_fitted ? c.home_switch_end.value_or(motion::homing_machine::none_above)
                                            : motion::homing_machine::none_below;
  m.index_at = c.index_position;
  // The csp velocity of one increment a cycle at the default resolution, when it is an integer.
  const object_description* resolution = find_drive_object(object::position_encoder_resolution, 1);
  const std::uint64_t per_rev_us = (resolution != nullptr ? static_cast<std::uint64_t>(resolution->default_value) : 0) *
                                   c.cycle_us;
  if (per_rev_us != 0 && csp_velocity_scale % per_rev_us == 0) {
    k.usual_increments_per_rev = static_cast<std::uint32_t>(resolution->default_value);
    k.usual_velocity_per_increment = static_cast<std::int64_t>(csp_velocity_scale / per_rev_us);
    k.usual_csp_reach = detail::csp_reach(k, per_rev_us);
  }
  return k;
}

namespace {

// The default of an entry of the one object table.
std::int64_t default_of(std::uint16_t index, std::uint8_t sub = 0) noexcept {
  const object_description* o = find_drive_object(index, sub);
  return o != nullptr ? o->default_value : 0;
}

template <typename T>
T default_as(std::uint16_t index, std::uint8_t sub = 0) noexcept {
  return static_cast<T>(default_of(index, sub));
}

}  // namespace

axis_state make_axis_state(const profile& p) noexcept { return make_axis_state(p, plant_constants::from({})); }

axis_state make_axis_state(const profile& p, const plant_constants& k) noexcept {
  axis_state a;
  a.core = make_axis(p);
  a.acceleration = default_as<std::uint32_t>(object::profile_acceleration);
  a.deceleration = default_as<std::uint32_t>(object::profile_deceleration);
  a.quick_stop_deceleration = default_as<std::uint32_t>(object::quick_stop_deceleration);
  a.requested_mode = a.operation_mode = default_as<std::int8_t>(object::modes_of_operation);
  mode_objects& o = a.objects;
  for (const detail::plain_setting& s : detail::plain_settings) {
    s.write(o, default_of(s.index, s.sub == detail::every_sub ? 0 : s.sub));
  }
  o.increments_per_rev = default_as<std::uint32_t>(object::position_encoder_resolution, 1);
  o.homing_method = default_as<std::int8_t>(object::homing_method);
  o.interpolation_value = default_as<std::uint8_t>(object::interpolation_time_period, 1);
  o.interpolation_index = default_as<std::int8_t>(object::interpolation_time_period, 2);
  o.interpolation_period_us = detail::interpolation_period_us(o.interpolation_value, o.interpolation_index);
  // The plant's own figures: its top speed, its target and standstill windows.
  o.max_motor_speed = k.max_velocity_rpm;
  o.velocity_window = k.target_window_rpm;
  o.velocity_threshold = k.standstill_window_rpm;
  a.pp.reset(0);
  return a;
}
}  // namespace cia402::sim
