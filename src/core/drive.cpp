#include "cia402/drive.hpp"

#include "cia402/words.hpp"
#include "bits.hpp"

namespace cia402 {
namespace {

constexpr std::uint8_t no_row = 0xFF;

constexpr std::uint32_t bits(fact f) noexcept { return static_cast<std::uint32_t>(f); }

constexpr std::uint32_t command_facts = bits(fact::disable_voltage) | bits(fact::quick_stop) |
                                        bits(fact::shutdown) | bits(fact::switch_on) |
                                        bits(fact::enable_operation) |
                                        bits(fact::stop_and_inhibit) | bits(fact::fault_reset);
constexpr std::uint32_t fault_facts = bits(fact::fault) | bits(fact::fault_quick_stop);

std::int8_t option_value(const axis& a, option o) noexcept {
  return a.options[static_cast<int>(o)];
}

// 1/5 slow-down, 2/6 quick-stop, 3/7 current limit, 4/8 voltage limit, 0 coast (0x605A, 0x605E).
stop_ramp ramp_of_code(int code) noexcept {
  if (code <= 0) return stop_ramp::coast;
  return static_cast<stop_ramp>(((code - 1) & 3) + 1);
}

// The option code a row's stop depends on, read when the stop starts (S16).
std::int8_t stop_code_of_row(const axis& a, row_stop stop) noexcept {
  switch (stop) {
    case row_stop::shutdown_option:
    case row_stop::shutdown_option_halt: return option_value(a, option::shutdown);
    case row_stop::disable_operation_option: return option_value(a, option::disable_operation);
    case row_stop::immediate:
    case row_stop::slow_down_ramp:
    case row_stop::quick_stop_ramp:
    case row_stop::halt_ramp: break;
  }
  return 0;
}

// The ramp a row's stop runs before its state change, given the code read when it started; none
// means the change is immediate. 0x605D acts at once (S16), so a stop "with Halt" reads it live.
stop_ramp ramp_of_row(const axis& a, row_stop stop, int code) noexcept {
  switch (stop) {
    case row_stop::shutdown_option:
    case row_stop::disable_operation_option:
      return code == 1 ? stop_ramp::slow_down : stop_ramp::none;
    case row_stop::slow_down_ramp: return stop_ramp::slow_down;
    case row_stop::quick_stop_ramp: return stop_ramp::quick_stop;
    case row_stop::halt_ramp: return ramp_of_code(option_value(a, option::halt));
    case row_stop::shutdown_option_halt:
      return code == 1 ? ramp_of_code(option_value(a, option::halt)) : stop_ramp::none;
    case row_stop::immediate: break;
  }
  return stop_ramp::none;
}

// What the present state (or the pending row's stop) asks of the motion side, and whether that stop
// ends with torque off (so the brake closes at standstill first, S12).
struct activity_now {
  stop_ramp ramp = stop_ramp::none;
  bool torque_wanted = false;
  bool stop_ends_torque = false;
};

activity_now activity_of(const profile& p, const axis& a, bool halt) noexcept {
  activity_now now;
  if (a.pending_row != no_row) {
    const transition_row& r = p.rows[a.pending_row];
    now.ramp = ramp_of_row(a, r.stop, a.stop_code);
    now.torque_wanted = true;
    // A stop into a state that holds torque (SWITCHED ON of seeds 003/004) keeps the brake open.
    now.stop_ends_torque = !p.torque_allowed(r.to);
    return now;
  }
  switch (p.info(a.current).activity) {
    case state_activity::idle: break;
    case state_activity::hold: now.torque_wanted = true; break;
    case state_activity::run:
      now.torque_wanted = true;
      if (halt) now.ramp = ramp_of_code(option_value(a, option::halt));
      break;
    case state_activity::quick_stop: {
      const int code = a.stop_code;  // 0x605A as it was when the quick stop started (S16)
      now.ramp = ramp_of_code(code);
      now.torque_wanted = now.ramp != stop_ramp::coast;
      now.stop_ends_torque = code >= 1 && code <= 4;
      break;
    }
    case state_activity::fault_reaction:
      now.ramp = (a.flags & axis_flag::coast_reaction)
                     ? stop_ramp::coast
                     : ramp_of_code(a.stop_code);  // 0x605E as at T13 (S16)
      now.torque_wanted = now.ramp != stop_ramp::coast;
      now.stop_ends_torque = true;
      break;
  }
  return now;
}

// The fault the drive acts on this cycle: a cause from outside, a lost connection with 0x6007 = 1,
// or an event of its own (STO or undervoltage while torque was on, S13/S14).
struct fault_now {
  std::uint16_t code = 0;
  std::uint8_t error_class = 0;
  bool internal = false;
};

fault_now fault_of(const profile& p, const axis& a, const drive_inputs& in) noexcept {
  const bool torque_was_on = (a.flags & axis_flag::torque_on) != 0;
  if (torque_was_on && in.sto) return {error_code::safe_torque_off, 3, true};
  if (torque_was_on && !in.dc_link) return {error_code::dc_link_undervoltage, 3, true};
  const std::uint8_t input_class = p.error_classes ? in.fault_class : std::uint8_t{2};
  if (in.fault_code != 0 && input_class >= 2) return {in.fault_code, input_class, false};
  // A lost connection with 0x6007 = 1 is a fault even beside a mere warning (class 0 or 1).
  if (in.connection_lost && option_value(a, option::abort_connection) == 1) {
    return {error_code::heartbeat, 2, false};
  }
  if (in.fault_code != 0) return {in.fault_code, input_class, false};
  return {};
}

bool raised_by_drive(std::uint16_t code) noexcept {
  return code == error_code::safe_torque_off || code == error_code::dc_link_undervoltage ||
         code == error_code::heartbeat;
}

void set_flag(axis& a, std::uint8_t flag, bool on) noexcept {
  a.flags = static_cast<std::uint8_t>(on ? (a.flags | flag) : (a.flags & ~flag));
}

}  // namespace

axis make_axis(const profile& p) noexcept {
  axis a;
  for (int i = 0; i < option_count; ++i) a.options[i] = p.options[i].default_value;
  return a;
}

namespace {

// Everything but the quiet cycle (detail/quiet_step.hpp): facts, the first matching row, pending
// stops (S7), outputs.
}  // namespace

drive_outputs detail::full_step(const profile& p, axis& a, const drive_inputs& in) noexcept {
  drive_outputs out;
  // Facts of this cycle. The common cycle (remote, no fault, voltage, no STO, no stop pending)
  // takes no branch here but the one on the fault code.
  const std::uint16_t cw = in.control_word;
  const std::uint32_t reset_bit = (cw >> 7) & 1u;
  const std::uint32_t reset_edge = reset_bit & ~static_cast<std::uint32_t>(a.flags);
  a.flags = static_cast<std::uint8_t>((a.flags & ~axis_flag::fault_reset_bit) | reset_bit);  // S2

  std::uint32_t f = bits(fact::automatic) |
                    (in.dc_link ? bits(fact::dc_link) : bits(fact::undervoltage)) |
                    (static_cast<std::uint32_t>(in.sto) << 13) |
                    // S15: a local enable commands only while the control word does not; a
                    // local disable acts whatever place has control.
                    (static_cast<std::uint32_t>(in.local_enable && !in.remote) << 19) |
                    (static_cast<std::uint32_t>(in.local_disable) << 20) |
                    // S16: in QUICK STOP ACTIVE the code read when the quick stop started.
                    quick_stop_facts(p.info(a.current).activity == state_activity::quick_stop
                                         ? a.stop_code
                                         : a.options[static_cast<int>(option::quick_stop)]) |
                    ((static_cast<std::uint32_t>(a.flags) & axis_flag::entered_by_fault) << 16) |
                    ((static_cast<std::uint32_t>(a.flags) & axis_flag::fault_latched) << 17);
  static_assert(axis_flag::entered_by_fault << 16 == static_cast<std::uint32_t>(fact::entered_by_fault));
  static_assert(axis_flag::fault_latched << 17 == static_cast<std::uint32_t>(fact::fault_latched));

  const int abort_code = option_value(a, option::abort_connection);
  if (!in.connection_lost || abort_code < 2) {
    if (in.remote) f |= (1u << p.command_of_bits[cw & 0x1Fu]) | (reset_edge << 6);
  } else {
    f |= abort_code == 2 ? bits(fact::disable_voltage) : bits(fact::quick_stop);  // S10
  }
  const bool halt = in.remote && (cw & control_bit::halt) && p.spec(option::halt).exists();
  if (halt) f |= bits(fact::halt);

  fault_now fault;
  if (in.fault_code != 0 || in.connection_lost || (a.flags & axis_flag::torque_on)) {
    fault = fault_of(p, a, in);
    if (fault.code != 0) {
      if (!p.error_classes || fault.error_class >= 2) f |= bits(fact::fault);
      if (p.error_classes && fault.error_class == 1) f |= bits(fact::fault_quick_stop);
      if (!p.error_classes || fault.error_class >= 1) f |= bits(fact::fault_present);
      if (fault.error_class >= 3) f |= bits(fact::fault_immediate);
      if (p.error_classes && fault.error_class == 4) {
        a.flags |= axis_flag::fault_latched;
        f |= bits(fact::fault_latched);
      }
    }
  }
  // S4: a fault that calls for a coast turns a ramped fault reaction into a coast at once, so the
  // stop completes (T14) in this same step with torque off and the brake closed.
  const state_activity act_before = p.info(a.current).activity;
  if (act_before == state_activity::fault_reaction &&
      (in.sto || !in.dc_link || (fault.code != 0 && fault.error_class >= 3))) {
    a.flags |= axis_flag::coast_reaction;
  }
  // Seed 001: T2 needs "< 1000 RPM", T7 fires on "> 1000 RPM"; exactly 1000 does neither.
  const std::int32_t limit = p.speed_limit_rpm;
  const std::int32_t speed = in.actual_speed_rpm;
  if (limit > 0 && (speed > limit || speed < -limit)) f |= bits(fact::overspeed);
  if (limit <= 0 || (speed < limit && speed > -limit)) f |= bits(fact::below_speed_limit);

  // A stop is complete at standstill with the brake engaged (when it ends with torque off), or at
  // once when it coasts.
  // Only a pending row, QUICK STOP ACTIVE and FAULT REACTION ACTIVE run stops that can coast or
  // end with torque off; elsewhere standstill is enough.
  const bool torque_was_on = (a.flags & axis_flag::torque_on) != 0;
  bool complete = in.sto || in.standstill;
  if (a.pending_row != no_row || act_before == state_activity::quick_stop ||
      act_before == state_activity::fault_reaction) {
    const activity_now before = activity_of(p, a, halt);
    complete = before.ramp == stop_ramp::coast || in.sto ||
               (in.standstill && (in.brake_engaged || !before.stop_ends_torque));
  }
  if (complete) f |= bits(fact::stop_complete);

  // The first row leaving the present state whose facts hold.
  const int from = static_cast<int>(a.current);
  std::uint8_t match = no_row;
  if (p.busy_from[from] & f) {
    for (std::uint32_t rows = p.rows_from[from]; rows != 0; rows &= rows - 1) {
      const std::uint8_t i = static_cast<std::uint8_t>(detail::lowest_bit(rows));
      const transition_row& r = p.rows[i];
      if ((r.any.bits() & f) && (r.all.bits() & f) == r.all.bits() && !(r.none.bits() & f)) {
        match = i;
        break;
      }
    }
  }

  // S7: while a row's stop runs, only rows that interrupt stops may take over; otherwise the
  // pending row completes when its stop does. A row with a ramp of its own runs it first, also
  // when it takes over from another stop (T17 during T5 still stops on the quick-stop ramp).
  std::uint8_t commit = no_row;
  std::uint8_t take = no_row;
  if (a.pending_row != no_row) {
    if (match != no_row && match != a.pending_row &&
        (p.rows[match].flags & row_flag::interrupts_stop)) {
      take = match;
    } else if (f & bits(fact::stop_complete)) {
      commit = a.pending_row;
    }
  } else {
    take = match;
  }
  if (take != no_row) {
    const row_stop stop = p.rows[take].stop;
    const std::int8_t code = stop_code_of_row(a, stop);  // read as the stop starts (S16)
    const bool ramp_first = torque_was_on && !in.sto && ramp_of_row(a, stop, code) != stop_ramp::none;
    if (ramp_first) {
      a.pending_row = take;
      a.stop_code = code;
    } else {
      commit = take;
    }
  }
  // S4: in FAULT REACTION ACTIVE and FAULT a new fault is recorded, whatever else happens. A fault
  // the drive raised itself (STO or undervoltage under torque, a lost link) came after the outside
  // cause that is still present, so that cause does not write over it.
  if ((f & bits(fact::fault)) &&
      (a.current == state::fault_reaction_active || a.current == state::fault) &&
      (fault.internal || !raised_by_drive(a.error_code))) {
    a.error_code = fault.code;
  }

  if (commit != no_row) {
    const transition_row& r = p.rows[commit];
    const std::uint32_t why = r.any.bits() & f;
    a.current = r.to;
    a.pending_row = no_row;
    // S16: the quick stop and the fault reaction run by the code they find as they start.
    switch (p.info(r.to).activity) {
      case state_activity::quick_stop: a.stop_code = option_value(a, option::quick_stop); break;
      case state_activity::fault_reaction:
        a.stop_code = option_value(a, option::fault_reaction);
        break;
      default: a.stop_code = 0; break;
    }
    a.last_transition = r.number;
    out.transition = r.number;
    out.clear_setpoints = (r.flags & row_flag::clears_setpoints) != 0;
    set_flag(a, axis_flag::entered_by_fault, (why & fault_facts) && !(why & command_facts));
    if (why & fault_facts) a.error_code = fault.code;
    if (why & bits(fact::fault)) {
      // A fault reaction has nothing to ramp when torque is already off, or cannot (S14).
      set_flag(a, axis_flag::coast_reaction, fault.internal || fault.error_class >= 3 ||
                                                 !torque_was_on || in.sto);
    }
    if (why & bits(fact::fault_reset)) {
      a.error_code = 0;
      set_flag(a, axis_flag::coast_reaction, false);
    }
  }
  const activity_now now = activity_of(p, a, halt);

  // Outputs of the state the drive is in now.
  const state s = a.current;
  out.current = s;
  const bool torque = now.torque_wanted && !in.sto && now.ramp != stop_ramp::coast;
  out.ramp = in.sto && now.torque_wanted ? stop_ramp::coast : now.ramp;
  out.torque = torque;
  out.brake_released = torque && !(now.stop_ends_torque && in.standstill);
  a.flags = static_cast<std::uint8_t>((a.flags & ~axis_flag::torque_on) |
                                      (torque ? axis_flag::torque_on : 0u));

  const state_info info = p.info(s);
  std::uint32_t sw = info.status_pattern | (static_cast<std::uint32_t>(in.dc_link) << 4) |
                     (static_cast<std::uint32_t>(in.sto) << 7) |
                     (static_cast<std::uint32_t>(in.remote) << 9) |
                     (in.status_bits & (status_bit::reported & ~status_bit::target_reached));
  if (p.error_classes && in.fault_code != 0 && in.fault_class <= 1) sw |= status_bit::warning;
  bool target;
  if (info.activity == state_activity::run) {
    target = halt ? in.standstill : (in.status_bits & status_bit::target_reached) != 0;
  } else {
    const int qs_code = a.stop_code;
    target = info.activity == state_activity::quick_stop && qs_code >= 5 && qs_code <= 8 &&
             in.standstill;
  }
  if (target && a.pending_row == no_row) sw |= status_bit::target_reached;
  out.status_word = static_cast<std::uint16_t>(sw);
  out.error_code = a.error_code;
  out.error_register = a.error_code ? error_register_of(a.error_code) : std::uint8_t{0};
  return out;
}

sdo_abort write_option(const profile& p, axis& a, std::uint16_t index, std::int32_t value) noexcept {
  option o;
  if (!option_of_index(index, o) || !p.spec(o).exists()) return sdo_abort::object_does_not_exist;
  if (!p.spec(o).allows(value)) return sdo_abort::invalid_value;
  a.options[static_cast<int>(o)] = static_cast<std::int8_t>(value);
  return sdo_abort::none;
}

sdo_abort read_option(const profile& p, const axis& a, std::uint16_t index,
                      std::int32_t& value) noexcept {
  option o;
  if (!option_of_index(index, o) || !p.spec(o).exists()) return sdo_abort::object_does_not_exist;
  value = a.options[static_cast<int>(o)];
  return sdo_abort::none;
}

}  // namespace cia402
