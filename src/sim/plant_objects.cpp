// The object interface of a virtual drive (CiA 402 objects from the one table, the CiA 301 error
// register), its fault causes and its construction. Every access answers with an SDO abort code; a
// refused write changes nothing.
#include <stdexcept>

#include "cia402/sim/virtual_drive.hpp"
#include "plant_internal.hpp"

namespace cia402::sim {

int detail::fault_count(const axis_state& a) noexcept {
  int n = 0;
  while (n < max_fault_causes && a.fault_codes[n] != 0) ++n;
  return n;
}

void detail::remove_fault_at(axis_state& a, int i) noexcept {
  for (int j = i; j + 1 < max_fault_causes; ++j) {
    a.fault_codes[j] = a.fault_codes[j + 1];
    a.fault_classes[j] = a.fault_classes[j + 1];
  }
  a.fault_codes[max_fault_causes - 1] = 0;
  a.fault_classes[max_fault_causes - 1] = 0;
}

bool detail::add_fault_cause(axis_state& a, std::uint16_t code, std::uint8_t error_class) noexcept {
  if (code == 0) return false;
  for (int i = 0; i < max_fault_causes; ++i) {
    if (a.fault_codes[i] == code) {
      remove_fault_at(a, i);
      break;
    }
  }
  bool kept_all = true;
  if (fault_count(a) == max_fault_causes) {
    remove_fault_at(a, 0);
    kept_all = false;
  }
  const int n = fault_count(a);
  a.fault_codes[n] = code;
  a.fault_classes[n] = error_class;
  return kept_all;
}

namespace {

using detail::set_flag;
using detail::fault_count;
using detail::remove_fault_at;
using detail::add_fault_cause;

// The option codes' indices (0x605A..0x605E, 0x6007): one range test.
constexpr bool is_option_index(std::uint16_t index) noexcept {
  return index == 0x6007 || static_cast<unsigned>(index - 0x605A) <= 4u;
}

// Why index/sub is not an object of this drive (find_drive_object found no entry).
sdo_abort missing(std::uint16_t index) noexcept {
  return find_drive_object(index, 0) == nullptr ? sdo_abort::object_does_not_exist
                                                : sdo_abort::sub_index_does_not_exist;
}

// The object at index/sub as this drive has it: from the one object table, an option code only
// where the profile has it. Existence, sub-index, access and range are checked here for every
// object alike; what a value means is the switch's below. One table lookup when the object exists.
sdo_abort describe(const profile& p, std::uint16_t index, std::uint8_t sub,
                   const object_description*& out) noexcept {
  out = find_drive_object(index, sub);
  option o;
  if (is_option_index(index) && option_of_index(index, o) && !p.spec(o).exists()) {
    return sdo_abort::object_does_not_exist;
  }
  return out != nullptr ? sdo_abort::none : missing(index);
}

const detail::plain_setting* find_plain_setting(std::uint16_t index, std::uint8_t sub) noexcept {
  for (const detail::plain_setting& s : detail::plain_settings) {
    if (s.index == index && (s.sub == detail::every_sub || s.sub == sub)) return &s;
  }
  return nullptr;
}

// The set-point objects end the "set-points cleared" of T4 when written.
void setpoint_written(axis_state& a) noexcept { set_flag(a, sim_flag::setpoints_cleared, false); }

}  // namespace

sdo_abort detail::write_any_object(const profile& p, axis_state& a, std::uint16_t index,
                                   std::uint8_t sub, std::int64_t value) noexcept {
  if (index == object::error_register) {
    return sub != 0 ? sdo_abort::sub_index_does_not_exist : sdo_abort::read_only_object;
  }
  const object_description* o = nullptr;
  if (const sdo_abort r = describe(p, index, sub, o); r != sdo_abort::none) return r;
  if (const sdo_abort r = check_write(*o, value); r != sdo_abort::none) return r;
  // Any object but the control word (itself a source of the core's inputs) may change what the next
  // cycle decides from, or what a settled csp axis's cycle may skip (decide() reads the objects):
  // the settled copy goes, and the next cycle decides in full.
  if (index != object::control_word) {
    a.settled_valid = false;
    a.objects_written = true;
  }
  if (is_option_index(index)) return write_option(p, a.core, index, static_cast<std::int32_t>(value));
  mode_objects& m = a.objects;
  const auto i32 = static_cast<std::int32_t>(value);
  const auto u32 = static_cast<std::uint32_t>(value);
  switch (index) {
    case object::control_word: a.control_word = static_cast<std::uint16_t>(value); break;
    case object::target_velocity:
      a.target_velocity = i32;
      setpoint_written(a);
      break;
    case object::profile_acceleration: a.acceleration = u32; break;
    case object::profile_deceleration: a.deceleration = u32; break;
    case object::quick_stop_deceleration: a.quick_stop_deceleration = u32; break;
    case object::modes_of_operation: {
      const object_description* supported = find_drive_object(object::supported_drive_modes);
      if (supported == nullptr || !(cia402::mode::supported_bit(value) &
                                    static_cast<std::uint32_t>(supported->default_value))) {
        return sdo_abort::invalid_value;
      }
      a.requested_mode = static_cast<std::int8_t>(value);
      break;
    }
    case object::target_position:
      m.target_position = i32;
      setpoint_written(a);
      break;
    case object::target_torque:
      m.target_torque = static_cast<std::int16_t>(value);
      setpoint_written(a);
      break;
    case object::position_encoder_resolution:
      if (sub == 1) m.increments_per_rev = u32;
      break;  // sub 2 (motor revolutions) takes only 1: the table's limits
    case object::homing_method:
      if (!motion::homing::supports(value)) return sdo_abort::invalid_value;
      m.homing_method = static_cast<std::int8_t>(value);
      break;
    case object::interpolation_time_period:
      if (sub == 1) m.interpolation_value = static_cast<std::uint8_t>(value);
      else m.interpolation_index = static_cast<std::int8_t>(value);
      m.interpolation_period_us = detail::interpolation_period_us(m.interpolation_value, m.interpolation_index);
      // A new period starts from the set-point the axis has now.
      detail::restart_interpolation(a, a.operation_mode == cia402::mode::cyclic_synchronous_velocity ? a.velocity
                                       : a.operation_mode == cia402::mode::cyclic_synchronous_torque ? a.torque_demand
                                                                                                      : a.demand);
      break;
    default:
      if (const detail::plain_setting* setting = find_plain_setting(index, sub)) {
        setting->write(m, value);
        break;
      }
      return sdo_abort::object_does_not_exist;
  }
  return sdo_abort::none;
}

sdo_abort read_object(const profile& p, const plant_constants& k, const axis_state& a, std::uint16_t index,
                      std::uint8_t sub, std::int64_t& value) noexcept {
  if (index == object::error_register) {
    if (sub != 0) return sdo_abort::sub_index_does_not_exist;
    value = error_register_of(a.core.error_code);
    return sdo_abort::none;
  }
  const object_description* o = nullptr;
  if (const sdo_abort r = describe(p, index, sub, o); r != sdo_abort::none) return r;
  if (o->access == object_access::write_only) return sdo_abort::write_only_object;
  if (is_option_index(index)) {
    std::int32_t v = 0;
    const sdo_abort r = read_option(p, a.core, index, v);
    if (r == sdo_abort::none) value = v;
    return r;
  }
  if (sub == 0 && o->access == object_access::read_only && o->low == o->high) {
    value = o->default_value;  // sub-index 0 of an array or record: its entry count
    return sdo_abort::none;
  }
  const mode_objects& m = a.objects;
  // Positions are INTEGER32 on the bus: they wrap as a 32-bit encoder count does.
  const auto wrap = [](std::int64_t v) { return static_cast<std::int64_t>(static_cast<std::int32_t>(v)); };
  switch (index) {
    case object::control_word: value = a.control_word; break;
    case object::status_word: value = a.last.status_word; break;
    case object::target_velocity: value = a.target_velocity; break;
    case object::velocity_actual_value: value = velocity_rpm(a); break;
    case object::profile_acceleration: value = a.acceleration; break;
    case object::profile_deceleration: value = a.deceleration; break;
    case object::quick_stop_deceleration: value = a.quick_stop_deceleration; break;
    case object::error_code: value = a.core.error_code; break;
    case object::modes_of_operation: value = a.requested_mode; break;
    case object::modes_of_operation_display: value = a.operation_mode; break;
    case object::supported_drive_modes: value = o->default_value; break;
    case object::position_demand_value: value = wrap(a.demand); break;
    case object::position_actual_value: value = wrap(a.position); break;
    case object::following_error_actual_value: value = wrap(following_error(a)); break;
    case object::torque_actual_value: value = a.torque; break;
    case object::target_position: value = m.target_position; break;
    case object::target_torque: value = m.target_torque; break;
    case object::position_encoder_resolution: value = sub == 1 ? m.increments_per_rev : 1; break;
    case object::homing_method: value = m.homing_method; break;
    case object::interpolation_time_period:
      value = sub == 1 ? m.interpolation_value : m.interpolation_index;
      break;
    case object::supported_homing_methods: value = o->default_value; break;  // the table's own list
    case object::digital_inputs: value = digital_inputs(k, a); break;
    default:
      if (const detail::plain_setting* setting = find_plain_setting(index, sub)) {
        value = setting->read(m);
        break;
      }
      return sdo_abort::object_does_not_exist;
  }
  return sdo_abort::none;
}

bool drive_view::inject_fault(std::uint16_t code, std::uint8_t error_class) noexcept {
  return add_fault_cause(*axis_, code, error_class);
}

bool drive_view::clear_fault(std::uint16_t code) noexcept {
  if (code == 0) return false;
  for (int i = 0; i < max_fault_causes; ++i) {
    if (axis_->fault_codes[i] == code) {
      remove_fault_at(*axis_, i);
      return true;
    }
  }
  return false;
}

void drive_view::clear_faults() noexcept {
  for (int i = 0; i < max_fault_causes; ++i) {
    axis_->fault_codes[i] = 0;
    axis_->fault_classes[i] = 0;
  }
}

std::uint16_t drive_view::fault_cause() const noexcept {
  const int n = fault_count(*axis_);
  return n > 0 ? axis_->fault_codes[n - 1] : std::uint16_t{0};
}

plant_constants checked_constants(const plant_config& config) {
  if (const char* why = check_plant_config(config)) throw std::invalid_argument(why);
  return plant_constants::from(config);
}

virtual_drive::virtual_drive(const profile& p, const plant_config& config)
    : profile_(&p), constants_(checked_constants(config)), axis_(make_axis_state(p, constants_)) {}

}  // namespace cia402::sim
