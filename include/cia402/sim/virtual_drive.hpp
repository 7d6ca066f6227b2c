// A virtual drive: the core state machine and a plant (sim/plant.hpp) behind one object interface,
// the way a fieldbus sees a drive. The CANopen layer sits on write()/read() unchanged: their results
// are the SDO abort codes.
#pragma once

#include <cstdint>

#include "cia402/drive.hpp"
#include "cia402/objects.hpp"
#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"
#include "cia402/sim/plant.hpp"

namespace cia402::sim {

/// The virtual drive's objects: the drive profile's, described once in cia402/objects.hpp (index,
/// type, access, limits, name), and the CiA 301 error register beside them.
namespace object {
using namespace cia402::object_index;
inline constexpr std::uint16_t error_register = 0x1001;  ///< UINT8, read-only (CiA 301)
/// Option codes 0x605A..0x605E and 0x6007 go to cia402::write_option / read_option.
}  // namespace object

/// The mode a drive powers up in (0x6060 / 0x6061); cia402::mode lists every mode the plant runs.
inline constexpr std::int64_t profile_velocity_mode = cia402::mode::profile_velocity;

namespace detail {
/// write_object() for every object but the set-points it writes inline.
sdo_abort write_any_object(const profile& p, axis_state& a, std::uint16_t index, std::uint8_t sub,
                           std::int64_t value) noexcept;
}  // namespace detail

/// Writes an object of one axis. Results: none; object_does_not_exist (unknown index, or an option
/// code the profile lacks); sub_index_does_not_exist (sub != 0); read_only_object (0x6041, 0x606C,
/// 0x603F, 0x1001, 0x6061); value_too_high / value_too_low (outside the object's type, or a ramp of
/// 0 rpm/s, which would never end); invalid_value (an option code or mode the profile does not
/// support). A refused write changes nothing. A write of 0x60FF also ends the "set-points cleared"
/// of T4.
///
/// Inline for 0x607A, 0x60FF and 0x6071 (sub 0), the set-points a cyclic master writes to every axis
/// every cycle (an RPDO's): the table's entry and limits as for every object, then the field.
inline sdo_abort write_object(const profile& p, axis_state& a, std::uint16_t index,
                              std::uint8_t sub, std::int64_t value) noexcept {
  if (index == object::target_position || index == object::target_velocity ||
      index == object::target_torque) {
    if (const object_description* o = find_drive_object(index, sub)) {
      if (const sdo_abort r = check_write(*o, value); r != sdo_abort::none) return r;
      if (index == object::target_position) {
        a.objects.target_position = static_cast<std::int32_t>(value);
      } else if (index == object::target_velocity) {
        a.target_velocity = static_cast<std::int32_t>(value);
      } else {
        a.objects.target_torque = static_cast<std::int16_t>(value);
      }
      // T4's clearing ends. Stored only when set: the next step reads the flags in a wide load,
      // which a narrow store just before would stall (store forwarding).
      if (a.flags & sim_flag::setpoints_cleared) {
        a.flags &= static_cast<std::uint8_t>(~sim_flag::setpoints_cleared);
      }
      return sdo_abort::none;
    }
  }
  return detail::write_any_object(p, a, index, sub, value);
}

/// Reads an object of one axis on a plant; on success `value` holds it (sign-extended for signed
/// types).
sdo_abort read_object(const profile& p, const plant_constants& k, const axis_state& a, std::uint16_t index,
                      std::uint8_t sub, std::int64_t& value) noexcept;

/// One axis, seen from outside: a handle into a machine or a virtual_drive. Cheap to copy; valid
/// while its owner lives.
class drive_view {
 public:
  drive_view(const profile& p, const plant_constants& k, axis_state& a) noexcept
      : profile_(&p), constants_(&k), axis_(&a) {}

  /// The object interface (see write_object / read_object).
  sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t value) noexcept {
    return write_object(*profile_, *axis_, index, sub, value);
  }
  sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& value) const noexcept {
    return read_object(*profile_, *constants_, *axis_, index, sub, value);
  }

  /// A fault cause appears (error code 0x0001..0xFFFF, error class 0..4 for profiles with classes).
  /// A cause raised again becomes the newest. With max_fault_causes already present the oldest is
  /// dropped; returns false then (and for code 0, which changes nothing).
  bool inject_fault(std::uint16_t code, std::uint8_t error_class = 2) noexcept;
  /// The cause with this code is gone; false if it was not present.
  bool clear_fault(std::uint16_t code) noexcept;
  /// Every cause is gone.
  void clear_faults() noexcept;
  /// The cause the drive sees (the newest), 0 if none.
  std::uint16_t fault_cause() const noexcept;

  void set_dc_link(bool present) noexcept { set(sim_flag::dc_link, present); }
  void set_sto(bool active) noexcept { set(sim_flag::sto, active); }
  void set_connection_lost(bool lost) noexcept { set(sim_flag::connection_lost, lost); }

  bool dc_link() const noexcept { return axis_->flags & sim_flag::dc_link; }
  bool sto() const noexcept { return axis_->flags & sim_flag::sto; }
  bool connection_lost() const noexcept { return axis_->flags & sim_flag::connection_lost; }

  /// What the core decided in the last cycle.
  const drive_outputs& outputs() const noexcept { return axis_->last; }
  state current() const noexcept { return axis_->core.current; }
  std::uint16_t control_word() const noexcept { return axis_->control_word; }
  /// Actual velocity: rpm rounded towards zero (0x606C), and exact in micro-rpm.
  std::int32_t velocity_rpm() const noexcept { return sim::velocity_rpm(*axis_); }
  std::int64_t velocity_micro_rpm() const noexcept { return axis_->velocity; }
  /// 0x60FF as written, and the set-point the motion side follows (0 after T4 until rewritten).
  std::int32_t target_velocity() const noexcept { return axis_->target_velocity; }
  std::int32_t effective_target() const noexcept { return sim::effective_target(*axis_); }
  /// The operation modes: 0x6061 (the mode running), 0x6060 (as written), 0x6064 position actual
  /// (increments, exact), 0x6062 demand, 0x60F4 following error, 0x6077 torque (permille).
  std::int8_t operation_mode() const noexcept { return axis_->operation_mode; }
  std::int8_t requested_mode() const noexcept { return axis_->requested_mode; }
  std::int64_t position() const noexcept { return axis_->position; }
  /// The shaft's own position, where the switches and index pulses are (0x6064 minus what homing
  /// set), and 0x60FD.
  std::int64_t shaft_position() const noexcept { return sim::shaft_position(*axis_); }
  std::uint32_t digital_inputs() const noexcept { return sim::digital_inputs(*constants_, *axis_); }
  /// What a homing run is doing (homing_phase_name() says it in words).
  motion::homing_phase homing_phase() const noexcept { return axis_->homing.phase(); }
  std::int64_t position_demand() const noexcept { return axis_->demand; }
  std::int64_t following_error() const noexcept { return sim::following_error(*axis_); }
  std::int32_t torque() const noexcept { return axis_->torque; }
  /// The brake holds the shaft (true when none is fitted).
  bool brake_engaged() const noexcept { return sim::brake_engaged(*constants_, *axis_); }
  /// The feedback the next cycle will give the drive.
  drive_inputs inputs() const noexcept { return plant_inputs(*constants_, *axis_); }

  const axis_state& state_of_axis() const noexcept { return *axis_; }
  const profile& table() const noexcept { return *profile_; }

 private:
  void set(std::uint8_t flag, bool on) noexcept {
    axis_->flags = static_cast<std::uint8_t>(on ? (axis_->flags | flag) : (axis_->flags & ~flag));
  }

  const profile* profile_;
  const plant_constants* constants_;
  axis_state* axis_;
};

/// One virtual drive with its own clock of cycles. The profile must outlive it.
class virtual_drive {
 public:
  /// Throws std::invalid_argument when check_plant_config() refuses the configuration.
  explicit virtual_drive(const profile& p, const plant_config& config = {});
  virtual_drive(const virtual_drive&) = delete;  // views point into it
  virtual_drive& operator=(const virtual_drive&) = delete;

  /// One cycle at time() (the plant's feedback in, the core's decision, the plant follows); then the
  /// clock advances by one cycle.
  drive_outputs step() noexcept {
    const drive_outputs out = step_axis(*profile_, constants_, axis_);
    ++cycle_;
    return out;
  }

  drive_view view() noexcept { return {*profile_, constants_, axis_}; }
  /// Cycles stepped so far, and the virtual time of the next step in microseconds.
  std::uint64_t cycle() const noexcept { return cycle_; }
  std::uint64_t time_us() const noexcept { return cycle_ * constants_.cycle_us; }
  const plant_constants& constants() const noexcept { return constants_; }

  // The view's interface, for convenience.
  sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t value) noexcept {
    return view().write(index, sub, value);
  }
  sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& value) const noexcept {
    return read_object(*profile_, constants_, axis_, index, sub, value);
  }

 private:
  const profile* profile_;
  plant_constants constants_;
  axis_state axis_;
  std::uint64_t cycle_ = 0;
};

}  // namespace cia402::sim
