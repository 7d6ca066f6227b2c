// The option-code objects 0x605A, 0x605B, 0x605C, 0x605D, 0x605E and 0x6007 in every built-in
// profile: which values are accepted (semantics.md S5..S10 and cia402-reference.md §3), what each
// accepted value does, and that a refused write (SDO abort 0x06090030 or 0x06020000) changes nothing.
#include <climits>
#include <cstdint>
#include <vector>

#include "test_support.hpp"

namespace cia402 {
namespace {

using test::bench;
using test::words_for;
using S = state;

struct object {
  std::uint16_t index;
  option which;
  int lo, hi;  ///< the standard's defined (non-manufacturer, non-reserved) range
};

// cia402-reference.md §3; semantics.md S5 (605A 0..8), S7 (605B, 605C 0..1), S8 (605D 1..4),
// S9 (605E 0..4), S10 (6007 0..3).
const object objects[] = {
    {0x605A, option::quick_stop, 0, 8},        {0x605B, option::shutdown, 0, 1},
    {0x605C, option::disable_operation, 0, 1}, {0x605D, option::halt, 1, 4},
    {0x605E, option::fault_reaction, 0, 4},    {0x6007, option::abort_connection, 0, 3},
};

// Values written in the sweeps: everything an INT16 object can hold, and int32 extremes.
std::vector<std::int32_t> probe_values() {
  std::vector<std::int32_t> v;
  for (std::int32_t x = -32768; x <= 32767; ++x) v.push_back(x);
  for (std::int32_t x : {INT32_MIN, INT32_MIN + 1, -65536, -32769, 32768, 65535, 65536, 65543,
                         INT32_MAX - 1, INT32_MAX}) {
    v.push_back(x);
  }
  return v;
}

stop_ramp ramp_of(int code) {
  switch (code) {
    case 1: case 5: return stop_ramp::slow_down;
    case 2: case 6: return stop_ramp::quick_stop;
    case 3: case 7: return stop_ramp::current_limit;
    case 4: case 8: return stop_ramp::voltage_limit;
    default: return stop_ramp::coast;
  }
}

// ---------------------------------------------------------------------------------------------
// Which values are accepted.

TEST(option_codes, cia402_accepts_exactly_the_values_semantics_md_defines) {
  const profile& p = standard_profile();
  const std::vector<std::int32_t> values = probe_values();
  for (const object& o : objects) {
    long wrong = 0;
    for (std::int32_t v : values) {
      axis a = make_axis(p);
      const axis before = a;
      const sdo_abort r = write_option(p, a, o.index, v);
      const bool in_range = v >= o.lo && v <= o.hi;
      if (in_range) {
        std::int32_t back = -12345;
        if (r != sdo_abort::none || read_option(p, a, o.index, back) != sdo_abort::none ||
            back != v) {
          if (++wrong <= 5) ADD_FAILURE() << test::hex(o.index) << " = " << v << " refused or not read back";
        }
      } else if (r != sdo_abort::invalid_value || !test::same_bytes(a, before)) {
        if (++wrong <= 5) {
          ADD_FAILURE() << test::hex(o.index) << " = " << v << " gave abort "
                        << test::hex(static_cast<std::uint32_t>(r), 8)
                        << " (want 0x06090030) or changed the axis";
        }
      }
    }
    EXPECT_EQ(wrong, 0) << test::hex(o.index);
  }
}

TEST(option_codes, cia402_defaults_are_the_ones_semantics_md_names) {
  const profile& p = standard_profile();
  const axis a = make_axis(p);
  const std::pair<std::uint16_t, std::int32_t> defaults[] = {
      {0x605A, 2}, {0x605B, 1}, {0x605C, 1}, {0x605D, 1}, {0x605E, 2}, {0x6007, 1}};
  for (const auto& d : defaults) {
    std::int32_t v = -1;
    EXPECT_EQ(read_option(p, a, d.first, v), sdo_abort::none) << test::hex(d.first);
    EXPECT_EQ(v, d.second) << test::hex(d.first);
  }
}

// Every profile: a missing object refuses every read and write with 0x06020000; an existing one
// accepts exactly the values its profile declares, which lie inside the standard's range; anything
// else gets 0x06090030. Every refusal leaves the axis byte for byte as it was.
TEST(option_codes, every_profile_accepts_only_declared_standard_values_and_refusals_change_nothing) {
  const std::vector<std::int32_t> values = probe_values();
  for (const profile* p : test::all_builtins()) {
    for (const object& o : objects) {
      SCOPED_TRACE(std::string(p->name) + " " + test::hex(o.index));
      const option_spec& spec = p->spec(o.which);
      for (int v = 0; v < 16; ++v) {
        if (spec.allows(v)) {
          EXPECT_TRUE(v >= o.lo && v <= o.hi) << "declares value " << v << " outside the standard's range";
        }
      }
      long wrong = 0;
      for (std::int32_t v : values) {
        axis a = make_axis(*p);
        a.current = S::operation_enabled;  // a running axis, not only a fresh one
        a.flags = axis_flag::torque_on;
        const axis before = a;
        const sdo_abort r = write_option(*p, a, o.index, v);
        sdo_abort want = sdo_abort::none;
        if (!spec.exists()) want = sdo_abort::object_does_not_exist;
        else if (!(v >= o.lo && v <= o.hi && spec.allows(v))) want = sdo_abort::invalid_value;
        const bool ok = r == want && (want == sdo_abort::none || test::same_bytes(a, before));
        if (!ok && ++wrong <= 5) {
          ADD_FAILURE() << "write " << v << ": abort " << test::hex(static_cast<std::uint32_t>(r), 8)
                        << ", want " << test::hex(static_cast<std::uint32_t>(want), 8)
                        << (test::same_bytes(a, before) ? "" : "; the axis changed");
        }
      }
      EXPECT_EQ(wrong, 0);
      std::int32_t v = 4711;
      const axis a = make_axis(*p);
      const sdo_abort r = read_option(*p, a, o.index, v);
      if (spec.exists()) {
        EXPECT_EQ(r, sdo_abort::none);
        EXPECT_TRUE(spec.allows(v)) << "default " << v << " is not a supported value";
      } else {
        EXPECT_EQ(r, sdo_abort::object_does_not_exist);
        EXPECT_EQ(v, 4711) << "a refused read must not touch the value";
      }
    }
  }
}

TEST(option_codes, indices_that_are_not_option_codes_do_not_exist_in_any_profile) {
  for (const profile* p : test::all_builtins()) {
    for (std::uint16_t index : {0x0000, 0x1001, 0x6040, 0x6041, 0x6059, 0x605F, 0x6006, 0x6008,
                                0x705A, 0xFFFF}) {
      axis a = make_axis(*p);
      const axis before = a;
      EXPECT_EQ(write_option(*p, a, index, 1), sdo_abort::object_does_not_exist)
          << p->name << " " << test::hex(index);
      EXPECT_TRUE(test::same_bytes(a, before));
      std::int32_t v = 99;
      EXPECT_EQ(read_option(*p, a, index, v), sdo_abort::object_does_not_exist);
      EXPECT_EQ(v, 99);
    }
  }
}

// What the seeds imply about which objects exist.
TEST(option_codes, seeds_decide_which_objects_exist) {
  // 000_44b471b7401b86be.txt: "'Quick Stop' is not supported": there is no quick stop option code.
  EXPECT_FALSE(test::builtin("no-quick-stop").spec(option::quick_stop).exists());
  // 001_f9323c8e43dc977c.txt: QUICK STOP ACTIVE is left only by T12 (Disable Voltage) or T16,
  // never by itself, so only the "stay" codes 5..8 fit; T8 "Halt or power stage immediately
  // disabled. Can be set via parameter DSM_ShutDownOption": both 605B values.
  const profile& lx = test::builtin("lexium32");
  ASSERT_TRUE(lx.spec(option::quick_stop).exists());
  for (int v = 0; v < 16; ++v) {
    if (lx.spec(option::quick_stop).allows(v)) {
      EXPECT_TRUE(v >= 5 && v <= 8) << v;
    }
  }
  EXPECT_TRUE(lx.spec(option::shutdown).allows(0));
  EXPECT_TRUE(lx.spec(option::shutdown).allows(1));
}

// ---------------------------------------------------------------------------------------------
// What each value does. For an object a profile lacks, its fixed value must behave the same way.

// The values to exercise for one object: every accepted one, or the fixed one if none.
std::vector<int> effective_values(const profile& p, option o) {
  std::vector<int> v;
  const option_spec& spec = p.spec(o);
  if (!spec.exists()) {
    v.push_back(spec.default_value);
  } else {
    for (int x = 0; x < 16; ++x) {
      if (spec.allows(x)) v.push_back(x);
    }
  }
  return v;
}

void set_option(bench& b, std::uint16_t index, option o, int v) {
  if (b.p.spec(o).exists()) {
    ASSERT_EQ(b.write(index, v), sdo_abort::none);
  }
}

bool has_quick_stop_active(const profile& p) {
  // 000_44b471b7401b86be.txt: Quick stop is not supported.
  return std::string(p.name) != "no-quick-stop";
}

// S5: 0 coasts and stays until Disable voltage (no T16); 1..4 ramp, close the brake at standstill,
// then T12 by themselves; 5..8 ramp, hold with bit 10 at standstill, T16 on Enable operation.
TEST(option_codes, quick_stop_code_every_value_behaves_as_s5) {
  for (const profile* p : test::all_builtins()) {
    if (!has_quick_stop_active(*p)) continue;
    for (int v : effective_values(*p, option::quick_stop)) {
      SCOPED_TRACE(std::string(p->name) + " 605A=" + std::to_string(v));
      bench b(*p);
      set_option(b, 0x605A, option::quick_stop, v);
      ASSERT_TRUE(test::reach(b, S::operation_enabled));
      const auto w = words_for(*p);
      b.in.standstill = false;
      b.in.brake_engaged = false;
      b.in.control_word = w.quick_stop;
      b.step();
      ASSERT_EQ(int(b.out.transition), 11);
      for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(b.out.current, S::quick_stop_active);
        EXPECT_FALSE(b.out.status_word & status_bit::target_reached) << "still moving";
        if (v == 0) {
          EXPECT_FALSE(b.out.torque);
          EXPECT_FALSE(b.out.brake_released);
          EXPECT_EQ(b.out.ramp, stop_ramp::coast);
        } else {
          EXPECT_TRUE(b.out.torque);
          EXPECT_TRUE(b.out.brake_released) << "the brake closes only at standstill";
          EXPECT_EQ(b.out.ramp, ramp_of(v));
        }
        b.step();
      }
      b.in.standstill = true;
      b.step();
      if (v == 0) {
        EXPECT_EQ(b.out.current, S::quick_stop_active) << "0 stays until Disable voltage";
        EXPECT_FALSE(b.out.status_word & status_bit::target_reached);
        b.in.control_word = w.enable_operation;
        EXPECT_EQ(int(b.step_until_transition(3)), no_transition) << "no T16 for 605A = 0";
        b.in.control_word = w.disable_voltage;
        EXPECT_EQ(int(b.step_until_transition(1)), 12);
      } else if (v <= 4) {
        EXPECT_EQ(b.out.current, S::quick_stop_active);
        EXPECT_TRUE(b.out.torque) << "the brake closes before torque goes (S12)";
        EXPECT_FALSE(b.out.brake_released);
        b.in.brake_engaged = true;
        EXPECT_EQ(int(b.step_until_transition(1)), 12) << "T12 by itself";
        EXPECT_EQ(b.out.current, S::switch_on_disabled);
        EXPECT_FALSE(b.out.torque);
      } else {
        b.in.brake_engaged = true;
        for (int i = 0; i < 3; ++i) {
          EXPECT_EQ(b.out.current, S::quick_stop_active) << "5..8 hold";
          EXPECT_TRUE(b.out.status_word & status_bit::target_reached) << "bit 10 at standstill";
          EXPECT_TRUE(b.out.torque);
          b.step();
        }
        b.in.control_word = w.enable_operation;
        EXPECT_EQ(int(b.step_until_transition(1)), 16);
        EXPECT_EQ(b.out.current, S::operation_enabled);
      }
    }
  }
}

// S7 for T8 (0x605B) and T5 (0x605C): 0 drive function off at once; 1 slow-down ramp, the state
// shows the source until the stop completes at standstill.
void check_shutdown_like(const profile& p, std::uint16_t index, option o, std::uint16_t command,
                         std::uint8_t number, state dest) {
  for (int v : effective_values(p, o)) {
    SCOPED_TRACE(std::string(p.name) + " " + test::hex(index) + "=" + std::to_string(v));
    bench b(p);
    set_option(b, index, o, v);
    ASSERT_TRUE(test::reach(b, S::operation_enabled));
    b.in.standstill = false;
    b.in.brake_engaged = false;
    b.in.control_word = command;
    b.step();
    if (v == 0) {
      EXPECT_EQ(int(b.out.transition), number) << "at once";
      EXPECT_EQ(b.out.current, dest);
      EXPECT_NE(b.out.ramp, stop_ramp::slow_down);
      EXPECT_FALSE(b.out.brake_released);
      if (dest != S::switched_on || !p.torque_allowed(S::switched_on)) {
        EXPECT_FALSE(b.out.torque);
      }
      continue;
    }
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(int(b.out.transition), no_transition) << "the stop runs first";
      EXPECT_EQ(b.out.current, S::operation_enabled);
      EXPECT_EQ(b.out.status_word & status_bit::state_bits, 0x0027) << "shows the source";
      EXPECT_EQ(b.out.ramp, stop_ramp::slow_down);
      EXPECT_TRUE(b.out.torque);
      b.step();
    }
    b.in.standstill = true;
    b.in.brake_engaged = true;
    EXPECT_EQ(int(b.step_until_transition(2)), number);
    EXPECT_EQ(b.out.current, dest);
  }
}

TEST(option_codes, shutdown_code_every_value_behaves_as_s7) {
  for (const profile* p : test::all_builtins()) {
    check_shutdown_like(*p, 0x605B, option::shutdown, words_for(*p).shutdown, 8,
                        S::ready_to_switch_on);
  }
}

TEST(option_codes, disable_operation_code_every_value_behaves_as_s7) {
  for (const profile* p : test::all_builtins()) {
    check_shutdown_like(*p, 0x605C, option::disable_operation, words_for(*p).switch_on, 5,
                        S::switched_on);
  }
}

// S8: halt (bit 8) picks the ramp by 0x605D; the state stays OPERATION ENABLED; bit 10 at
// standstill; clearing bit 8 resumes. Without the object (PROFIBUS: STW bit 8 is jog) bit 8 does
// nothing to the state machine.
TEST(option_codes, halt_code_every_value_behaves_as_s8) {
  for (const profile* p : test::all_builtins()) {
    const bool exists = p->spec(option::halt).exists();
    for (int v : effective_values(*p, option::halt)) {
      SCOPED_TRACE(std::string(p->name) + " 605D=" + std::to_string(v));
      bench b(*p);
      set_option(b, 0x605D, option::halt, v);
      ASSERT_TRUE(test::reach(b, S::operation_enabled));
      const std::uint16_t run = words_for(*p).enable_operation;
      b.in.standstill = false;
      b.in.brake_engaged = false;
      b.in.control_word = run | control_bit::halt;
      b.step();
      EXPECT_EQ(b.out.current, S::operation_enabled);
      EXPECT_EQ(int(b.out.transition), no_transition);
      EXPECT_TRUE(b.out.torque);
      EXPECT_TRUE(b.out.brake_released);
      EXPECT_FALSE(b.out.status_word & status_bit::target_reached) << "still moving";
      EXPECT_EQ(b.out.ramp, exists ? ramp_of(v) : stop_ramp::none);
      b.in.standstill = true;
      b.in.brake_engaged = true;
      b.step();
      EXPECT_EQ(b.out.current, S::operation_enabled);
      EXPECT_EQ(static_cast<bool>(b.out.status_word & status_bit::target_reached), exists)
          << "bit 10 at standstill after a halt";
      EXPECT_TRUE(b.out.torque) << "a halt holds with torque";
      b.in.control_word = run;
      b.step();
      EXPECT_EQ(b.out.current, S::operation_enabled);
      EXPECT_EQ(b.out.ramp, stop_ramp::none) << "clearing bit 8 resumes";
      EXPECT_FALSE(b.out.status_word & status_bit::target_reached);
    }
  }
}

// S9: 0x605E picks the fault reaction: 0 coasts (T14 at once), 1..4 ramp, then T14 at standstill.
TEST(option_codes, fault_reaction_code_every_value_behaves_as_s9) {
  for (const profile* p : test::all_builtins()) {
    for (int v : effective_values(*p, option::fault_reaction)) {
      SCOPED_TRACE(std::string(p->name) + " 605E=" + std::to_string(v));
      bench b(*p);
      set_option(b, 0x605E, option::fault_reaction, v);
      ASSERT_TRUE(test::reach(b, S::operation_enabled));
      b.in.standstill = false;
      b.in.brake_engaged = false;
      b.in.fault_code = 0x2310;
      b.in.fault_class = 2;
      b.step();
      ASSERT_EQ(int(b.out.transition), 13);
      EXPECT_EQ(b.out.error_code, 0x2310);
      if (v == 0) {
        EXPECT_FALSE(b.out.torque);
        EXPECT_FALSE(b.out.brake_released);
        EXPECT_EQ(b.out.ramp, stop_ramp::coast);
        EXPECT_EQ(int(b.step_until_transition(1)), 14) << "a coast is complete at once";
        continue;
      }
      for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(b.out.current, S::fault_reaction_active);
        EXPECT_TRUE(b.out.torque);
        EXPECT_EQ(b.out.ramp, ramp_of(v));
        b.step();
      }
      b.in.standstill = true;
      b.in.brake_engaged = true;
      EXPECT_EQ(int(b.step_until_transition(2)), 14);
      EXPECT_EQ(b.out.current, S::fault);
      EXPECT_FALSE(b.out.torque);
    }
  }
}

// S10: on a lost connection, 0 does nothing, 1 is a fault 0x8130, 2 is the Disable voltage command
// and 3 the Quick stop command: exactly what that command sent by the master would do.
TEST(option_codes, abort_connection_code_every_value_behaves_as_s10) {
  for (const profile* p : test::all_builtins()) {
    for (int v : effective_values(*p, option::abort_connection)) {
      SCOPED_TRACE(std::string(p->name) + " 6007=" + std::to_string(v));
      const auto w = words_for(*p);
      bench b(*p);
      set_option(b, 0x6007, option::abort_connection, v);
      ASSERT_TRUE(test::reach(b, S::operation_enabled));
      bench twin = b;  // the same axis, told by its master instead
      b.in.connection_lost = true;
      b.in.standstill = false;
      twin.in.standstill = false;
      if (v == 0) {
        b.step();
        EXPECT_EQ(b.out.current, S::operation_enabled);
        EXPECT_TRUE(b.out.torque);
        continue;
      }
      if (v == 1) {
        b.step();
        EXPECT_EQ(int(b.out.transition), 13);
        EXPECT_EQ(b.out.error_code, 0x8130);
        EXPECT_EQ(b.out.error_register, 0x11) << "generic + communication (CiA 301)";
        continue;
      }
      twin.in.control_word = v == 2 ? w.disable_voltage : w.quick_stop;
      for (int i = 0; i < 4; ++i) {
        if (i == 2) b.in.standstill = twin.in.standstill = true;
        b.step();
        twin.step();
        EXPECT_TRUE(test::same_outputs(b.out, twin.out))
            << "step " << i << ": lost connection " << test::describe(b.out) << " vs command "
            << test::describe(twin.out);
      }
      EXPECT_NE(b.a.current, S::operation_enabled);
    }
  }
}

// S10 with seed 001's error classes: an error of class 0 or 1 is only a warning or a quick stop; it
// must not hide a lost connection, which with 0x6007 = 1 is a fault of its own (T13, 0x8130).
TEST(option_codes, lexium32_lost_connection_faults_even_with_a_class_0_error_present) {
  bench b(test::builtin("lexium32"));
  ASSERT_TRUE(test::reach(b, S::switch_on_disabled));
  b.in.fault_code = 0x2310;
  b.in.fault_class = 0;
  b.in.connection_lost = true;
  b.step();
  EXPECT_EQ(int(b.out.transition), 13) << test::describe(b.out);
  EXPECT_EQ(b.out.current, S::fault_reaction_active);
  EXPECT_EQ(b.out.error_code, 0x8130);
}

// ---------------------------------------------------------------------------------------------
// A refused write changes nothing: byte for byte, and in everything the axis does afterwards.

std::vector<drive_inputs> afterwards_script(const profile& p) {
  const auto w = words_for(p);
  std::vector<drive_inputs> s;
  auto add = [&](std::uint16_t cw, bool standstill = true, std::uint16_t fault = 0,
                 bool lost = false) {
    drive_inputs in;
    in.control_word = cw;
    in.standstill = standstill;
    in.brake_engaged = standstill;
    in.fault_code = fault;
    in.connection_lost = lost;
    s.push_back(in);
  };
  add(w.enable_operation);
  add(w.enable_operation | control_bit::halt, false);
  add(w.enable_operation | control_bit::halt);
  add(w.quick_stop, false);
  add(w.quick_stop);
  add(w.quick_stop);
  add(w.enable_operation);
  add(w.shutdown, false);
  add(w.shutdown);
  add(w.switch_on);
  add(w.enable_operation);
  add(w.enable_operation);
  add(w.switch_on, false);
  add(w.switch_on);
  add(w.enable_operation);
  add(w.enable_operation, true, 0, true);
  add(w.enable_operation, false, 0x2310);
  add(w.enable_operation, true, 0x2310);
  add(w.enable_operation);
  add(w.enable_operation | control_bit::fault_reset);
  add(w.shutdown);
  return s;
}

TEST(option_codes, refused_write_leaves_axis_and_later_behaviour_unchanged) {
  const std::int32_t refused_candidates[] = {INT32_MIN, -32768, -129, -128, -2, -1, 0, 1, 2,
                                             3,         4,      5,    6,    7,  8,  9, 15, 16,
                                             127,       128,    255,  256,  32767, INT32_MAX};
  for (const profile* p : test::all_builtins()) {
    const std::vector<drive_inputs> script = afterwards_script(*p);
    // Axes in a few states, including one whose T8 stop is running.
    std::vector<axis> starts;
    for (state s : {S::switch_on_disabled, S::operation_enabled, S::quick_stop_active, S::fault}) {
      bench b(*p);
      if (s == S::quick_stop_active && !has_quick_stop_active(*p)) continue;
      ASSERT_TRUE(test::reach(b, s));
      starts.push_back(b.a);
      if (s == S::operation_enabled) {
        b.in.standstill = false;
        b.in.control_word = words_for(*p).shutdown;
        b.step();
        starts.push_back(b.a);
      }
    }
    int refusals = 0;
    for (const axis& start : starts) {
      for (const object& o : objects) {
        for (std::int32_t v : refused_candidates) {
          axis written = start;
          const sdo_abort r = write_option(*p, written, o.index, v);
          if (r == sdo_abort::none) continue;
          ++refusals;
          SCOPED_TRACE(std::string(p->name) + " from " + state_name(start.current) + " write " +
                       test::hex(o.index) + " = " + std::to_string(v));
          ASSERT_TRUE(test::same_bytes(written, start)) << "the refused write changed the axis";
          axis untouched = start;
          for (std::size_t i = 0; i < script.size(); ++i) {
            const drive_outputs x = step(*p, written, script[i]);
            const drive_outputs y = step(*p, untouched, script[i]);
            ASSERT_TRUE(test::same_outputs(x, y))
                << "step " << i << ": " << test::describe(x) << " vs " << test::describe(y);
          }
          EXPECT_TRUE(test::same_bytes(written, untouched));
        }
      }
    }
    EXPECT_GT(refusals, 0) << p->name;
  }
}

// The opposite check, so the comparison above can fail: an accepted write does change behaviour.
TEST(option_codes, accepted_write_of_a_different_value_changes_later_behaviour) {
  const profile& p = standard_profile();
  bench a(p), b(p);
  ASSERT_TRUE(test::reach(a, S::operation_enabled));
  ASSERT_TRUE(test::reach(b, S::operation_enabled));
  ASSERT_EQ(b.write(0x605B, 0), sdo_abort::none);
  a.in.control_word = b.in.control_word = 0x06;
  a.step();
  b.step();
  EXPECT_FALSE(test::same_outputs(a.out, b.out));
  EXPECT_EQ(a.out.current, S::operation_enabled) << "605B = 1 ramps first";
  EXPECT_EQ(b.out.current, S::ready_to_switch_on) << "605B = 0 at once";
}

}  // namespace
}  // namespace cia402
