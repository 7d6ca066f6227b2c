// Long random runs on every built-in profile, beside the exhaustive model check (model_check.hpp):
// random control words, fault causes and classes, STO, DC-link loss, lost connections, standstill
// and brake feedback, option writes and power cycles. After every step the safety invariants of
// docs/semantics.md S4, S11..S14 must hold, and every transition follows its seed's arrow. What the
// model check does not cover is here: option writes and power cycles in the middle of a run. The
// runs are seeded (std::mt19937), so a failure repeats exactly; the message gives profile, seed and
// step.
#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace cia402 {
namespace {

using S = state;

constexpr int steps_per_profile = 200000;

// The arrow every seed draws for each transition number (all five agree; seed 001 numbers the states
// 1..9, T7 "4 -> 3" is READY TO SWITCH ON -> SWITCH ON DISABLED, T15 "9 -> 3" FAULT -> SWITCH ON
// DISABLED). T13 leaves any state but FRA and FAULT; T17 (seed 004) leaves OE or QSA.
bool seed_arrow(std::uint8_t t, state from, state to) {
  switch (t) {
    case 0: return from == S::start && to == S::not_ready_to_switch_on;
    case 1: return from == S::not_ready_to_switch_on && to == S::switch_on_disabled;
    case 2: return from == S::switch_on_disabled && to == S::ready_to_switch_on;
    case 3: return from == S::ready_to_switch_on && to == S::switched_on;
    case 4: return from == S::switched_on && to == S::operation_enabled;
    case 5: return from == S::operation_enabled && to == S::switched_on;
    case 6: return from == S::switched_on && to == S::ready_to_switch_on;
    case 7: return from == S::ready_to_switch_on && to == S::switch_on_disabled;
    case 8: return from == S::operation_enabled && to == S::ready_to_switch_on;
    case 9: return from == S::operation_enabled && to == S::switch_on_disabled;
    case 10: return from == S::switched_on && to == S::switch_on_disabled;
    case 11: return from == S::operation_enabled && to == S::quick_stop_active;
    case 12: return from == S::quick_stop_active && to == S::switch_on_disabled;
    case 13:
      return from != S::start && from != S::fault_reaction_active && from != S::fault &&
             to == S::fault_reaction_active;
    case 14: return from == S::fault_reaction_active && to == S::fault;
    case 15: return from == S::fault && to == S::switch_on_disabled;
    case 16: return from == S::quick_stop_active && to == S::operation_enabled;
    case 17:
      return (from == S::operation_enabled || from == S::quick_stop_active) &&
             to == S::switch_on_disabled;
    default: return false;
  }
}

const std::uint16_t option_indices[] = {0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007, 0x6040};
const std::uint16_t fault_codes[] = {0x2310, 0x3210, 0x4310, 0x5530, 0x8611, 0xFF10, 0x1000};

// What the test knows about a step besides its inputs and outputs.
struct step_facts {
  state prev_state = S::start;
  bool fault = false;         ///< a fault must act this step (cause, STO/undervoltage with torque, 6007=1)
  bool class_1 = false;       ///< lexium32: an error of class 1 is present
  bool class_4_seen = false;  ///< lexium32: a class-4 error was seen since the last power cycle
};

// The safety invariants; returns the broken ones.
std::vector<std::string> broken_invariants(const profile& p, const step_facts& f,
                                           const drive_inputs& in, const drive_outputs& out) {
  std::vector<std::string> broken;
  auto check = [&](bool ok, const char* what) {
    if (!ok) broken.emplace_back(what);
  };
  const state s = out.current;
  const state from = f.prev_state;
  check(!out.torque || p.torque_allowed(s), "torque in a state without torque (S12)");
  check(!(out.torque && in.sto), "torque while STO is active (S14)");
  check(!out.brake_released || out.torque, "brake released without torque (S12)");
  check((out.status_word & status_bit::state_bits) == p.status_pattern(s),
        "status bits 0..3, 5, 6 do not show the state (S11)");
  check(static_cast<bool>(out.status_word & status_bit::voltage_enabled) == in.dc_link,
        "status bit 4 is not the DC-link voltage (S11)");
  check(static_cast<bool>(out.status_word & status_bit::remote) == in.remote,
        "status bit 9 is not remote (S11)");
  check(!((in.status_bits & status_bit::warning) || in.sto) || (out.status_word & status_bit::warning),
        "a warning (or STO, S14) without status bit 7");
  check((out.status_word & status_bit::mode_specific) ==
            (in.status_bits & status_bit::mode_specific),
        "status bits 8, 12..15 not passed through");
  check(static_cast<bool>(out.status_word & status_bit::internal_limit_active) ==
            static_cast<bool>(in.status_bits & status_bit::internal_limit_active),
        "status bit 11 not passed through");
  check(!(f.fault && from != S::start && from != S::fault_reaction_active && from != S::fault) ||
            (s == S::fault_reaction_active && out.transition == 13),
        "a fault cause did not take T13 to FAULT REACTION ACTIVE (faults win, S4)");
  check(!(f.fault && from == S::fault_reaction_active) ||
            s == S::fault_reaction_active || s == S::fault,
        "a fault cause in FAULT REACTION ACTIVE went elsewhere than FAULT");
  check(!(f.fault && from == S::fault) || s == S::fault,
        "left FAULT while a fault cause is present (S2)");
  check(!(f.class_1 && !f.fault && from == S::operation_enabled) || s == S::quick_stop_active,
        "an error of class 1 in OPERATION ENABLED did not quick-stop (seed 001 T11)");
  check(!(f.class_4_seen && from == S::fault) || s == S::fault,
        "left FAULT after a class-4 error without a power cycle");
  if (out.transition == no_transition) {
    check(s == from, "the state changed without a transition number");
  } else {
    const std::vector<int> seed = test::seed_transitions(p);
    check(std::find(seed.begin(), seed.end(), out.transition) != seed.end(),
          "a transition number the seed does not print");
    check(seed_arrow(out.transition, from, s), "the transition number does not match the seed's arrow");
  }
  check(!((s == S::fault_reaction_active || s == S::fault) && out.error_code == 0),
        "FAULT REACTION ACTIVE / FAULT without an error code (0x603F)");
  check(static_cast<bool>(out.error_register & 0x01) == (out.error_code != 0),
        "error register bit 0 does not follow 0x603F");
  return broken;
}

struct random_run {
  const profile& p;
  std::mt19937 rng;
  axis a;
  drive_inputs in;
  drive_outputs prev{};
  state prev_state = S::start;
  bool class_4_seen = false;  // lexium32: only a power cycle clears a class-4 error
  int fault_left = 0;         // steps the present fault cause lasts
  int hold_cw = 0;            // steps the present control word lasts
  long step_no = 0;
  std::array<long, 18> transitions_seen{};
  std::array<long, state_count> states_seen{};
  long option_writes = 0, option_refusals = 0;
  long violations = 0;
  std::string report;

  random_run(const profile& prof, std::uint32_t seed) : p(prof), rng(seed), a(make_axis(prof)) {}

  int roll(int n) { return static_cast<int>(rng() % static_cast<std::uint32_t>(n)); }
  bool chance(int per_mille) { return roll(1000) < per_mille; }

  // Each kind of violation is counted; the first example of each is kept with full context.
  std::map<std::string, long> kinds;
  void violation(const std::string& what) {
    ++violations;
    if (kinds[what]++ > 0 || kinds.size() > 8) return;
    std::ostringstream os;
    os << "  step " << step_no << " from " << state_name(prev_state) << " (prev "
       << test::describe(prev) << ")\n    inputs cw=" << test::hex(in.control_word)
       << " fault=" << test::hex(in.fault_code) << " class=" << int(in.fault_class)
       << " dc_link=" << in.dc_link << " sto=" << in.sto << " standstill=" << in.standstill
       << " brake_engaged=" << in.brake_engaged << " remote=" << in.remote
       << " lost=" << in.connection_lost << " 6007=" << abort_connection_code()
       << " speed=" << in.actual_speed_rpm << "\n    got " << test::describe(prev_out_now)
       << "\n    violates: " << what << "\n";
    report += os.str();
  }
  std::string summary() const {
    std::ostringstream os;
    for (const auto& k : kinds) os << "  " << k.second << " x " << k.first << "\n";
    return os.str();
  }
  drive_outputs prev_out_now{};

  void next_inputs() {
    const auto w = test::words_for(p);
    if (hold_cw-- <= 0) {
      hold_cw = roll(6);
      if (chance(750)) {
        const std::uint16_t cmds[] = {w.disable_voltage, w.quick_stop, w.shutdown, w.switch_on,
                                      w.enable_operation, w.enable_operation, w.enable_operation};
        std::uint16_t cw = cmds[roll(7)];
        if (chance(150)) cw |= control_bit::fault_reset;
        if (chance(150)) cw |= control_bit::halt;
        if (chance(100)) cw ^= 0x0004;  // seed 004's T17 and the plain quick stop
        in.control_word = cw;
      } else {
        in.control_word = static_cast<std::uint16_t>(rng());
      }
    }
    if (fault_left > 0) {
      if (--fault_left == 0) in.fault_code = 0;
    } else if (chance(8)) {
      in.fault_code = fault_codes[roll(7)];
      in.fault_class = static_cast<std::uint8_t>(roll(5));
      fault_left = 1 + roll(20);
    }
    if (chance(4)) in.sto = !in.sto;
    if (chance(4)) in.dc_link = !in.dc_link;
    if (chance(3)) in.connection_lost = !in.connection_lost;
    if (chance(3)) in.remote = !in.remote;
    if (!in.remote && chance(100)) in.remote = true;
    if (chance(300)) in.standstill = chance(600);
    if (chance(300)) in.brake_engaged = in.standstill ? chance(800) : chance(100);
    if (chance(20)) {
      const std::int32_t speeds[] = {0, 0, 0, 500, 999, 1000, 1001, 1500, -999, -1001};
      in.actual_speed_rpm = speeds[roll(10)];
    }
    if (chance(10)) in.local_enable = !in.local_enable;
    if (chance(10)) in.local_disable = !in.local_disable;
    const bool warning = chance(20), target_reached = chance(300), internal_limit = chance(20);
    // The mode bits random, the drive's own bits too: they must not reach the status word.
    in.status_bits = static_cast<std::uint16_t>(
        (rng() & ~unsigned{status_bit::reported & ~status_bit::mode_specific}) |
        (warning ? status_bit::warning : 0u) | (target_reached ? status_bit::target_reached : 0u) |
        (internal_limit ? status_bit::internal_limit_active : 0u));
  }

  void maybe_write_option() {
    if (!chance(10)) return;
    const std::uint16_t index = option_indices[roll(7)];
    const std::int32_t value = roll(24) - 3;
    const axis before = a;
    ++option_writes;
    const sdo_abort r = write_option(p, a, index, value);
    if (r != sdo_abort::none) {
      ++option_refusals;
      if (!test::same_bytes(a, before)) {
        violation("a refused write of " + std::to_string(value) + " to " + test::hex(index) +
                  " changed the axis");
      }
    } else {
      std::int32_t back = -999;
      if (read_option(p, a, index, back) != sdo_abort::none || back != value) {
        violation("an accepted write of " + std::to_string(value) + " to " + test::hex(index) +
                  " does not read back");
      }
    }
  }

  int abort_connection_code() const {
    std::int32_t v = 0;
    if (read_option(p, a, 0x6007, v) == sdo_abort::none) return v;
    return p.spec(option::abort_connection).default_value;
  }

  void one_step() {
    ++step_no;
    next_inputs();
    maybe_write_option();
    if (chance(1) && roll(10) == 0) {  // power cycle
      a = make_axis(p);
      prev = drive_outputs{};
      prev_state = S::start;
      class_4_seen = false;
    }
    // What must count as a fault this step, from the inputs alone (S4, S10, S13, S14).
    const bool classes = p.error_classes;
    const bool cause = in.fault_code != 0 && (!classes || in.fault_class >= 2);
    const bool class_1 = classes && in.fault_code != 0 && in.fault_class == 1;
    const bool sto_fault = prev.torque && in.sto;
    const bool voltage_fault = prev.torque && !in.dc_link;
    const bool lost_fault = in.connection_lost && abort_connection_code() == 1;
    const bool fault = cause || sto_fault || voltage_fault || lost_fault;
    if (classes && in.fault_code != 0 && in.fault_class == 4) class_4_seen = true;

    axis full_axis = a;  // the same cycle without the quiet fast path must agree exactly
    const drive_outputs out = step(p, a, in);
    prev_out_now = out;
    const drive_outputs full = detail::full_step(p, full_axis, in);
    if (!test::same_outputs(out, full) || !test::same_bytes(a, full_axis)) {
      violation("the quiet cycle differs from the full step: " + test::describe(full));
    }
    step_facts f;
    f.prev_state = prev_state;
    f.fault = fault;
    f.class_1 = class_1;
    f.class_4_seen = class_4_seen;
    for (const std::string& what : broken_invariants(p, f, in, out)) violation(what);
    if (out.transition < transitions_seen.size()) ++transitions_seen[out.transition];
    const state s = out.current;
    ++states_seen[static_cast<int>(s)];
    prev = out;
    prev_state = s;
  }
};

void run_profile(const char* name, std::uint32_t seed) {
  const profile& p = test::builtin(name);
  random_run run(p, seed);
  for (int i = 0; i < steps_per_profile; ++i) run.one_step();
  EXPECT_EQ(run.violations, 0) << name << " seed " << seed << ": " << run.violations
                               << " violations:\n"
                               << run.summary() << "the first of each kind:\n"
                               << run.report;
  // The run must have gone everywhere the seed goes, or it proves little.
  for (int t : test::seed_transitions(p)) {
    EXPECT_GT(run.transitions_seen[static_cast<std::size_t>(t)], 0)
        << name << ": the random run never took T" << t;
  }
  EXPECT_GT(run.option_refusals, 100) << name;
  bool has_objects = false;
  for (int o = 0; o < option_count; ++o) has_objects = has_objects || p.options[o].exists();
  if (has_objects) {
    EXPECT_GT(run.option_writes - run.option_refusals, 100) << name;
  }
}

// 002_522d2c0bb8f5a5f8.txt
TEST(safety, cia402_random_run_keeps_every_invariant) { run_profile("cia402", 0xC1A402u); }
// 000_44b471b7401b86be.txt
TEST(safety, no_quick_stop_random_run_keeps_every_invariant) {
  run_profile("no-quick-stop", 0x44B471B7u);
}
// 001_f9323c8e43dc977c.txt
TEST(safety, lexium32_random_run_keeps_every_invariant) { run_profile("lexium32", 0xF9323C8Eu); }
// 003_83442f2f4b0b2bb9.txt
TEST(safety, s300_profibus_random_run_keeps_every_invariant) {
  run_profile("s300-profibus", 0x83442F2Fu);
}
// 004_e07fd68605b3a8c6.txt
TEST(safety, ax2000_profibus_random_run_keeps_every_invariant) {
  run_profile("ax2000-profibus", 0xE07FD686u);
}

// The checker must be able to fail: hand it outputs that break each rule and see it complain.
TEST(safety, checker_reports_each_broken_invariant) {
  const profile& p = standard_profile();
  drive_inputs in;
  step_facts f;
  f.prev_state = S::switched_on;
  drive_outputs good;
  good.current = S::switched_on;
  good.status_word = 0x0233;
  EXPECT_TRUE(broken_invariants(p, f, in, good).empty());

  auto complains = [&](drive_outputs out, const drive_inputs& i, const step_facts& facts,
                       const char* about) {
    for (const std::string& b : broken_invariants(p, facts, i, out)) {
      if (b.find(about) != std::string::npos) return true;
    }
    return false;
  };
  drive_outputs o = good;
  o.torque = true;
  o.brake_released = true;
  EXPECT_TRUE(complains(o, in, f, "torque in a state without torque"));
  o = good;
  o.brake_released = true;
  EXPECT_TRUE(complains(o, in, f, "brake released without torque"));
  o = good;
  o.status_word = 0x0237;
  EXPECT_TRUE(complains(o, in, f, "do not show the state"));
  drive_inputs sto = in;
  sto.sto = true;
  o = good;
  o.current = S::operation_enabled;
  o.status_word = 0x02B7;
  o.torque = true;
  o.transition = 4;
  EXPECT_TRUE(complains(o, sto, f, "STO"));
  step_facts faulty = f;
  faulty.fault = true;
  EXPECT_TRUE(complains(good, in, faulty, "faults win"));
  o = good;
  o.transition = 6;
  EXPECT_TRUE(complains(o, in, f, "arrow"));
}

}  // namespace
}  // namespace cia402
