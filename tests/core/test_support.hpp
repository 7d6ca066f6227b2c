// Helpers shared by the core's behavioural tests: printing, the control words each built-in profile's
// seed uses for the standard commands, and driving an axis through real steps to a given state.
// Nothing here computes an expected outcome: the tests write those from the seeds and semantics.md.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "cia402/state.hpp"

namespace cia402 {
// So gtest prints states and ramps by name, not as raw bytes.
inline void PrintTo(state s, std::ostream* os) { *os << state_name(s); }
inline void PrintTo(stop_ramp r, std::ostream* os) { *os << stop_ramp_name(r); }
inline void PrintTo(sdo_abort a, std::ostream* os) {
  *os << "0x" << std::hex << static_cast<std::uint32_t>(a) << std::dec << " (" << sdo_abort_text(a)
      << ")";
}
}  // namespace cia402

namespace cia402::test {

inline const profile& builtin(const char* name) {
  const profile* p = find_builtin_profile(name);
  if (p == nullptr) {
    ADD_FAILURE() << "no built-in profile named " << name;
    return standard_profile();
  }
  return *p;
}

inline std::vector<const profile*> all_builtins() {
  std::vector<const profile*> out;
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) out.push_back(&builtin_profile(i));
  return out;
}

/// The control words a master sends for the standard commands, as each seed spells them.
/// cia402-reference.md §2.2 for the CiA 402 drives (seeds 000, 001, 002) and seed 003's STW; seed
/// 004 (AX2000) needs bit 4 set for Enable operation, and bit 4 cleared is its fast stop.
struct command_words {
  std::uint16_t disable_voltage = 0x0000;
  std::uint16_t quick_stop = 0x0002;
  std::uint16_t shutdown = 0x0006;
  std::uint16_t switch_on = 0x0007;  ///< also Disable operation
  std::uint16_t enable_operation = 0x000F;
};

inline command_words words_for(const profile& p) {
  command_words w;
  if (std::strcmp(p.name, "ax2000-profibus") == 0) {
    // 004_e07fd68605b3a8c6.txt: T11 "Bit 4 is canceled", T16 "Bit 4 is set".
    w.quick_stop = 0x000F;
    w.shutdown = 0x0016;
    w.switch_on = 0x0017;
    w.enable_operation = 0x001F;
  }
  return w;
}

inline std::string hex(std::uint32_t v, int width = 4) {
  std::ostringstream os;
  os << "0x" << std::hex;
  os.width(width);
  os.fill('0');
  os << v;
  return os.str();
}

/// One line of a step's outputs, or of anything with their fields (an oracle's expectation).
template <typename Outputs>
std::string describe(const Outputs& o) {
  std::ostringstream os;
  os << state_name(o.current) << " T"
     << (o.transition == no_transition ? std::string("-") : std::to_string(o.transition))
     << " sw=" << hex(o.status_word) << " torque=" << o.torque << " brake_released="
     << o.brake_released << " ramp=" << stop_ramp_name(o.ramp) << " clear_setpoints="
     << o.clear_setpoints << " error=" << hex(o.error_code) << " reg=" << hex(o.error_register, 2);
  return os.str();
}

inline bool same_outputs(const drive_outputs& a, const drive_outputs& b) {
  return a.current == b.current && a.status_word == b.status_word && a.transition == b.transition &&
         a.ramp == b.ramp && a.torque == b.torque && a.brake_released == b.brake_released &&
         a.clear_setpoints == b.clear_setpoints && a.error_code == b.error_code &&
         a.error_register == b.error_register;
}

inline bool same_bytes(const axis& a, const axis& b) { return std::memcmp(&a, &b, sizeof(axis)) == 0; }

/// An axis bound to a profile, stepped with inputs the test owns.
struct bench {
  const profile& p;
  axis a;
  drive_inputs in;
  drive_outputs out;
  std::vector<std::uint8_t> taken;  ///< every transition taken, in order

  explicit bench(const profile& prof) : p(prof), a(make_axis(prof)) {}

  const drive_outputs& step() {
    out = cia402::step(p, a, in);
    if (out.transition != no_transition) taken.push_back(out.transition);
    return out;
  }
  /// Steps with unchanged inputs until a transition is taken (at most `limit` steps); returns it.
  std::uint8_t step_until_transition(int limit = 4) {
    for (int i = 0; i < limit; ++i) {
      step();
      if (out.transition != no_transition) return out.transition;
    }
    return no_transition;
  }
  /// Steps with unchanged inputs until the state stops changing; returns the transitions taken.
  std::vector<std::uint8_t> settle(int limit = 8) {
    std::vector<std::uint8_t> seen;
    for (int i = 0; i < limit; ++i) {
      const state before = a.current;
      step();
      if (out.transition != no_transition) seen.push_back(out.transition);
      if (out.transition == no_transition && a.current == before && a.pending_row == 0xFF) break;
    }
    return seen;
  }
  sdo_abort write(std::uint16_t index, std::int32_t value) { return write_option(p, a, index, value); }
};

/// Drives `b` from power-up through real transitions to `target`, on an ideal plant, using the
/// profile's own command words. Leaves the control word that holds the state in b.in.control_word.
/// For QUICK STOP ACTIVE the caller picks 0x605A first where the profile has it (codes 1..4 leave the
/// state by themselves one step later). FAULT is reached with the cause already cleared.
inline ::testing::AssertionResult reach(bench& b, state target) {
  const command_words w = words_for(b.p);
  if (target == state::start) goto check;
  b.in.control_word = w.disable_voltage;
  b.step();  // T0
  if (target == state::not_ready_to_switch_on) goto check;
  b.step();  // T1
  if (target == state::switch_on_disabled) goto check;
  if (target == state::fault_reaction_active || target == state::fault) {
    b.in.fault_code = 0x5530;  // any cause; a "hardware" code, class 2 where classes exist
    b.in.fault_class = 2;
    b.step();  // T13 from SWITCH ON DISABLED
    if (target == state::fault_reaction_active) goto check;
    b.step();  // T14
    b.in.fault_code = 0;
    b.step();  // the cause is gone, bit 7 low: stays in FAULT
    goto check;
  }
  b.in.control_word = w.shutdown;
  b.step();  // T2
  if (target == state::ready_to_switch_on) goto check;
  b.in.control_word = w.switch_on;
  b.step();  // T3
  if (target == state::switched_on) goto check;
  b.in.control_word = w.enable_operation;
  b.step();  // T4
  if (target == state::operation_enabled) goto check;
  b.in.control_word = w.quick_stop;
  b.step();  // T11
check:
  if (b.a.current != target) {
    return ::testing::AssertionFailure()
           << "could not reach " << state_name(target) << " in profile " << b.p.name
           << "; stuck in " << state_name(b.a.current) << " after " << describe(b.out);
  }
  return ::testing::AssertionSuccess();
}

/// The transitions each seed prints as supported, 0..17 (the seeds' own numbering).
inline std::vector<int> seed_transitions(const profile& p) {
  std::vector<int> t;
  const std::string seed = p.seed;
  if (seed == "000_44b471b7401b86be.txt") {
    // T11 and T12 are printed but "'Quick Stop' is not supported"; there is no T16.
    t = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 13, 14, 15};
  } else if (seed == "004_e07fd68605b3a8c6.txt") {
    for (int i = 0; i <= 17; ++i) t.push_back(i);
  } else {
    // 001, 002 and 003 print T0..T16.
    for (int i = 0; i <= 16; ++i) t.push_back(i);
  }
  return t;
}

// The states some chain of rows leads to from START. A row may list a source state its profile never
// enters (no-quick-stop shares "every state but FAULT" for T13, QUICK STOP ACTIVE included).
inline std::uint16_t reachable_states(const profile& p) {
  std::uint16_t seen = state_bit(state::start);
  for (bool grew = true; grew;) {
    grew = false;
    for (std::size_t i = 0; i < p.row_count; ++i) {
      const transition_row r = p.row(i);
      if ((r.from & seen) != 0 && (seen & state_bit(r.to)) == 0) {
        seen = static_cast<std::uint16_t>(seen | state_bit(r.to));
        grew = true;
      }
    }
  }
  return seen;
}

}  // namespace cia402::test
