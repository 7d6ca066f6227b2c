// The homing mode (CiA 402-2 mode 6) on the plant: motion::homing runs the method, the plant gives
// it the machine's home switch and index pulses.
#include "../plant_internal.hpp"

namespace cia402::sim::detail {

std::uint16_t homing_cycle(const plant_constants& k, axis_state& a, motion::shaft& s) noexcept {
  const mode_objects& o = a.objects;
  motion::homing_parameters par;
  par.method = o.homing_method;
  par.switch_speed_rpm = o.homing_switch_speed;
  par.zero_speed_rpm = o.homing_zero_speed;
  par.acceleration_rpm_s = o.homing_acceleration;
  par.home_offset = o.home_offset;
  par.increments_per_rev = o.increments_per_rev;
  par.home_switch_at = k.home_switch_position;
  par.index_at = k.index_position;
  const motion::homing_status st =
      a.homing.step((a.control_word & control_bit::homing_operation_start) != 0, par, s, k.cycle_us);
  a.demand = s.position;
  return static_cast<std::uint16_t>((st.target_reached ? status_bit::target_reached : 0u) |
                                    (st.attained ? status_bit::homing_attained : 0u) |
                                    (st.error ? status_bit::homing_error : 0u));
}

}  // namespace cia402::sim::detail
