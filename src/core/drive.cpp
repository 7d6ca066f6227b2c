#include "cia402/drive.hpp"

#include "cia402/words.hpp"
#include "bits.hpp"

namespace cia402 {
namespace {

constexpr std::uint8_t no_row = 0xFF;

// The pieces of the full step (commit_row, state_outputs) are compiled into it: g++ -O3 called them,
// and then an ordinary cycle's constant inputs (ordinary_full_step) did not reach them. A build
// for size leaves the choice to the compiler, which keeps the firmware smaller (bench/cortex_m4).
#if defined(__OPTIMIZE_SIZE__) || !defined(__GNUC__)
#define CIA402_STEP_PIECE
#else
#define CIA402_STEP_PIECE [[gnu::always_inline]] inline
#endif

constexpr std::uint32_t bits(fact f) noexcept { return static_cast<std::uint32_t>(f); }

constexpr std::uint32_t command_facts = bits(fact::disable_voltage) | bits(fact::quick_stop) |
                                        bits(fact::shutdown) | bits(fact::switch_on) |
                                        bits(fact::enable_operation) |
                                        bits(fact::stop_and_inhibit) | bits(fact::fault_reset);
constexpr std::uint32_t fault_facts = bits(fact::fault) | bits(fact::fault_quick_stop);

std::int8_t option_value(const axis& a, option o) noexcept {
  return a.options[static_cast<int>(o)];
}

namespace stop_bits = detail::stop_bits;
using detail::stop_nibble;

constexpr std::uint32_t stop_table = [] {
  std::uint32_t t = 0;
  for (int s = 0; s < row_stop_count; ++s) t |= stop_nibble(static_cast<row_stop>(s)) << (4 * s);
  return t;
}();
static_assert(row_stop_count <= 8, "a nibble per row_stop in 32 bits");
static_assert(static_cast<int>(stop_ramp::slow_down) == 1 && static_cast<int>(stop_ramp::quick_stop) == 2 &&
              static_cast<unsigned>(stop_ramp::coast) == detail::ramp_of_code(0));

unsigned stop_of(row_stop s) noexcept {
  const unsigned i = static_cast<unsigned>(s);
  return i < row_stop_count ? (stop_table >> (4 * i)) & 0xFu : 0u;
}

// The option code a row's stop depends on, read when the stop starts (S16).
std::int8_t stop_code_of_row(const axis& a, unsigned stop) noexcept {
  if (!(stop & stop_bits::if_code_is_1)) return 0;
  return option_value(a, (stop & stop_bits::code_605c) ? option::disable_operation : option::shutdown);
}

// Whether a row's stop runs a ramp before its state change, given the code read when it started;
// else the change is immediate. A ramp 0x605D picks is never none, so its code is not read here.
bool stop_ramps(unsigned stop, int code) noexcept {
  return (stop & stop_bits::ramp) != 0 && !((stop & stop_bits::if_code_is_1) && code != 1);
}

// What the present state (or the pending row's stop) asks of the motion side, and whether that stop
// ends with torque off (so the brake closes at standstill first, S12). Packed in one register: the
// ramp in bits 0..7, then the two flags.
namespace activity {
constexpr unsigned torque_wanted = 1u << 8;
constexpr unsigned stop_ends_torque = 1u << 9;
constexpr unsigned ramp = 0xFFu;
}  // namespace activity

unsigned activity_of(const profile& p, const axis& a, bool halt) noexcept {
  // The option code is chosen first so that detail::ramp_of_code() is compiled once, not per case (the
  // Cortex-M4 firmware: bench/cortex_m4). Torque is "wanted" in every state but an idle one, also
  // where the stop coasts: the outputs turn a coast's torque off all the same.
  unsigned ends = 0;
  int code;
  if (a.pending_row != no_row) {
    const stored_row& r = p.rows[a.pending_row];
    const unsigned stop = stop_of(r.stop);
    // A stop into a state that holds torque (SWITCHED ON of seeds 003/004) keeps the brake open.
    ends = p.torque_allowed(r.to) ? 0u : activity::stop_ends_torque;
    const unsigned ramp = stop & stop_bits::ramp;
    if ((stop & stop_bits::if_code_is_1) && a.stop_code != 1) return activity::torque_wanted | ends;
    if (ramp != stop_bits::halt_ramp_live) return ramp | activity::torque_wanted | ends;
    code = option_value(a, option::halt);
  } else {
    const state_activity act = p.info(a.current).activity;
    if (act == state_activity::idle) return 0;
    code = a.stop_code;
    if (act == state_activity::hold || act == state_activity::run) {
      if (!halt || act != state_activity::run) return activity::torque_wanted;
      code = option_value(a, option::halt);
    } else if (act == state_activity::fault_reaction) {
      // 0x605E as it was when the reaction started (S16), unless the drive turned it into a coast.
      ends = activity::stop_ends_torque;
      if (a.flags & axis_flag::coast_reaction) code = 0;
    } else if (code >= 1 && code <= 4) {  // 0x605A as it was when the quick stop started (S16)
      ends = activity::stop_ends_torque;
    }
  }
  return detail::ramp_of_code(code) | activity::torque_wanted | ends;
}

bool raised_by_drive(std::uint16_t code) noexcept {
  return (code == error_code::safe_torque_off) | (code == error_code::dc_link_undervoltage) |
         (code == error_code::heartbeat);
}

// The fault facts an error class raises (fault, fault_quick_stop, fault_present, fault_immediate:
// bits 8..11), a nibble per class 0..5 (5 stands for any class above 4). Without error classes a
// fault has class 2, or 3 when the drive raised it itself, so the table serves both.
constexpr std::uint32_t fault_facts_of_class = [] {
  std::uint32_t t = 0;
  for (unsigned c = 0; c <= 5; ++c) {
    const std::uint32_t facts = (c >= 2 ? bits(fact::fault) : 0u) |
                                (c == 1 ? bits(fact::fault_quick_stop) : 0u) |
                                (c >= 1 ? bits(fact::fault_present) : 0u) |
                                (c >= 3 ? bits(fact::fault_immediate) : 0u);
    t |= (facts >> 8) << (4 * c);
  }
  return t;
}();
static_assert((fault_facts | bits(fact::fault_present) | bits(fact::fault_immediate)) == 0xF00u);

// The fault the drive acts on in a cycle: an event of its own (STO or undervoltage while torque was
// on, S13/S14), a cause from outside, or a lost connection with 0x6007 = 1, which is a fault even
// beside a mere warning (class 0 or 1). The drive's own faults have class 3.
struct cycle_fault {
  std::uint16_t code = 0;
  unsigned error_class = 0;
  bool internal = false;  ///< raised by the drive itself
};

cycle_fault fault_of(const profile& p, const drive_inputs& in, bool torque_was_on, bool link_fault) noexcept {
  cycle_fault f;
  const unsigned input_class = p.error_classes ? in.fault_class : 2u;
  if (torque_was_on && (in.sto || !in.dc_link)) {
    f.code = in.sto ? error_code::safe_torque_off : error_code::dc_link_undervoltage;
    f.error_class = 3;
    f.internal = true;
  } else if (in.fault_code != 0 && (input_class >= 2 || !link_fault)) {
    f.code = in.fault_code;
    f.error_class = input_class;
  } else if (link_fault) {
    f.code = error_code::heartbeat;
    f.error_class = 2;
  }
  return f;
}

// Seed 001: T2 needs "< 1000 RPM", T7 fires on "> 1000 RPM"; exactly 1000 does neither.
std::uint32_t speed_facts(const profile& p, const drive_inputs& in) noexcept {
  const std::int32_t limit = p.speed_limit_rpm;
  const std::int32_t speed = in.actual_speed_rpm;
  const std::uint32_t magnitude = speed < 0 ? 0u - static_cast<std::uint32_t>(speed)
                                            : static_cast<std::uint32_t>(speed);
  if (limit <= 0) return bits(fact::below_speed_limit);
  if (magnitude > static_cast<std::uint32_t>(limit)) return bits(fact::overspeed);
  if (magnitude < static_cast<std::uint32_t>(limit)) return bits(fact::below_speed_limit);
  return 0;
}

// The first row leaving state `from` whose facts hold, or no_row.
std::uint8_t first_row(const profile& p, int from, std::uint32_t f) noexcept {
  for (std::uint32_t rows = p.rows_from[from]; rows != 0; rows &= rows - 1) {
    const std::uint8_t i = static_cast<std::uint8_t>(detail::lowest_bit(rows));
    const stored_row& r = p.rows[i];
    const std::uint32_t all = p.fact_sets[r.all];
    if ((p.fact_sets[r.any] & f) && (all & f) == all && !(p.fact_sets[r.none] & f)) return i;
  }
  return no_row;
}

// The state change of a row whose stop (if any) is done: the new state, its stop code (S16), the
// axis flags and the error code its reasons call for.
CIA402_STEP_PIECE void commit_row(const profile& p, axis& a, const stored_row& r, std::uint32_t f, const cycle_fault& fault,
                bool torque_was_on, bool sto, drive_outputs& out) noexcept {
  const std::uint32_t why = p.fact_sets[r.any] & f;
  a.current = r.to;
  a.pending_row = no_row;
  // S16: the quick stop and the fault reaction run by the code they find as they start.
  const state_activity act = p.info(r.to).activity;
  a.stop_code = act == state_activity::quick_stop       ? option_value(a, option::quick_stop)
                : act == state_activity::fault_reaction ? option_value(a, option::fault_reaction)
                                                        : std::int8_t{0};
  a.last_transition = r.number;
  out.transition = r.number;
  out.clear_setpoints = (r.flags & row_flag::clears_setpoints) != 0;
  // Built in a register and stored once: a store per flag made the Cortex-M4 firmware larger.
  unsigned flags = a.flags & ~static_cast<unsigned>(axis_flag::entered_by_fault);
  if ((why & fault_facts) && !(why & command_facts)) flags |= axis_flag::entered_by_fault;
  if (why & fault_facts) a.error_code = fault.code;
  if (why & (bits(fact::fault) | bits(fact::fault_reset))) {
    flags &= ~static_cast<unsigned>(axis_flag::coast_reaction);
    // A fault reaction has nothing to ramp when torque is already off, or cannot (S14). A fault
    // reset ends the coast.
    if (!(why & bits(fact::fault_reset)) && (fault.error_class >= 3 || !torque_was_on || sto)) {
      flags |= axis_flag::coast_reaction;
    }
  }
  if (why & bits(fact::fault_reset)) a.error_code = 0;
  a.flags = static_cast<std::uint8_t>(flags);
}

// The outputs of the state the drive is in now (or of the stop it runs), and torque_on for the next
// cycle.
CIA402_STEP_PIECE void state_outputs(const profile& p, axis& a, const drive_inputs& in, bool halt, drive_outputs& out) noexcept {
  const unsigned now = activity_of(p, a, halt);
  const state s = a.current;
  out.current = s;
  const bool torque_wanted = (now & activity::torque_wanted) != 0;
  const auto ramp = static_cast<stop_ramp>(now & activity::ramp);
  const bool torque = torque_wanted && !in.sto && ramp != stop_ramp::coast;
  out.ramp = in.sto && torque_wanted ? stop_ramp::coast : ramp;
  out.torque = torque;
  out.brake_released = torque && !((now & activity::stop_ends_torque) && in.standstill);
  a.flags = static_cast<std::uint8_t>((a.flags & ~axis_flag::torque_on) |
                                      (torque ? axis_flag::torque_on : 0u));

  const state_info info = p.info(s);
  std::uint32_t sw = info.status_pattern | (static_cast<std::uint32_t>(in.dc_link) << 4) |
                     (static_cast<std::uint32_t>(in.sto) << 7) |
                     (static_cast<std::uint32_t>(in.remote) << 9) |
                     (in.status_bits & (status_bit::reported & ~status_bit::target_reached));
  sw |= static_cast<std::uint32_t>(p.error_classes & (in.fault_code != 0) & (in.fault_class <= 1))
        << 7;  // status_bit::warning
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
  out.error_register = error_register_of(a.error_code);
}

}  // namespace

axis make_axis(const profile& p) noexcept {
  axis a;
  for (int i = 0; i < option_count; ++i) a.options[i] = p.options[i].default_value;
  return a;
}

namespace {

// Everything but the ordinary cycle (detail/quiet_step.hpp): facts, the first matching row, pending
// stops (S7), outputs. With Ordinary the inputs an ordinary cycle has (no fault code, DC link, no STO,
// remote, link up, no local request) are constants the compiler folds away.
template <bool Ordinary>
drive_outputs full_step_of(const profile& p, axis& a, const drive_inputs& given) noexcept {
  drive_inputs ordinary;
  if constexpr (Ordinary) {
    ordinary = given;
    ordinary.fault_code = 0;
    ordinary.dc_link = true;
    ordinary.sto = false;
    ordinary.remote = true;
    ordinary.connection_lost = false;
    ordinary.local_enable = false;
    ordinary.local_disable = false;
  }
  const drive_inputs& in = Ordinary ? ordinary : given;
  drive_outputs out;
  // Facts of this cycle.
  const std::uint16_t cw = in.control_word;
  // The axis keeps bit 7 in fault_reset_bit (bit 3, where compiled.hpp's key needs it); the edge is
  // taken in bit 0: working in bit 3 made the Cortex-M4 firmware 40 bytes larger (bench/cortex_m4).
  constexpr unsigned reset_flag_shift = 3;
  static_assert(axis_flag::fault_reset_bit == 1u << reset_flag_shift);
  const std::uint32_t reset_bit = (cw >> 7) & 1u;
  const std::uint32_t reset_edge = reset_bit & ~(static_cast<std::uint32_t>(a.flags) >> reset_flag_shift);
  a.flags = static_cast<std::uint8_t>((a.flags & ~axis_flag::fault_reset_bit) |
                                      (reset_bit << reset_flag_shift));  // S2
  const bool torque_was_on = (a.flags & axis_flag::torque_on) != 0;
  const state_activity act_before = p.info(a.current).activity;

  std::uint32_t f = bits(fact::automatic) |
                    (in.dc_link ? bits(fact::dc_link) : bits(fact::undervoltage)) |
                    (static_cast<std::uint32_t>(in.sto) << 13) |
                    // S15: a local enable commands only while the control word does not; a
                    // local disable acts whatever place has control.
                    (static_cast<std::uint32_t>(in.local_enable && !in.remote) << 19) |
                    (static_cast<std::uint32_t>(in.local_disable) << 20) |
                    // S16: in QUICK STOP ACTIVE the code read when the quick stop started.
                    detail::quick_stop_facts(act_before == state_activity::quick_stop
                                         ? a.stop_code
                                         : a.options[static_cast<int>(option::quick_stop)]) |
                    ((static_cast<std::uint32_t>(a.flags) & axis_flag::entered_by_fault) << 18) |
                    ((static_cast<std::uint32_t>(a.flags) & axis_flag::fault_latched) << 19);
  static_assert(axis_flag::entered_by_fault << 18 == static_cast<std::uint32_t>(fact::entered_by_fault));
  static_assert(axis_flag::fault_latched << 19 == static_cast<std::uint32_t>(fact::fault_latched));

  const int abort_code = option_value(a, option::abort_connection);
  const bool link_fault = in.connection_lost && abort_code == 1;
  if (in.connection_lost && abort_code >= 2) {
    f |= abort_code == 2 ? bits(fact::disable_voltage) : bits(fact::quick_stop);  // S10
  } else if (in.remote) {
    f |= (1u << p.command_of_bits[cw & 0x1Fu]) | (reset_edge << 6);
  }
  const bool halt = in.remote && (cw & control_bit::halt) && p.spec(option::halt).exists();
  if (halt) f |= bits(fact::halt);

  const cycle_fault fault = fault_of(p, in, torque_was_on, link_fault);
  f |= ((fault_facts_of_class >> (4 * (fault.error_class < 5 ? fault.error_class : 5u))) & 0xFu) << 8;
  if (fault.error_class == 4) {  // only with error classes
    a.flags |= axis_flag::fault_latched;
    f |= bits(fact::fault_latched);
  }
  // S4: a fault that calls for a coast turns a ramped fault reaction into a coast at once, so the
  // stop completes (T14) in this same step with torque off and the brake closed.
  if (act_before == state_activity::fault_reaction &&
      (f & (bits(fact::sto) | bits(fact::undervoltage) | bits(fact::fault_immediate)))) {
    a.flags |= axis_flag::coast_reaction;
  }
  f |= speed_facts(p, in);

  // A stop is complete at standstill with the brake engaged (when it ends with torque off), or at
  // once when it coasts.
  // Only a pending row, QUICK STOP ACTIVE and FAULT REACTION ACTIVE run stops that can coast or
  // end with torque off; elsewhere standstill is enough.
  bool complete = in.sto || in.standstill;
  if (a.pending_row != no_row || act_before == state_activity::quick_stop ||
      act_before == state_activity::fault_reaction) {
    const unsigned before = activity_of(p, a, halt);
    complete = (before & activity::ramp) == static_cast<unsigned>(stop_ramp::coast) || in.sto ||
               (in.standstill && (in.brake_engaged || !(before & activity::stop_ends_torque)));
  }
  if (complete) f |= bits(fact::stop_complete);

  const std::uint8_t match = first_row(p, static_cast<int>(a.current), f);

  // S7: while a row's stop runs, only rows that interrupt stops may take over; otherwise the
  // pending row completes when its stop does. A row with a ramp of its own runs it first, also
  // when it takes over from another stop (T17 during T5 still stops on the quick-stop ramp).
  std::uint8_t commit = no_row;
  std::uint8_t take = match;
  if (a.pending_row != no_row) {
    if (match == no_row || match == a.pending_row ||
        !(p.rows[match].flags & row_flag::interrupts_stop)) {
      take = no_row;
      if (complete) commit = a.pending_row;
    }
  }
  if (take != no_row) {
    const unsigned stop = stop_of(p.rows[take].stop);
    const std::int8_t code = stop_code_of_row(a, stop);  // read as the stop starts (S16)
    if (torque_was_on && !in.sto && stop_ramps(stop, code)) {
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
      ((a.current == state::fault_reaction_active) | (a.current == state::fault)) &&
      (fault.internal || !raised_by_drive(a.error_code))) {
    a.error_code = fault.code;
  }

  if (commit != no_row) commit_row(p, a, p.rows[commit], f, fault, torque_was_on, in.sto, out);
  state_outputs(p, a, in, halt, out);
  return out;
}

}  // namespace

drive_outputs detail::full_step(const profile& p, axis& a, const drive_inputs& in) noexcept {
  return full_step_of<false>(p, a, in);
}

// A build for size has the one full step: a second instance would call the pieces (commit_row,
// state_outputs) from two places, so they would no longer be compiled into it (bench/cortex_m4).
drive_outputs detail::ordinary_full_step(const profile& p, axis& a, const drive_inputs& in) noexcept {
#if defined(__OPTIMIZE_SIZE__)
  return detail::full_step(p, a, in);
#else
  return full_step_of<true>(p, a, in);
#endif
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
