// Profile `no-quick-stop`: the CANopen drive of seed 000_44b471b7401b86be.txt, which does not
// support Quick Stop (its footnote on T7, T10, T11, T12). docs/profiles/no-quick-stop.md cites each row.
#include "profiles/builtin.hpp"
#include "profiles/rows.hpp"

namespace cia402::detail {
namespace {

// First match wins; T13 first because faults win over any command. There is no T11, T12 or T16:
// QUICK STOP ACTIVE cannot be reached. A Quick stop command acts as Disable voltage wherever it acts:
// T7 and T10 as the seed says, and T9 by our choice, so the stop a master asks for is never ignored.
// This drive has no QUICK STOP ACTIVE, so "all states" of T13 (seed line 143) leaves it out.
constexpr std::uint16_t every_state_it_has_but_fault =
    every_state_but_fault & static_cast<std::uint16_t>(~state_bit(S::quick_stop_active));

constexpr transition_row rows[] = {
    t13_fault(every_state_it_has_but_fault),
    t0_power_on,
    t1_initialised,
    // S14: SWITCH ON DISABLED is not left while STO is active.
    row(2, from(S::switch_on_disabled), S::ready_to_switch_on, facts(F::shutdown), {}, facts(F::sto)),
    // "System checks if power supply is switched on" (seed line 49).
    t3_switch_on,
    row(4, from(S::switched_on), S::operation_enabled, facts(F::enable_operation),
        facts(F::dc_link), facts(F::sto), row_stop::immediate, clears),
    // T5, T8: ramp on 0x221E, close the brake at standstill, then power off (seed lines 69, 99).
    row(5, from(S::operation_enabled), S::switched_on, facts(F::switch_on), {}, {},
        row_stop::slow_down_ramp),
    // S14: under STO, SWITCHED ON goes to SWITCH ON DISABLED (T10), whatever the command.
    row(6, from(S::switched_on), S::ready_to_switch_on, facts(F::shutdown), {}, facts(F::sto)),
    // S14: STO acts as seed 002's "local signal" Disable voltage in T7 and T10.
    row(7, from(S::ready_to_switch_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::quick_stop, F::sto)),
    row(8, from(S::operation_enabled), S::ready_to_switch_on, facts(F::shutdown), {}, {},
        row_stop::slow_down_ramp),
    // T9 coasts and closes the brake at once (seed line 109).
    row(9, from(S::operation_enabled), S::switch_on_disabled,
        facts(F::disable_voltage, F::quick_stop), {}, {}, row_stop::immediate, interrupts),
    row(10, from(S::switched_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::quick_stop, F::sto)),
    t14_reaction_done,
    t15_fault_reset,
};

constexpr std::array<option_spec, option_count> options = {{
    {0, 0},                  // 0x605A: no quick stop
    {0, 1},                  // 0x605B: fixed ramp (0x221E), not an object here
    {0, 1},                  // 0x605C: likewise
    {value_range(1, 4), 1},  // 0x605D halt: the standard's, the seed is silent
    {value_range(0, 4), 2},  // 0x605E: the standard's, the seed is silent
    {value_range(0, 3), 1},  // 0x6007: the standard's
}};

constexpr profile base = make_profile(
    "no-quick-stop", "000_44b471b7401b86be.txt",
    "CANopen drive without quick stop; ramped T5/T8 on 0x221E, coasting T9", standard_decoder, stored_rows<rows>,
    standard_states(state_activity::idle), options);

}  // namespace

const profile no_quick_stop_profile = with_ordinary_cycles<base>();

}  // namespace cia402::detail
