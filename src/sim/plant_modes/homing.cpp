// The homing mode (CiA 402-2 mode 6) on the plant: motion::homing runs the method on the shaft's
// own position, where the machine's switches and index pulses are, and sets the offset between it
// and 0x6064. The switches also show in 0x60FD.
#include "../plant_internal.hpp"

namespace cia402::sim {

std::uint32_t digital_inputs(const plant_constants& k, const axis_state& a) noexcept {
  const motion::homing_machine& m = k.machine;
  const std::int64_t at = shaft_position(a);
  const std::int64_t before = a.previous_position - a.home_shift;
  return (m.negative_limit_active(at) ? digital_input::negative_limit_switch : 0u) |
         (m.positive_limit_active(at) ? digital_input::positive_limit_switch : 0u) |
         (m.home_switch_active(at) ? digital_input::home_switch : 0u) |
         (m.index_pulse_between(before, at, a.objects.increments_per_rev) ? index_pulse_input : 0u);
}

namespace detail {

std::uint16_t homing_cycle(const plant_constants& k, axis_state& a, motion::shaft& s) noexcept {
  const mode_objects& o = a.objects;
  motion::homing_parameters par;
  par.method = o.homing_method;
  par.switch_speed_rpm = o.homing_switch_speed;
  par.zero_speed_rpm = o.homing_zero_speed;
  par.acceleration_rpm_s = o.homing_acceleration;
  par.home_offset = o.home_offset;
  par.increments_per_rev = o.increments_per_rev;
  // The run works on the shaft's own position; 0x6064 is that plus the offset it sets.
  motion::shaft own = s;
  own.position -= a.home_shift;
  std::int64_t shift = a.home_shift;
  const motion::homing_status st =
      a.homing.step((a.control_word & control_bit::homing_operation_start) != 0, par, k.machine, own, shift,
                    k.cycle_us, speed_limit_rpm(k, a));
  // The shaft's position before this cycle reads in the new coordinates too, so that 0x60FD's
  // index pulse bit follows the shaft, not the redefinition.
  a.previous_position += shift - a.home_shift;
  a.home_shift = shift;
  s = own;
  s.position += shift;
  a.demand = s.position;
  return static_cast<std::uint16_t>((st.target_reached ? status_bit::target_reached : 0u) |
                                    (st.attained ? status_bit::homing_attained : 0u) |
                                    (st.error ? status_bit::homing_error : 0u) |
                                    (st.limited ? status_bit::internal_limit_active : 0u));
}

}  // namespace detail
}  // namespace cia402::sim
