#include "cia402/drive402/sim_device.hpp"

#include <algorithm>

#include "cia402/manufacturer_objects.hpp"

namespace cia402::drive402 {

sim_device::sim_device(const profile& p, const sim::plant_config& config)
    : profile_(&p), config_(config), drive_(std::make_unique<sim::virtual_drive>(p, config)) {}

std::uint32_t sim_device::step(std::uint32_t elapsed_us) noexcept {
  const std::uint32_t cycle = drive_->constants().cycle_us;
  const std::uint64_t pending = static_cast<std::uint64_t>(pending_us_) + elapsed_us;
  pending_us_ = static_cast<std::uint32_t>(
      std::min<std::uint64_t>(pending, static_cast<std::uint64_t>(max_catch_up_cycles) * cycle));
  while (pending_us_ >= cycle) {
    apply_connection();
    drive_->step();
    pending_us_ -= cycle;
  }
  report_changes();
  return cycle - pending_us_;
}

void sim_device::set_connection_lost(bool lost) noexcept {
  fieldbus_lost_ = lost;
  apply_connection();
}

void sim_device::apply_connection() noexcept {
  if (!fieldbus_lost_) {
    loss_acting_ = false;
  } else if (!loss_acting_) {
    const sim::drive_view v = drive_->view();
    const state s = v.current();
    loss_acting_ = s == state::operation_enabled || s == state::quick_stop_active || v.outputs().torque;
  }
  drive_->view().set_connection_lost(loss_acting_);
}

void sim_device::report_changes() noexcept {
  const sim::drive_view v = drive_->view();
  const std::uint16_t status = v.outputs().status_word;
  const std::uint16_t error = v.outputs().error_code;
  const std::int32_t velocity = v.velocity_rpm();
  if (status != status_word_) {
    status_word_ = status;
    changed(object_index::status_word, 0);
  }
  if (error != error_code_) {
    error_code_ = error;
    changed(object_index::error_code, 0);
    changed(sim::object::error_register, 0);
    error_changed(error);
  }
  if (velocity != velocity_rpm_) {
    velocity_rpm_ = velocity;
    changed(object_index::velocity_actual_value, 0);
  }
  // The operation modes' actual values, as the bus reads them (0x6064 wraps as INTEGER32).
  const auto position = static_cast<std::int32_t>(v.position());
  if (position != position_) {
    position_ = position;
    changed(object_index::position_actual_value, 0);
  }
  const auto demand = static_cast<std::int32_t>(v.position_demand());
  if (demand != demand_) {
    demand_ = demand;
    changed(object_index::position_demand_value, 0);
    changed(object_index::following_error_actual_value, 0);
  }
  if (v.torque() != torque_) {
    torque_ = v.torque();
    changed(object_index::torque_actual_value, 0);
  }
  if (v.operation_mode() != mode_) {
    mode_ = v.operation_mode();
    changed(object_index::modes_of_operation_display, 0);
  }
}

std::array<std::uint8_t, 5> sim_device::manufacturer_error_field() const noexcept {
  const std::uint16_t status = drive_->view().outputs().status_word;
  return {static_cast<std::uint8_t>(status), static_cast<std::uint8_t>(status >> 8), 0, 0, 0};
}

sdo_abort sim_device::write(std::uint16_t index, std::uint8_t sub, std::int64_t value) noexcept {
  if (index != fault_injection_index) return drive_->write(index, sub, value);
  if (sub != 0) return sdo_abort::sub_index_does_not_exist;
  if (value < 0) return sdo_abort::value_too_low;
  if (value > 0xFFFF) return sdo_abort::value_too_high;
  if (value == 0) {
    drive_->view().clear_faults();
  } else {
    (void)drive_->view().inject_fault(static_cast<std::uint16_t>(value));
  }
  return sdo_abort::none;
}

void sim_device::reset() noexcept {
  // The configuration was accepted when the device was made, so this cannot throw.
  drive_ = std::make_unique<sim::virtual_drive>(*profile_, config_);
  loss_acting_ = false;  // a drive at power-on is not enabled: the loss acts again only if it becomes so
  apply_connection();
  pending_us_ = 0;
  report_changes();
}

}  // namespace cia402::drive402
