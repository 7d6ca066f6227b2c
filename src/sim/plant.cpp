// The plant and the object interface of a virtual drive. Every state-machine decision is the
// core's (cia402::step); this file only turns its outputs into motion and brake, and the motion and
// brake back into its inputs.
#include "cia402/sim/plant.hpp"

#include <limits>
#include <stdexcept>

#include "cia402/sim/machine.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/words.hpp"

namespace cia402::sim {
namespace {

constexpr std::int64_t micro = 1000000;  // micro-rpm per rpm

std::int64_t magnitude(std::int64_t v) noexcept { return v < 0 ? -v : v; }

// Cycles a delay takes, at least one: the drive sees a change in the next cycle at the earliest.
std::uint16_t delay_cycles(std::uint32_t delay_us, std::uint32_t cycle_us) noexcept {
  const std::uint64_t cycles = (std::uint64_t{delay_us} + cycle_us - 1) / cycle_us;
  return static_cast<std::uint16_t>(cycles < 1 ? 1 : cycles);
}

// Moves v towards goal: by at most `up` while |v| grows, by at most `down` while it shrinks. A
// change of sign first stops at 0 (the rest of that cycle is not carried over).
std::int64_t approach(std::int64_t v, std::int64_t goal, std::int64_t up,
                      std::int64_t down) noexcept {
  if (v == goal) return v;
  if (v >= 0 && goal > v) return v + up < goal ? v + up : goal;
  if (v <= 0 && goal < v) return v - up > goal ? v - up : goal;
  if (v > 0) {  // goal < v: slow down towards max(goal, 0)
    const std::int64_t floor = goal > 0 ? goal : 0;
    return v - down > floor ? v - down : floor;
  }
  const std::int64_t ceiling = goal < 0 ? goal : 0;  // v < 0, goal > v
  return v + down < ceiling ? v + down : ceiling;
}

// Micro-rpm per cycle of a stop ramp (not coast, not none).
std::int64_t ramp_step(const plant_constants& k, const axis_state& a, stop_ramp r) noexcept {
  const std::int64_t cycle = k.cycle_us;
  switch (r) {
    case stop_ramp::slow_down: return std::int64_t{a.deceleration} * cycle;
    case stop_ramp::quick_stop: return std::int64_t{a.quick_stop_deceleration} * cycle;
    case stop_ramp::current_limit:
      return std::int64_t{a.quick_stop_deceleration} * cycle * k.current_limit_percent / 100;
    case stop_ramp::voltage_limit:
      return std::int64_t{a.deceleration} * cycle * k.voltage_limit_percent / 100;
    case stop_ramp::none:
    case stop_ramp::coast: break;
  }
  return 0;
}

void set_flag(axis_state& a, std::uint8_t flag, bool on) noexcept {
  a.flags = static_cast<std::uint8_t>(on ? (a.flags | flag) : (a.flags & ~flag));
}

// The plant over one cycle under the outputs the drive just decided: first the shaft (with the
// brake as it was at the start of the cycle), then the brake.
void follow(const profile& p, const plant_constants& k, axis_state& a,
            const drive_outputs& out) noexcept {
  const std::int64_t cycle = k.cycle_us;
  std::int64_t goal = 0;
  std::int64_t up = 0;
  std::int64_t down = 0;
  if (!out.torque) {
    down = k.coast_step;  // coasting: friction only
  } else if (out.ramp != stop_ramp::none && out.ramp != stop_ramp::coast) {
    down = ramp_step(k, a, out.ramp);
  } else if (p.info(out.current).activity == state_activity::run) {
    goal = std::int64_t{effective_target(a)} * micro;
    up = std::int64_t{a.acceleration} * cycle;
    down = std::int64_t{a.deceleration} * cycle;
  } else {
    down = std::int64_t{a.deceleration} * cycle;  // torque held without motion (e.g. hold states)
  }
  if (k.brake_fitted && (a.flags & sim_flag::brake_closed)) {
    goal = 0;  // an engaged (or still releasing) brake holds the shaft: nothing accelerates
    up = 0;
    down += k.brake_step;
  }
  a.velocity = approach(a.velocity, goal, up, down);

  if (!k.brake_fitted) return;
  const bool open = out.brake_released;
  if (open != ((a.flags & sim_flag::brake_commanded_open) != 0)) {
    set_flag(a, sim_flag::brake_commanded_open, open);
    a.brake_timer = open ? k.release_cycles : k.engage_cycles;
  }
  const bool closed = (a.flags & sim_flag::brake_closed) != 0;
  if (closed == open) {  // not yet where commanded; a command taken back cancels the change
    if (a.brake_timer > 0) --a.brake_timer;
    if (a.brake_timer == 0) set_flag(a, sim_flag::brake_closed, !open);
  }
}

int fault_count(const axis_state& a) noexcept {
  int n = 0;
  while (n < max_fault_causes && a.fault_codes[n] != 0) ++n;
  return n;
}

void remove_fault_at(axis_state& a, int i) noexcept {
  for (int j = i; j + 1 < max_fault_causes; ++j) {
    a.fault_codes[j] = a.fault_codes[j + 1];
    a.fault_classes[j] = a.fault_classes[j + 1];
  }
  a.fault_codes[max_fault_causes - 1] = 0;
  a.fault_classes[max_fault_causes - 1] = 0;
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
  if (c.target_window_rpm > 1000000) return "target window must be at most 1000000 rpm";
  return nullptr;
}

plant_constants plant_constants::from(const plant_config& c) noexcept {
  plant_constants k;
  k.cycle_us = c.cycle_us;
  k.coast_step = std::int64_t{c.coast_deceleration} * c.cycle_us;
  k.brake_step = std::int64_t{c.brake_deceleration} * c.cycle_us;
  k.standstill_window = std::int64_t{c.standstill_window_rpm} * micro;
  k.target_window = std::int64_t{c.target_window_rpm} * micro;
  k.engage_cycles = delay_cycles(c.brake_engage_delay_us, c.cycle_us);
  k.release_cycles = delay_cycles(c.brake_release_delay_us, c.cycle_us);
  k.current_limit_percent = static_cast<std::uint16_t>(c.current_limit_percent);
  k.voltage_limit_percent = static_cast<std::uint16_t>(c.voltage_limit_percent);
  k.brake_fitted = c.brake_fitted;
  return k;
}

axis_state make_axis_state(const profile& p) noexcept {
  axis_state a;
  a.core = make_axis(p);
  return a;
}

namespace {

inline drive_inputs inputs_of(const plant_constants& k, const axis_state& a) noexcept {
  // The core's quiet cycle reads the first eight bytes of the inputs as one word; they are copied
  // whole from the defaults and touched only when an input differs, so that read is not stalled
  // behind byte stores.
  static constexpr drive_inputs nominal{};
  drive_inputs in = nominal;
  constexpr std::uint8_t unusual = sim_flag::sto | sim_flag::connection_lost;
  if (a.fault_codes[0] != 0 || (a.flags & (sim_flag::dc_link | unusual)) != sim_flag::dc_link) {
    const int n = fault_count(a);
    if (n > 0) {
      in.fault_code = a.fault_codes[n - 1];
      in.fault_class = a.fault_classes[n - 1];
    }
    in.dc_link = (a.flags & sim_flag::dc_link) != 0;
    in.sto = (a.flags & sim_flag::sto) != 0;
    in.connection_lost = (a.flags & sim_flag::connection_lost) != 0;
  }
  in.control_word = a.control_word;
  const bool standstill = magnitude(a.velocity) <= k.standstill_window;
  in.standstill = standstill;
  in.brake_engaged = brake_engaged(k, a);
  const bool target_reached =
      magnitude(a.velocity - std::int64_t{effective_target(a)} * micro) <= k.target_window;
  // Status bit 11 while a stop at the current or voltage limit is still braking.
  const bool internal_limit = !standstill && (a.last.ramp == stop_ramp::current_limit ||
                                              a.last.ramp == stop_ramp::voltage_limit);
  in.status_bits = static_cast<std::uint16_t>((target_reached ? status_bit::target_reached : 0u) |
                                              (internal_limit ? status_bit::internal_limit_active : 0u) |
                                              (standstill ? 0x1000u : 0u));  // pv: speed = 0
  in.actual_speed_rpm = velocity_rpm(a);
  return in;
}

}  // namespace

drive_inputs plant_inputs(const plant_constants& k, const axis_state& a) noexcept {
  return inputs_of(k, a);
}

const drive_outputs& step_axis(const profile& p, const plant_constants& k, axis_state& a) noexcept {
  const drive_outputs out = cia402::step(p, a.core, inputs_of(k, a));
  // Field by field: a whole-struct copy is assembled on the stack and read back in words, which
  // stalls on the narrow stores just made (a third of the cycle's time in the many-axes bench).
  a.last.current = out.current;
  a.last.status_word = out.status_word;
  a.last.transition = out.transition;
  a.last.ramp = out.ramp;
  a.last.torque = out.torque;
  a.last.brake_released = out.brake_released;
  a.last.clear_setpoints = out.clear_setpoints;
  a.last.error_code = out.error_code;
  a.last.error_register = out.error_register;
  if (out.clear_setpoints) a.flags |= sim_flag::setpoints_cleared;
  follow(p, k, a, out);
  return a.last;
}

namespace {

// The object at index/sub as this drive has it: from the one object table, an option code only
// where the profile has it. Existence, sub-index, access and range are checked here for every
// object alike; what a value means is the switch's below.
sdo_abort describe(const profile& p, std::uint16_t index, std::uint8_t sub,
                   const object_description*& out) noexcept {
  out = find_drive_object(index, 0);
  option o;
  if (out == nullptr || (option_of_index(index, o) && !p.spec(o).exists())) {
    return sdo_abort::object_does_not_exist;
  }
  if (sub != 0) return sdo_abort::sub_index_does_not_exist;
  return sdo_abort::none;
}

}  // namespace

sdo_abort write_object(const profile& p, axis_state& a, std::uint16_t index, std::uint8_t sub,
                       std::int64_t value) noexcept {
  if (index == object::error_register) {
    return sub != 0 ? sdo_abort::sub_index_does_not_exist : sdo_abort::read_only_object;
  }
  const object_description* o = nullptr;
  if (const sdo_abort r = describe(p, index, sub, o); r != sdo_abort::none) return r;
  if (const sdo_abort r = check_write(*o, value); r != sdo_abort::none) return r;
  option opt;
  if (option_of_index(index, opt)) return write_option(p, a.core, index, static_cast<std::int32_t>(value));
  switch (index) {
    case object::control_word: a.control_word = static_cast<std::uint16_t>(value); break;
    case object::target_velocity:
      a.target_velocity = static_cast<std::int32_t>(value);
      set_flag(a, sim_flag::setpoints_cleared, false);
      break;
    case object::profile_acceleration: a.acceleration = static_cast<std::uint32_t>(value); break;
    case object::profile_deceleration: a.deceleration = static_cast<std::uint32_t>(value); break;
    case object::quick_stop_deceleration:
      a.quick_stop_deceleration = static_cast<std::uint32_t>(value);
      break;
    case object::modes_of_operation:
      if (value != profile_velocity_mode) return sdo_abort::invalid_value;
      break;
    default: return sdo_abort::object_does_not_exist;
  }
  return sdo_abort::none;
}

sdo_abort read_object(const profile& p, const axis_state& a, std::uint16_t index, std::uint8_t sub,
                      std::int64_t& value) noexcept {
  if (index == object::error_register) {
    if (sub != 0) return sdo_abort::sub_index_does_not_exist;
    value = error_register_of(a.core.error_code);
    return sdo_abort::none;
  }
  const object_description* o = nullptr;
  if (const sdo_abort r = describe(p, index, sub, o); r != sdo_abort::none) return r;
  if (o->access == object_access::write_only) return sdo_abort::write_only_object;
  option opt;
  if (option_of_index(index, opt)) {
    std::int32_t v = 0;
    const sdo_abort r = read_option(p, a.core, index, v);
    if (r == sdo_abort::none) value = v;
    return r;
  }
  switch (index) {
    case object::control_word: value = a.control_word; break;
    case object::status_word: value = a.last.status_word; break;
    case object::target_velocity: value = a.target_velocity; break;
    case object::velocity_actual_value: value = velocity_rpm(a); break;
    case object::profile_acceleration: value = a.acceleration; break;
    case object::profile_deceleration: value = a.deceleration; break;
    case object::quick_stop_deceleration: value = a.quick_stop_deceleration; break;
    case object::error_code: value = a.core.error_code; break;
    case object::modes_of_operation:
    case object::modes_of_operation_display: value = profile_velocity_mode; break;
    case object::supported_drive_modes: value = o->default_value; break;
    default: return sdo_abort::object_does_not_exist;
  }
  return sdo_abort::none;
}

bool drive_view::inject_fault(std::uint16_t code, std::uint8_t error_class) noexcept {
  if (code == 0) return false;
  axis_state& a = *axis_;
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

virtual_drive::virtual_drive(const profile& p, const plant_config& config)
    : profile_(&p), axis_(make_axis_state(p)) {
  if (const char* why = check_plant_config(config)) throw std::invalid_argument(why);
  constants_ = plant_constants::from(config);
}

machine::machine(const profile& p, std::size_t axes, const plant_config& config)
    : profile_(&p), axes_(axes, make_axis_state(p)) {
  if (const char* why = check_plant_config(config)) throw std::invalid_argument(why);
  constants_ = plant_constants::from(config);
}

}  // namespace cia402::sim
