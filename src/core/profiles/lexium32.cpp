// Profile `lexium32`: the Lexium-32-style table of seed 001_f9323c8e43dc977c.txt (states 1..9,
// error classes, conditions on T2 and T7, T16 by Fault Reset or Enable Operation).
// docs/profiles/lexium32.md cites each row.
#include "profiles/builtin.hpp"
#include "profiles/rows.hpp"

namespace cia402::detail {
namespace {

// First match wins. T13 (error classes 2..4) first; T7 before T3 so that an undervoltage, STO or
// overspeed in READY TO SWITCH ON drops to SWITCH ON DISABLED even while Switch on is commanded.
constexpr transition_row rows[] = {
    t13_fault(),
    t0_power_on,
    t1_initialised,
    // T2: no undervoltage, actual velocity < 1000 rpm, STO = +24 V, Shutdown (seed lines 6..10).
    row(2, from(S::switch_on_disabled), S::ready_to_switch_on, facts(F::shutdown),
        facts(F::dc_link, F::below_speed_limit), facts(F::sto)),
    // T7: undervoltage, STO = 0 V, actual velocity > 1000 rpm, or Disable Voltage (seed lines 22..26).
    row(7, from(S::ready_to_switch_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::undervoltage, F::sto, F::overspeed)),
    // T3: local request or Switch On or Enable Operation (seed lines 11..13).
    // S15: a local disable request wins over any enable.
    row(3, from(S::ready_to_switch_on), S::switched_on,
        facts(F::switch_on, F::enable_operation, F::local_enable), facts(F::dc_link),
        facts(F::sto, F::local_disable)),
    // T4: automatic after a local enable, or Enable Operation (seed lines 14..17).
    row(4, from(S::switched_on), S::operation_enabled, facts(F::enable_operation, F::local_enable),
        facts(F::dc_link), facts(F::sto, F::local_disable)),
    // T5: "Movement is canceled with Halt", brake applied, power stage disabled (seed lines 18..20):
    // the halt ramp (0x605D), and the cancelled movement's set-points are dropped.
    row(5, from(S::operation_enabled), S::switched_on, facts(F::switch_on), {}, {},
        row_stop::halt_ramp, clears),
    // S14: under STO, SWITCHED ON goes to SWITCH ON DISABLED (T10), whatever the command.
    row(6, from(S::switched_on), S::ready_to_switch_on, facts(F::shutdown), {}, facts(F::sto)),
    // T8: Halt or immediate, by DSM_ShutDownOption, here 0x605B (seed lines 27..29).
    row(8, from(S::operation_enabled), S::ready_to_switch_on, facts(F::shutdown), {}, {},
        row_stop::shutdown_option_halt, clears),
    // T9: Disable Voltage disables at once; a local request follows DSM_ShutDownOption (lines 30..36).
    row(9, from(S::operation_enabled), S::switch_on_disabled, facts(F::disable_voltage), {}, {},
        row_stop::immediate, interrupts | clears),
    row(9, from(S::operation_enabled), S::switch_on_disabled, facts(F::local_disable), {}, {},
        row_stop::shutdown_option_halt, interrupts | clears),
    // S14: STO acts as a local Disable voltage.
    row(10, from(S::switched_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::local_disable, F::sto)),
    // T11: error class 1 or Quick Stop (seed lines 39..40).
    row(11, from(S::operation_enabled), S::quick_stop_active,
        facts(F::quick_stop, F::fault_quick_stop), {}, {}, row_stop::immediate, interrupts | clears),
    // T12: "disabled immediately, even if Quick Stop is still active" (seed lines 41..43).
    row(12, from(S::quick_stop_active), S::switch_on_disabled,
        facts(F::disable_voltage, F::local_disable)),
    // T14: error response terminated (class 2), at once for classes 3 and 4 (seed lines 46..47).
    t14_reaction_done,
    // T15: Fault Reset once the cause is corrected; class 4 needs a power cycle (eSM table).
    row(15, from(S::fault), S::switch_on_disabled, facts(F::fault_reset), {},
        facts(F::fault_present, F::fault_latched)),
    // T16: Enable Operation, or Fault Reset after a quick stop caused by a class-1 error (lines 50..54).
    // Enable Operation leaves only a quick stop the fieldbus asked for (footnote 3, line 57): a
    // class-1 error needs its Fault Reset.
    row(16, from(S::quick_stop_active), S::operation_enabled, facts(F::enable_operation), {},
        facts(F::entered_by_fault)),
    row(16, from(S::quick_stop_active), S::operation_enabled, facts(F::fault_reset),
        facts(F::entered_by_fault), facts(F::fault_present)),
};

constexpr std::array<option_spec, option_count> options = {{
    {values(6, 7), 6},       // 0x605A: quick stop holds in QUICK STOP ACTIVE (no automatic T12)
    {value_range(0, 1), 1},  // 0x605B: DSM_ShutDownOption (T8, local T9)
    {0, 1},                  // 0x605C: T5 always halts first, not an object here
    {values(1, 3), 1},       // 0x605D: deceleration ramp or torque ramp
    {0, 2},                  // 0x605E: the error class decides; class 2 stops on the quick-stop ramp
    {value_range(0, 3), 1},  // 0x6007
}};

constexpr profile make() noexcept {
  profile p = make_profile("lexium32", "001_f9323c8e43dc977c.txt",
                           "Lexium-32-style: error classes, T2/T7 conditions, T16 by Fault Reset",
                           standard_decoder, stored_rows<rows>, standard_states(state_activity::idle), options);
  p.speed_limit_rpm = 1000;
  p.error_classes = true;
  return p;
}

constexpr profile base = make();

}  // namespace

const profile lexium32_profile = with_ordinary_cycles<base>();

}  // namespace cia402::detail
