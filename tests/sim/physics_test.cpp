// Physics of the virtual drive, checked against the rules the issue states, written from the plant's
// documentation (include/cia402/sim/plant.hpp) and semantics.md S5, S7, S8, S12..S14 rather than
// from the simulator's code: a stop from v at deceleration d reaches standstill within v/d plus one
// cycle (and not sooner than v/d); a ramped stop engages the brake before torque goes off; a coast
// removes torque at once; motion waits for the brake to release.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "cia402/sim/virtual_drive.hpp"
#include "sim_support.hpp"

namespace {

using namespace sim_test;

plant_config exact_plant(std::uint32_t cycle_us) {
  plant_config c;
  c.cycle_us = cycle_us;
  c.standstill_window_rpm = 0;  // standstill means exactly 0, so stop times are exact
  c.current_limit_percent = 150;
  c.voltage_limit_percent = 80;
  return c;
}

// The deceleration (rpm/s) each 0x605A code stops at, from S5 and the plant's documentation:
// 1/5 slow-down ramp 0x6084, 2/6 quick-stop ramp 0x6085, 3/7 current limit (a percentage of
// 0x6085), 4/8 voltage limit (a percentage of 0x6084).
std::uint64_t oracle_rate(int code, std::uint32_t dec, std::uint32_t qs, const plant_config& c) {
  switch ((code - 1) % 4) {
    case 0: return dec;
    case 1: return qs;
    case 2: return std::uint64_t{qs} * c.current_limit_percent / 100;
    default: return std::uint64_t{dec} * c.voltage_limit_percent / 100;
  }
}

struct stop_case {
  int code;
  std::uint32_t cycle_us;
};

void PrintTo(const stop_case& c, std::ostream* os) {
  *os << "0x605A=" << c.code << ", cycle " << c.cycle_us << " us";
}

class quick_stop_time : public ::testing::TestWithParam<stop_case> {};

TEST_P(quick_stop_time, standstill_within_speed_over_deceleration_plus_one_cycle_and_not_sooner) {
  const stop_case c = GetParam();
  const plant_config plant = exact_plant(c.cycle_us);
  virtual_drive d(standard_profile(), plant);
  constexpr std::uint32_t dec = 3000;
  constexpr std::uint32_t qs = 7000;  // 1000 rpm / 7000 rpm/s = 142.857... ms: not a whole cycle
  ASSERT_EQ(d.write(0x605A, 0, c.code), sdo_abort::none);
  ASSERT_EQ(d.write(0x6083, 0, 20000), sdo_abort::none);
  ASSERT_EQ(d.write(0x6084, 0, dec), sdo_abort::none);
  ASSERT_EQ(d.write(0x6085, 0, qs), sdo_abort::none);
  run_at(d, 1000);

  ASSERT_EQ(d.write(0x6040, 0, 0x000B), sdo_abort::none);  // Quick stop
  const long cycles = step_until(d, [&](const drive_outputs&) {
    return d.view().velocity_micro_rpm() == 0;
  });
  ASSERT_GT(cycles, 0);
  const std::uint64_t rate = oracle_rate(c.code, dec, qs, plant);
  // cycles x cycle_us <= v/d + cycle_us and >= v/d, in integers (v/d in us = v * 1e6 / rate).
  const std::uint64_t spent = static_cast<std::uint64_t>(cycles) * c.cycle_us * rate;
  EXPECT_LE(spent, 1000ull * 1000000ull + std::uint64_t{c.cycle_us} * rate)
      << "code " << c.code << ": " << cycles << " cycles of " << c.cycle_us << " us";
  EXPECT_GE(spent, 1000ull * 1000000ull) << "code " << c.code << " stopped faster than its ramp";
}

std::vector<stop_case> stop_cases() {
  std::vector<stop_case> v;
  for (int code = 1; code <= 8; ++code) {
    for (std::uint32_t cycle : {250u, 1000u, 4000u}) v.push_back({code, cycle});
  }
  return v;
}

INSTANTIATE_TEST_SUITE_P(codes_1_to_8, quick_stop_time, ::testing::ValuesIn(stop_cases()),
                         [](const auto& info) {
                           return "code_" + std::to_string(info.param.code) + "_cycle_" +
                                  std::to_string(info.param.cycle_us) + "us";
                         });

// ------------------------------------------------------------------------------------------------
// A coast removes torque at once: in the very cycle the drive sees the cause, torque is off and the
// brake is commanded closed (S12, S13, S14, S5 code 0, S9 code 0).

struct coast_case {
  const char* name;
  void (*cause)(virtual_drive&);
};

void PrintTo(const coast_case& c, std::ostream* os) { *os << c.name; }

class coast : public ::testing::TestWithParam<coast_case> {};

TEST_P(coast, removes_torque_and_closes_the_brake_in_the_cycle_it_is_seen) {
  virtual_drive d(standard_profile());
  ASSERT_EQ(d.write(0x605E, 0, 0), sdo_abort::none);  // a fault reaction that coasts
  run_at(d, 1200);
  GetParam().cause(d);
  const drive_outputs out = d.step();
  EXPECT_FALSE(out.torque) << GetParam().name;
  EXPECT_FALSE(out.brake_released) << GetParam().name;
  EXPECT_TRUE(out.ramp == stop_ramp::coast || out.ramp == stop_ramp::none) << GetParam().name;
  // The shaft is not braked yet (engage delay): it coasts on friction only.
  const plant_config c;
  EXPECT_EQ(d.view().velocity_micro_rpm(), 1200 * micro - std::int64_t{c.coast_deceleration} * 1000);
}

INSTANTIATE_TEST_SUITE_P(
    causes, coast,
    ::testing::Values(
        coast_case{"quick_stop_code_0",
                   [](virtual_drive& d) {
                     ASSERT_EQ(d.write(0x605A, 0, 0), sdo_abort::none);
                     ASSERT_EQ(d.write(0x6040, 0, 0x000B), sdo_abort::none);
                   }},
        coast_case{"disable_voltage_t9",
                   [](virtual_drive& d) { ASSERT_EQ(d.write(0x6040, 0, 0x0000), sdo_abort::none); }},
        coast_case{"sto", [](virtual_drive& d) { d.view().set_sto(true); }},
        coast_case{"dc_link_lost", [](virtual_drive& d) { d.view().set_dc_link(false); }},
        coast_case{"fault_with_reaction_code_0",
                   [](virtual_drive& d) { d.view().inject_fault(0x2310); }},
        coast_case{"shutdown_with_0x605B_0",
                   [](virtual_drive& d) {
                     ASSERT_EQ(d.write(0x605B, 0, 0), sdo_abort::none);
                     ASSERT_EQ(d.write(0x6040, 0, 0x0006), sdo_abort::none);
                   }}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(coast, slows_on_friction_until_the_brake_engages_then_on_friction_and_brake) {
  plant_config c;
  c.coast_deceleration = 500;
  c.brake_deceleration = 9500;
  c.brake_engage_delay_us = 10000;
  virtual_drive d(standard_profile(), c);
  run_at(d, 1000);
  d.view().set_sto(true);
  for (int i = 0; i < 10; ++i) d.step();  // 10 cycles of friction alone: 0.5 rpm each
  EXPECT_EQ(d.view().velocity_micro_rpm(), 995 * micro);
  EXPECT_TRUE(d.view().brake_engaged());
  d.step();  // now the brake holds as well: 0.5 + 9.5 rpm per cycle
  EXPECT_EQ(d.view().velocity_micro_rpm(), 985 * micro);
}

// ------------------------------------------------------------------------------------------------
// Every ramped stop of every built-in profile engages the brake before torque goes off (S12).

struct ramped_stop {
  std::string what;
  std::uint16_t option_index = 0;
  int option_value = 0;
  enum class how { command, fault } trigger = how::command;
  command cmd = command::quick_stop;
};

std::vector<ramped_stop> ramped_stops_of(const profile& p) {
  std::vector<ramped_stop> stops;
  auto value_possible = [&](option o, int v) {
    const option_spec& s = p.spec(o);
    return s.exists() ? s.allows(v) : s.default_value == v;
  };
  for (int v = 1; v <= 8; ++v) {
    if (value_possible(option::quick_stop, v)) {
      stops.push_back({"quick stop 0x605A=" + std::to_string(v), 0x605A, v,
                       ramped_stop::how::command, command::quick_stop});
    }
  }
  if (value_possible(option::shutdown, 1)) {
    stops.push_back({"shutdown 0x605B=1", 0x605B, 1, ramped_stop::how::command, command::shutdown});
  }
  if (value_possible(option::disable_operation, 1)) {
    stops.push_back({"disable operation 0x605C=1", 0x605C, 1, ramped_stop::how::command,
                     command::switch_on});
  }
  for (int v = 1; v <= 4; ++v) {
    if (value_possible(option::fault_reaction, v)) {
      stops.push_back({"fault reaction 0x605E=" + std::to_string(v), 0x605E, v,
                       ramped_stop::how::fault, command::quick_stop});
    }
  }
  return stops;
}

TEST(ramped_stop, every_profile_engages_the_brake_before_torque_goes_off) {
  int checked = 0;
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    for (const ramped_stop& s : ramped_stops_of(p)) {
      SCOPED_TRACE(std::string(p.name) + ": " + s.what);
      plant_config c;
      c.brake_engage_delay_us = 25000;
      virtual_drive d(p, c);
      option o = option::quick_stop;
      ASSERT_TRUE(option_of_index(s.option_index, o));
      if (p.spec(o).exists()) {
        ASSERT_EQ(d.write(s.option_index, 0, s.option_value), sdo_abort::none);
      }
      ASSERT_EQ(d.write(0x6084, 0, 4000), sdo_abort::none);
      run_at(d, 800);
      if (s.trigger == ramped_stop::how::fault) {
        d.view().inject_fault(0x2310, 2);
      } else {
        ASSERT_EQ(d.write(0x6040, 0, word_for(p, s.cmd)), sdo_abort::none);
      }
      bool torque = true;
      long brake_closed_for = 0;  // cycles the drive has commanded the brake closed
      for (int k = 0; k < 5000 && torque; ++k) {
        const drive_inputs in = d.view().inputs();
        const drive_outputs out = d.step();
        if (!out.torque) {
          EXPECT_TRUE(in.standstill) << "torque off before standstill";
          EXPECT_TRUE(in.brake_engaged) << "torque off before the brake engaged";
          EXPECT_GE(brake_closed_for, 25) << "torque off before the engage delay passed";
          ++checked;
          torque = false;
        }
        brake_closed_for = out.brake_released ? 0 : brake_closed_for + 1;
      }
      // Stops that end holding torque (QUICK STOP ACTIVE 5..8, T5 into a holding SWITCHED ON)
      // never turn it off; they must keep the brake released.
      if (torque) EXPECT_TRUE(d.view().outputs().brake_released);
    }
  }
  std::printf("ramped stops that ended with torque off, over all built-in profiles: %d\n", checked);
  EXPECT_GE(checked, 12) << "too few stops ended with torque off to prove anything";
}

// ------------------------------------------------------------------------------------------------

class brake_release : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(brake_release, motion_waits_until_the_release_delay_has_passed) {
  plant_config c;
  c.brake_release_delay_us = GetParam();
  virtual_drive d(standard_profile(), c);
  command_for(d, 0x0006, 5);
  ASSERT_EQ(d.write(0x6040, 0, 0x000F), sdo_abort::none);
  ASSERT_GT(step_until(d, [](const drive_outputs& o) { return o.transition == 4; }, 10), 0);
  ASSERT_EQ(d.write(0x60FF, 0, 1000), sdo_abort::none);
  // The brake opens max(delay, one cycle) after T4; the cycle that first sees it open moves.
  // Sampled j cycles after T4: still at rest, the brake engaged until j = release_cycles.
  const long release_cycles = std::max<long>(1, (GetParam() + 999) / 1000);
  for (long j = 1; j <= release_cycles; ++j) {
    EXPECT_EQ(d.view().velocity_micro_rpm(), 0) << "moved " << j << " cycles after T4";
    EXPECT_EQ(d.view().brake_engaged(), j < release_cycles) << j << " cycles after T4";
    d.step();
  }
  EXPECT_GT(d.view().velocity_micro_rpm(), 0) << "the first cycle with the brake open moves";
}

INSTANTIATE_TEST_SUITE_P(delays, brake_release, ::testing::Values(0u, 1000u, 7000u, 7500u, 30000u, 100000u),
                         [](const auto& info) { return std::to_string(info.param) + "us"; });

TEST(brake, torque_stays_on_for_exactly_the_engage_delay_after_standstill) {
  for (std::uint32_t delay_ms : {1u, 15u, 40u}) {
    plant_config c;
    c.brake_engage_delay_us = delay_ms * 1000;
    virtual_drive d(standard_profile(), c);
    run_at(d, 600);
    ASSERT_EQ(d.write(0x6040, 0, 0x000B), sdo_abort::none);  // 0x605A = 2
    const long to_standstill = step_until(d, [&](const drive_outputs&) {
      return d.view().inputs().standstill;
    });
    ASSERT_GT(to_standstill, 0);
    const long to_t12 = step_until(d, [](const drive_outputs& o) { return o.transition == 12; });
    // The first step at standstill commands the brake closed; the delay later the drive sees it.
    EXPECT_EQ(to_t12, static_cast<long>(delay_ms) + 1) << delay_ms << " ms";
    EXPECT_FALSE(d.view().outputs().torque);
  }
}

TEST(brake, drive_without_brake_moves_at_once_and_ends_a_ramped_stop_at_standstill) {
  plant_config c;
  c.brake_fitted = false;
  virtual_drive d(standard_profile(), c);
  command_for(d, 0x0006, 5);
  ASSERT_EQ(d.write(0x6040, 0, 0x000F), sdo_abort::none);
  ASSERT_GT(step_until(d, [](const drive_outputs& o) { return o.transition == 4; }, 10), 0);
  ASSERT_EQ(d.write(0x60FF, 0, 300), sdo_abort::none);
  EXPECT_TRUE(d.view().inputs().brake_engaged);  // no brake reads as engaged
  d.step();
  EXPECT_GT(d.view().velocity_micro_rpm(), 0);  // no release delay to wait for
  ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().velocity_rpm() == 300; }), 0);
  ASSERT_EQ(d.write(0x6040, 0, 0x000B), sdo_abort::none);
  ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().inputs().standstill; }), 0);
  const drive_outputs out = d.step();  // the first cycle that sees standstill completes the stop
  EXPECT_EQ(out.transition, 12);
}

// ------------------------------------------------------------------------------------------------

TEST(halt, each_0x605D_code_ramps_at_its_rate_holds_at_zero_and_resumes) {
  for (int code = 1; code <= 4; ++code) {
    plant_config c = exact_plant(1000);
    virtual_drive d(standard_profile(), c);
    ASSERT_EQ(d.write(0x605D, 0, code), sdo_abort::none);
    ASSERT_EQ(d.write(0x6084, 0, 2000), sdo_abort::none);
    ASSERT_EQ(d.write(0x6085, 0, 5000), sdo_abort::none);
    run_at(d, 900);
    ASSERT_EQ(d.write(0x6040, 0, 0x010F), sdo_abort::none);
    const drive_outputs first = d.step();
    EXPECT_EQ(first.current, state::operation_enabled);
    EXPECT_TRUE(first.torque);
    const std::uint64_t rate = oracle_rate(code, 2000, 5000, c);
    EXPECT_EQ(d.view().velocity_micro_rpm(), 900 * micro - static_cast<std::int64_t>(rate) * 1000)
        << "code " << code;
    ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().velocity_micro_rpm() == 0; }), 0);
    for (int k = 0; k < 50; ++k) {
      const drive_outputs o = d.step();
      EXPECT_EQ(o.current, state::operation_enabled);
      EXPECT_TRUE(o.torque);
      EXPECT_TRUE(o.brake_released);
      EXPECT_EQ(d.view().velocity_micro_rpm(), 0);
    }
    EXPECT_TRUE(d.view().outputs().status_word & 0x0400) << "bit 10 at standstill after halt";
    ASSERT_EQ(d.write(0x6040, 0, 0x000F), sdo_abort::none);
    d.step();
    EXPECT_GT(d.view().velocity_micro_rpm(), 0) << "resumes at once: the brake stayed released";
  }
}

TEST(setpoints, t4_clears_them_so_the_motor_holds_zero_until_0x60FF_is_written_again) {
  virtual_drive d(standard_profile());
  ASSERT_EQ(d.write(0x60FF, 0, 1000), sdo_abort::none);  // written before the enable
  enable(d);
  for (int k = 0; k < 100; ++k) d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), 0);
  EXPECT_EQ(d.view().effective_target(), 0);
  std::int64_t v = 0;
  ASSERT_EQ(d.read(0x60FF, 0, v), sdo_abort::none);
  EXPECT_EQ(v, 1000);  // the object keeps its value; only the set-point is cleared
  ASSERT_EQ(d.write(0x60FF, 0, 1000), sdo_abort::none);
  d.step();
  EXPECT_GT(d.view().velocity_micro_rpm(), 0);
}

TEST(setpoints, ax2000_fast_stop_t11_clears_them_so_t16_returns_to_a_standing_motor) {
  // Seed 004_e07fd68605b3a8c6.txt T11: "Setpoints are canceled".
  const profile& p = *find_builtin_profile("ax2000-profibus");
  virtual_drive d(p);
  run_at(d, 500);
  ASSERT_EQ(d.write(0x6040, 0, word_for(p, command::quick_stop)), sdo_abort::none);
  const drive_outputs t11 = d.step();
  ASSERT_EQ(t11.transition, 11);
  ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().velocity_micro_rpm() == 0; }), 0);
  ASSERT_EQ(d.write(0x6040, 0, word_for(p, command::enable_operation)), sdo_abort::none);
  ASSERT_EQ(d.step().transition, 16);
  for (int k = 0; k < 50; ++k) d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), 0);
}

TEST(velocity, reversing_slows_on_0x6084_to_zero_then_speeds_up_on_0x6083) {
  virtual_drive d(standard_profile());
  ASSERT_EQ(d.write(0x6083, 0, 5000), sdo_abort::none);
  ASSERT_EQ(d.write(0x6084, 0, 2000), sdo_abort::none);
  run_at(d, 100);
  ASSERT_EQ(d.write(0x60FF, 0, -100), sdo_abort::none);
  d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), 98 * micro);  // 2 rpm per cycle down
  ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().velocity_micro_rpm() == 0; }), 0);
  d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), -5 * micro);  // 5 rpm per cycle up the other way
}

TEST(status, target_reached_only_within_the_window_and_internal_limit_while_braking_at_the_limit) {
  plant_config c;
  c.target_window_rpm = 5;
  virtual_drive d(standard_profile(), c);
  ASSERT_EQ(d.write(0x6083, 0, 1000), sdo_abort::none);  // 1 rpm per cycle
  enable(d);
  ASSERT_EQ(d.write(0x60FF, 0, 100), sdo_abort::none);
  ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().velocity_rpm() == 94; }), 0);
  EXPECT_FALSE(d.step().status_word & 0x0400);  // 94 rpm seen: 6 rpm off
  EXPECT_TRUE(d.step().status_word & 0x0400);   // 95 rpm seen: within 5 rpm
  ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().velocity_rpm() == 100; }), 0);
  ASSERT_EQ(d.write(0x605A, 0, 3), sdo_abort::none);
  ASSERT_EQ(d.write(0x6040, 0, 0x000B), sdo_abort::none);
  EXPECT_FALSE(d.step().status_word & 0x0800);  // the cycle the stop starts
  EXPECT_TRUE(d.step().status_word & 0x0800);   // braking at the current limit
  ASSERT_GT(step_until(d, [&](const drive_outputs&) { return d.view().inputs().standstill; }), 0);
  EXPECT_FALSE(d.step().status_word & 0x0800);
}

// ------------------------------------------------------------------------------------------------
// Faults injected at any time.

TEST(faults, a_fault_mid_quick_stop_takes_over_on_the_fault_reaction_ramp) {
  virtual_drive d(standard_profile());
  ASSERT_EQ(d.write(0x605A, 0, 6), sdo_abort::none);
  ASSERT_EQ(d.write(0x605E, 0, 1), sdo_abort::none);  // fault reaction on the slow-down ramp
  ASSERT_EQ(d.write(0x6084, 0, 2000), sdo_abort::none);
  ASSERT_EQ(d.write(0x6085, 0, 10000), sdo_abort::none);
  run_at(d, 1000);
  ASSERT_EQ(d.write(0x6040, 0, 0x000B), sdo_abort::none);
  for (int k = 0; k < 20; ++k) d.step();
  EXPECT_EQ(d.view().velocity_micro_rpm(), 800 * micro);  // 10 rpm per cycle
  d.view().inject_fault(0x2310);
  const drive_outputs t13 = d.step();
  EXPECT_EQ(t13.transition, 13);
  EXPECT_EQ(t13.current, state::fault_reaction_active);
  EXPECT_TRUE(t13.torque);
  EXPECT_EQ(d.view().velocity_micro_rpm(), 798 * micro);  // now 2 rpm per cycle
}

TEST(faults, a_second_fault_during_the_fault_reaction_is_recorded_without_a_transition) {
  virtual_drive d(standard_profile());
  run_at(d, 1000);
  d.view().inject_fault(0x2310);
  ASSERT_EQ(d.step().transition, 13);
  d.step();
  d.view().inject_fault(0x4310);
  const drive_outputs o = d.step();
  EXPECT_EQ(o.transition, no_transition);
  EXPECT_EQ(o.current, state::fault_reaction_active);
  EXPECT_EQ(o.error_code, 0x4310);
  std::int64_t reg = 0;
  ASSERT_EQ(d.read(0x1001, 0, reg), sdo_abort::none);
  EXPECT_EQ(reg, 0x09);  // generic + temperature
}

TEST(faults, reset_is_refused_while_a_cause_is_present_and_taken_after_clearing) {
  virtual_drive d(standard_profile());
  enable(d);
  d.view().inject_fault(0x2310);
  d.view().inject_fault(0x5000);
  ASSERT_GT(step_until(d, [](const drive_outputs& o) { return o.current == state::fault; }, 100), 0);
  command_for(d, 0x008F, 3);
  EXPECT_EQ(d.view().current(), state::fault);
  EXPECT_TRUE(d.view().clear_fault(0x5000));
  EXPECT_EQ(d.view().fault_cause(), 0x2310);
  command_for(d, 0x000F, 1);
  command_for(d, 0x008F, 1);
  EXPECT_EQ(d.view().current(), state::fault) << "0x2310 is still present";
  d.view().clear_faults();
  command_for(d, 0x000F, 1);
  command_for(d, 0x008F, 1);
  EXPECT_EQ(d.view().current(), state::switch_on_disabled);
  EXPECT_EQ(d.view().outputs().transition, 15);
}

TEST(faults, at_most_four_causes_are_kept_and_the_newest_is_the_one_seen) {
  virtual_drive d(standard_profile());
  drive_view v = d.view();
  EXPECT_FALSE(v.inject_fault(0));
  for (std::uint16_t code : {0x1000, 0x2000, 0x3000, 0x4000}) EXPECT_TRUE(v.inject_fault(code));
  EXPECT_FALSE(v.inject_fault(0x5000));  // drops 0x1000
  EXPECT_FALSE(v.clear_fault(0x1000));
  EXPECT_EQ(v.fault_cause(), 0x5000);
  EXPECT_TRUE(v.inject_fault(0x2000));  // raised again: newest, still four
  EXPECT_EQ(v.fault_cause(), 0x2000);
  EXPECT_TRUE(v.clear_fault(0x2000));
  EXPECT_EQ(v.fault_cause(), 0x5000);
}

TEST(faults, lexium32_class_1_cause_quick_stops_instead_of_faulting) {
  // Seed 001_f9323c8e43dc977c.txt T11: "Error of error class 1" -> Quick Stop.
  const profile& p = *find_builtin_profile("lexium32");
  virtual_drive d(p);
  run_at(d, 500);
  d.view().inject_fault(0x2310, 1);
  const drive_outputs o = d.step();
  EXPECT_EQ(o.current, state::quick_stop_active);
  EXPECT_TRUE(o.status_word & 0x0080) << "class 1 shows as a warning";
}

TEST(connection, lost_with_0x6007_1_faults_and_with_3_quick_stops) {
  {
    virtual_drive d(standard_profile());
    run_at(d, 500);
    d.view().set_connection_lost(true);
    const drive_outputs o = d.step();
    EXPECT_EQ(o.transition, 13);
    EXPECT_EQ(o.error_code, 0x8130);
  }
  {
    virtual_drive d(standard_profile());
    ASSERT_EQ(d.write(0x6007, 0, 3), sdo_abort::none);
    run_at(d, 500);
    d.view().set_connection_lost(true);
    EXPECT_EQ(d.step().transition, 11);
  }
}

TEST(config, refused_configurations_throw_with_the_reason) {
  plant_config c;
  c.cycle_us = 0;
  EXPECT_NE(check_plant_config(c), nullptr);
  EXPECT_THROW({ virtual_drive refused(standard_profile(), c); }, std::invalid_argument);
  c = plant_config{};
  c.current_limit_percent = 0;
  EXPECT_NE(check_plant_config(c), nullptr);
  c = plant_config{};
  c.brake_engage_delay_us = 70000000;  // more than 65535 cycles of 1 ms
  EXPECT_NE(check_plant_config(c), nullptr);
  EXPECT_EQ(check_plant_config(plant_config{}), nullptr);
}

}  // namespace
