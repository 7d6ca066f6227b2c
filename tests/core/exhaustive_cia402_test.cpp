// Exhaustive check of the standard profile `cia402` (seed 002_522d2c0bb8f5a5f8.txt, semantics.md
// S1..S14): every FSA state x every 16-bit control word x bit 7 previously 0/1 x fault cause present
// or not, one step and a second step with the same inputs, on the ideal plant (drive_inputs
// defaults), against an oracle written here from the standard's tables and semantics.md. The oracle
// never calls the code under test and never reads the profile's rows.
#include <cstdint>
#include <sstream>
#include <string>

#include "test_support.hpp"

namespace cia402 {
namespace {

using test::hex;

// ---------------------------------------------------------------------------------------------
// The oracle.

enum class order { disable_voltage, quick_stop, shutdown, switch_on, enable_operation };

const char* order_name(order c) {
  switch (c) {
    case order::disable_voltage: return "Disable voltage";
    case order::quick_stop: return "Quick stop";
    case order::shutdown: return "Shutdown";
    case order::switch_on: return "Switch on / Disable operation";
    case order::enable_operation: return "Enable operation";
  }
  return "?";
}

// S1: a complete partition of bits 0..3, first match wins. Bits 4..15 play no part in the command.
order decode_s1(std::uint16_t cw) {
  if ((cw & 0x0002) == 0) return order::disable_voltage;
  if ((cw & 0x0004) == 0) return order::quick_stop;
  if ((cw & 0x0001) == 0) return order::shutdown;
  if ((cw & 0x0008) == 0) return order::switch_on;
  return order::enable_operation;
}

// cia402-reference.md §1.1 with S11 (bit 5 = 1 in READY TO SWITCH ON, SWITCHED ON, OPERATION
// ENABLED only): bits 0..3, 5, 6.
std::uint16_t state_bits_of(state s) {
  switch (s) {
    case state::start:
    case state::not_ready_to_switch_on: return 0x0000;
    case state::switch_on_disabled: return 0x0040;
    case state::ready_to_switch_on: return 0x0021;
    case state::switched_on: return 0x0023;
    case state::operation_enabled: return 0x0027;
    case state::quick_stop_active: return 0x0007;
    case state::fault_reaction_active: return 0x000F;
    case state::fault: return 0x0008;
  }
  return 0xFFFF;
}

// 0x605A 1..4 / 5..8, 0x605D 1..4 and 0x605E 1..4: slow-down ramp, quick-stop ramp, current limit,
// voltage limit (cia402-reference.md §3). 0 (605A, 605E): disable the drive function, i.e. coast.
stop_ramp ramp_of(int code) {
  switch (code) {
    case 0: return stop_ramp::coast;
    case 1: case 5: return stop_ramp::slow_down;
    case 2: case 6: return stop_ramp::quick_stop;
    case 3: case 7: return stop_ramp::current_limit;
    case 4: case 8: return stop_ramp::voltage_limit;
    default: return stop_ramp::none;
  }
}

// CiA 301 error register for the codes used here: bit 0 generic, bit 1 current (0x2xxx).
std::uint8_t register_of(std::uint16_t code) {
  if (code == 0) return 0;
  std::uint8_t r = 0x01;
  if ((code >> 12) == 0x2) r |= 0x02;
  if ((code >> 12) == 0x3) r |= 0x04;
  if ((code >> 12) == 0x4) r |= 0x08;
  return r;
}

// What the oracle remembers between steps.
struct model {
  state s = state::switch_on_disabled;
  bool prev_bit7 = false;       // S2: the edge is taken against the previous control word
  bool torque_was_on = false;   // the previous step delivered torque
  bool reaction_coasts = false; // the running fault reaction is a coast
  int pending = 0;              // 5 or 8: that transition's slow-down stop runs (S7)
  std::uint16_t error_code = 0; // 0x603F
  int qs = 2, shutdown = 1, disable_operation = 1, halt = 1, fault_reaction = 2;  // defaults S5..S9
};

struct expectation {
  state current;
  std::uint8_t transition;
  std::uint16_t status_word;
  bool torque;
  bool brake_released;
  stop_ramp ramp;
  bool clear_setpoints;
  std::uint16_t error_code;
  std::uint8_t error_register;
};

// One step of the ideal plant: DC link on, no STO, at standstill, brake engaged, remote, no warning.
// Every ramp finishes in the step after it starts.
expectation oracle_step(model& m, std::uint16_t cw, std::uint16_t fault_code) {
  const bool bit7 = (cw & 0x0080) != 0;
  const bool reset_edge = bit7 && !m.prev_bit7;  // S2
  m.prev_bit7 = bit7;
  const order c = decode_s1(cw);
  const bool halt = (cw & 0x0100) != 0;
  const bool fault = fault_code != 0;
  const state from = m.s;

  std::uint8_t t = no_transition;
  state to = from;
  auto take = [&](std::uint8_t number, state dest) { t = number; to = dest; };

  if (m.pending != 0) {
    // S7: while the T5/T8 stop runs, Disable voltage (T9), Quick stop (T11) and faults (T13) take
    // over; anything else waits, and the stop (at standstill now) completes.
    if (fault) take(13, state::fault_reaction_active);
    else if (c == order::disable_voltage) take(9, state::switch_on_disabled);
    else if (c == order::quick_stop) take(11, state::quick_stop_active);
    else if (m.pending == 5) take(5, state::switched_on);
    else take(8, state::ready_to_switch_on);
    m.pending = 0;
  } else if (fault && from != state::fault_reaction_active && from != state::fault) {
    take(13, state::fault_reaction_active);  // S4, and faults win over any command (S12)
  } else {
    switch (from) {
      case state::start: take(0, state::not_ready_to_switch_on); break;
      case state::not_ready_to_switch_on: take(1, state::switch_on_disabled); break;
      case state::switch_on_disabled:
        if (c == order::shutdown) take(2, state::ready_to_switch_on);
        break;
      case state::ready_to_switch_on:
        if (c == order::disable_voltage || c == order::quick_stop) take(7, state::switch_on_disabled);
        // S3: Enable operation here takes T3 now and T4 in the next step.
        else if (c == order::switch_on || c == order::enable_operation) take(3, state::switched_on);
        break;
      case state::switched_on:
        if (c == order::disable_voltage || c == order::quick_stop) take(10, state::switch_on_disabled);
        else if (c == order::shutdown) take(6, state::ready_to_switch_on);
        else if (c == order::enable_operation) take(4, state::operation_enabled);
        break;
      case state::operation_enabled:
        if (c == order::disable_voltage) take(9, state::switch_on_disabled);
        else if (c == order::quick_stop) take(11, state::quick_stop_active);
        else if (c == order::shutdown) {
          // S7: 0x605B = 0 changes at once; 1 ramps first and the state shows the source meanwhile.
          if (m.shutdown == 1) m.pending = 8;
          else take(8, state::ready_to_switch_on);
        } else if (c == order::switch_on) {
          if (m.disable_operation == 1) m.pending = 5;
          else take(5, state::switched_on);
        }
        break;
      case state::quick_stop_active:
        // S6, S5.
        if (c == order::disable_voltage) take(12, state::switch_on_disabled);
        else if (m.qs >= 1 && m.qs <= 4) take(12, state::switch_on_disabled);  // ramp has ended
        else if (m.qs >= 5 && m.qs <= 8 && c == order::enable_operation) {
          take(16, state::operation_enabled);
        }
        break;
      case state::fault_reaction_active:
        take(14, state::fault);  // the reaction (ramp or coast) has ended on the ideal plant
        break;
      case state::fault:
        if (reset_edge && !fault) take(15, state::switch_on_disabled);  // S2
        break;
    }
  }

  // 0x603F: a new fault is recorded (T13, or S4 in FRA and FAULT); T15 clears it.
  if (fault && (t == 13 || from == state::fault_reaction_active || from == state::fault)) {
    m.error_code = fault_code;
  }
  if (t == 15) m.error_code = 0;
  if (t == 13) m.reaction_coasts = !m.torque_was_on || m.fault_reaction == 0;

  // Outputs of where the drive is now (S12, S11).
  expectation e{};
  bool target = false;
  e.ramp = stop_ramp::none;
  if (m.pending != 0) {
    // The slow-down stop runs in OPERATION ENABLED; at standstill the brake closes before torque
    // goes. Bit 10 belongs to a halt or a 5..8 quick stop, not to a stop that leaves the state.
    e.torque = true;
    e.brake_released = false;
    e.ramp = stop_ramp::slow_down;
  } else {
    switch (to) {
      case state::operation_enabled:
        e.torque = true;
        e.brake_released = true;  // a halt keeps torque, so the brake stays open
        if (halt) {
          e.ramp = ramp_of(m.halt);  // S8
          target = true;             // at standstill
        }
        break;
      case state::quick_stop_active:
        if (m.qs == 0) {
          e.ramp = stop_ramp::coast;  // S5: drive function off at once
        } else if (m.qs <= 4) {
          e.torque = true;  // ramps; at standstill the brake closes before T12 removes torque
          e.ramp = ramp_of(m.qs);
        } else {
          e.torque = true;  // holds
          e.brake_released = true;
          e.ramp = ramp_of(m.qs);
          target = true;  // S5: bit 10 at standstill
        }
        break;
      case state::fault_reaction_active:
        if (m.reaction_coasts) {
          e.ramp = stop_ramp::coast;
        } else {
          e.torque = true;
          e.ramp = ramp_of(m.fault_reaction);  // S9; brake closes at standstill
        }
        break;
      default: break;  // no torque, brake closed
    }
  }
  m.s = to;
  m.torque_was_on = e.torque;
  e.current = to;
  e.transition = t;
  e.status_word = static_cast<std::uint16_t>(state_bits_of(to) | 0x0010 /* DC link */ |
                                             0x0200 /* remote */ | (target ? 0x0400 : 0));
  e.clear_setpoints = t == 4;  // seed 002 T4: "clear all internal" set-points
  e.error_code = m.error_code;
  e.error_register = register_of(m.error_code);
  return e;
}

// ---------------------------------------------------------------------------------------------
// The sweep.

constexpr std::uint16_t fault_cause = 0x2310;  // continuous over-current
constexpr std::uint16_t earlier_error = 0x5530;

const state fsa_states[] = {
    state::not_ready_to_switch_on, state::switch_on_disabled, state::ready_to_switch_on,
    state::switched_on,            state::operation_enabled,  state::quick_stop_active,
    state::fault_reaction_active,  state::fault,
};

struct sweep_config {
  int qs = 2, shutdown = 1, disable_operation = 1;
};

// The axis and the oracle's model for "drive in state s", set up as the brief says.
void set_up(const profile& p, state s, bool bit7_before, const sweep_config& cfg, axis& a, model& m) {
  a = make_axis(p);
  ASSERT_EQ(write_option(p, a, 0x605A, cfg.qs), sdo_abort::none);
  ASSERT_EQ(write_option(p, a, 0x605B, cfg.shutdown), sdo_abort::none);
  ASSERT_EQ(write_option(p, a, 0x605C, cfg.disable_operation), sdo_abort::none);
  a.current = s;
  if (bit7_before) a.flags |= axis_flag::fault_reset_bit;
  // Torque is on in OPERATION ENABLED, in QUICK STOP ACTIVE unless 605A = 0 coasted, and in a
  // ramping FAULT REACTION ACTIVE.
  const bool torque = s == state::operation_enabled ||
                      (s == state::quick_stop_active && cfg.qs != 0) ||
                      s == state::fault_reaction_active;
  if (torque) a.flags |= axis_flag::torque_on;
  if (s == state::fault_reaction_active || s == state::fault) a.error_code = earlier_error;
  // The quick stop and the fault reaction started with the codes configured here (S16).
  if (s == state::quick_stop_active) a.stop_code = static_cast<std::int8_t>(cfg.qs);
  if (s == state::fault_reaction_active) a.stop_code = a.options[static_cast<int>(option::fault_reaction)];

  m = model{};
  m.s = s;
  m.prev_bit7 = bit7_before;
  m.torque_was_on = torque;
  m.error_code = a.error_code;
  m.qs = cfg.qs;
  m.shutdown = cfg.shutdown;
  m.disable_operation = cfg.disable_operation;
}

struct mismatch_log {
  long count = 0;
  long checked = 0;
  std::string first;
  void add(const std::string& s) {
    if (++count <= 8) first += s + "\n";
  }
  std::string report() const {
    std::ostringstream os;
    os << count << " mismatches in " << checked << " checked steps; the first ones:\n" << first;
    return os.str();
  }
};

// Mismatches of the FSA behaviour (state, transition, status word, torque, brake, ramp, set-points)
// and of the error code (0x603F / 0x1001) are counted apart, so one cannot hide the other.
struct sweep_logs {
  mismatch_log behaviour;
  mismatch_log error_code;
};

bool behaviour_matches(const expectation& e, const drive_outputs& o) {
  return e.current == o.current && e.transition == o.transition && e.status_word == o.status_word &&
         e.torque == o.torque && e.brake_released == o.brake_released && e.ramp == o.ramp &&
         e.clear_setpoints == o.clear_setpoints;
}

bool error_code_matches(const expectation& e, const drive_outputs& o) {
  return e.error_code == o.error_code && e.error_register == o.error_register;
}

// Compares one step; false if the behaviour differs (later steps then say nothing new). The context
// is built only for a mismatch: the sweeps run millions of steps.
template <typename Context>
bool compare(const expectation& e, const drive_outputs& o, Context context, sweep_logs& logs) {
  ++logs.behaviour.checked;
  ++logs.error_code.checked;
  const bool behaviour = behaviour_matches(e, o);
  if (behaviour && error_code_matches(e, o)) return true;
  const std::string both = context() + ":\n    expected " + test::describe(e) + "\n    actual   " +
                           test::describe(o);
  (behaviour ? logs.error_code : logs.behaviour).add(both);
  return behaviour;
}

void expect_no_mismatch(const sweep_logs& logs) {
  EXPECT_EQ(logs.behaviour.count, 0) << "FSA behaviour differs from the oracle: "
                                     << logs.behaviour.report();
  EXPECT_EQ(logs.error_code.count, 0) << "0x603F / 0x1001 differ from the oracle: "
                                      << logs.error_code.report();
}

// Every 16-bit control word x bit 7 before x fault or not, for one state: two steps with the same
// inputs each (the second shows completions: T4 after T3, T12 after a 1..4 quick stop, T5/T8 after
// their ramp, T14 after T13).
void sweep_state(const profile& p, state s, const sweep_config& cfg, sweep_logs& logs) {
  for (int bit7_before = 0; bit7_before <= 1; ++bit7_before) {
    axis start_axis;
    model start_model;
    set_up(p, s, bit7_before != 0, cfg, start_axis, start_model);
    for (int with_fault = 0; with_fault <= 1; ++with_fault) {
      for (std::uint32_t cw = 0; cw <= 0xFFFF; ++cw) {
        axis a = start_axis;
        model m = start_model;
        drive_inputs in;
        in.control_word = static_cast<std::uint16_t>(cw);
        in.fault_code = with_fault ? fault_cause : 0;
        for (int step_no = 1; step_no <= 2; ++step_no) {
          const expectation e = oracle_step(m, in.control_word, in.fault_code);
          const drive_outputs o = step(p, a, in);
          auto context = [&] {
            std::ostringstream os;
            os << "from " << state_name(s) << " cw=" << hex(cw) << " ("
               << order_name(decode_s1(static_cast<std::uint16_t>(cw))) << ") bit7_before="
               << bit7_before << " fault=" << (with_fault ? hex(fault_cause) : "none")
               << " 605A=" << cfg.qs << " 605B=" << cfg.shutdown << " 605C="
               << cfg.disable_operation << " step " << step_no;
            return os.str();
          };
          if (!compare(e, o, context, logs)) break;
        }
      }
    }
  }
}

TEST(exhaustive_cia402, every_state_control_word_reset_bit_and_fault_matches_the_standard) {
  const profile& p = standard_profile();
  sweep_logs logs;
  for (state s : fsa_states) sweep_state(p, s, sweep_config{}, logs);
  expect_no_mismatch(logs);
  if (logs.behaviour.count == 0) {
    EXPECT_EQ(logs.behaviour.checked, 8L * 65536 * 2 * 2 * 2) << "every case ran both steps";
  }
}

// S5, S6: every quick stop option code in QUICK STOP ACTIVE.
TEST(exhaustive_cia402, quick_stop_active_every_option_code_matches_s5_and_s6) {
  const profile& p = standard_profile();
  sweep_logs logs;
  for (int qs = 0; qs <= 8; ++qs) {
    sweep_config cfg;
    cfg.qs = qs;
    sweep_state(p, state::quick_stop_active, cfg, logs);
  }
  expect_no_mismatch(logs);
}

// S7: 0x605B and 0x605C, 0 and 1, in OPERATION ENABLED; the second step completes a ramped T5/T8.
TEST(exhaustive_cia402, operation_enabled_shutdown_and_disable_operation_codes_match_s7) {
  const profile& p = standard_profile();
  sweep_logs logs;
  for (int shutdown = 0; shutdown <= 1; ++shutdown) {
    for (int disable_operation = 0; disable_operation <= 1; ++disable_operation) {
      sweep_config cfg;
      cfg.shutdown = shutdown;
      cfg.disable_operation = disable_operation;
      sweep_state(p, state::operation_enabled, cfg, logs);
    }
  }
  expect_no_mismatch(logs);
}

// S7: while a ramped T5 or T8 runs, every control word and fault in the next step: T9, T11 and T13
// take over, anything else waits and the stop completes at standstill.
TEST(exhaustive_cia402, running_t5_or_t8_stop_then_every_control_word_matches_s7) {
  const profile& p = standard_profile();
  sweep_logs logs;
  // Disable operation (T5) and Shutdown (T8), the latter with bit 7 and the halt bit, which play no
  // part in it.
  const std::uint16_t starters[] = {0x0007, 0x0186};
  for (std::uint16_t first : starters) {
    for (int bit7_before = 0; bit7_before <= 1; ++bit7_before) {
      axis start_axis;
      model start_model;
      set_up(p, state::operation_enabled, bit7_before != 0, sweep_config{}, start_axis, start_model);
      drive_inputs in;
      in.control_word = first;
      const expectation e1 = oracle_step(start_model, in.control_word, 0);
      const drive_outputs o1 = step(p, start_axis, in);
      auto context1 = [&] {
        std::ostringstream os;
        os << "from OPERATION_ENABLED bit7_before=" << bit7_before << " cw=" << hex(first)
           << " step 1";
        return os.str();
      };
      if (!compare(e1, o1, context1, logs)) continue;
      for (int with_fault = 0; with_fault <= 1; ++with_fault) {
        for (std::uint32_t cw = 0; cw <= 0xFFFF; ++cw) {
          axis a = start_axis;
          model m = start_model;
          in.control_word = static_cast<std::uint16_t>(cw);
          in.fault_code = with_fault ? fault_cause : 0;
          const expectation e2 = oracle_step(m, in.control_word, in.fault_code);
          const drive_outputs o2 = step(p, a, in);
          auto context = [&] {
            std::ostringstream os;
            os << "from OPERATION_ENABLED bit7_before=" << bit7_before << " first cw="
               << hex(first) << " then cw=" << hex(cw) << " ("
               << order_name(decode_s1(static_cast<std::uint16_t>(cw)))
               << ") fault=" << (with_fault ? hex(fault_cause) : "none") << " step 2";
            return os.str();
          };
          compare(e2, o2, context, logs);
        }
      }
    }
  }
  expect_no_mismatch(logs);
}

// The oracle itself must be able to fail: a few hand-checked points against seed 002 and S-rules,
// so a broken oracle cannot pass the sweeps silently.
TEST(exhaustive_cia402, oracle_agrees_with_hand_read_seed_rows) {
  model m;
  m.s = state::switch_on_disabled;
  EXPECT_EQ(oracle_step(m, 0x0006, 0).transition, 2);  // seed 002 T2: Shutdown
  EXPECT_EQ(oracle_step(m, 0x000F, 0).transition, 3);  // S3: T3 ...
  const expectation t4 = oracle_step(m, 0x000F, 0);    // ... then T4
  EXPECT_EQ(t4.transition, 4);
  EXPECT_EQ(t4.status_word, 0x0237);
  EXPECT_TRUE(t4.torque);
  EXPECT_EQ(oracle_step(m, 0x000B, 0).transition, 11);  // Quick stop
  EXPECT_EQ(oracle_step(m, 0x000B, 0).transition, 12);  // 605A = 2 ends by itself
  m.s = state::fault;
  m.prev_bit7 = false;
  EXPECT_EQ(oracle_step(m, 0x0080, 0x1000).transition, no_transition);  // cause still present
  EXPECT_EQ(oracle_step(m, 0x0080, 0).transition, no_transition);       // edge used up (S2)
  EXPECT_EQ(oracle_step(m, 0x0000, 0).transition, no_transition);
  EXPECT_EQ(oracle_step(m, 0x0080, 0).transition, 15);
}

}  // namespace
}  // namespace cia402
