// Profile `ax2000-profibus`: Beckhoff AX2000/AX2500 PROFIBUS DP, seed 004_e07fd68605b3a8c6.txt. Same
// shape as s300-profibus, but fast stop is bit 4 (T11, T16) and bit 2 cleared inhibits switch-on
// (T17). docs/profiles/ax2000-profibus.md gives the reasons and cites each row.
#include "profiles/builtin.hpp"
#include "profiles/rows.hpp"

namespace cia402::detail {
namespace {

// Bit 1 cleared: inhibit voltage; bit 2 cleared: stop and inhibit switch-on; bit 0 cleared:
// shutdown; bit 3 cleared: disable operation; bit 4 cleared: fast stop; else enable operation.
constexpr decoder_rule decoder[] = {
    {0x02, 0x00, command::disable_voltage},
    {0x04, 0x00, command::stop_and_inhibit},
    {0x01, 0x00, command::shutdown},
    {0x08, 0x00, command::switch_on},
    {0x10, 0x00, command::quick_stop},
};

constexpr transition_row rows[] = {
    t13_fault(),
    t0_power_on,
    t1_initialised,
    // T2: bits 1 and 2 set, DC bus link voltage present (seed lines 14..16).
    row(2, from(S::switch_on_disabled), S::ready_to_switch_on, facts(F::shutdown),
        facts(F::dc_link), facts(F::sto)),
    // T3: "Bit 0 is also set" (seed line 19), whatever bits 3 and 4 say: with bit 4 clear the word
    // decodes as fast stop, which still switches on.
    row(3, from(S::ready_to_switch_on), S::switched_on,
        facts(F::switch_on, F::enable_operation, F::quick_stop), facts(F::dc_link), facts(F::sto)),
    row(4, from(S::switched_on), S::operation_enabled, facts(F::enable_operation),
        facts(F::dc_link), facts(F::sto)),
    row(5, from(S::operation_enabled), S::switched_on, facts(F::switch_on), {}, {},
        row_stop::slow_down_ramp),
    row(6, from(S::switched_on), S::ready_to_switch_on, facts(F::shutdown)),
    // T7, T10: "Bit 1 or Bit 2 is canceled" (seed lines 33, 42); S14: STO as a local Disable voltage.
    row(7, from(S::ready_to_switch_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::stop_and_inhibit, F::sto)),
    row(8, from(S::operation_enabled), S::ready_to_switch_on, facts(F::shutdown), {}, {},
        row_stop::immediate, interrupts),
    row(9, from(S::operation_enabled), S::switch_on_disabled, facts(F::disable_voltage), {}, {},
        row_stop::immediate, interrupts),
    // No STO trigger on T10: SWITCHED ON holds torque here, so STO is a fault (S14, T13 first).
    row(10, from(S::switched_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::stop_and_inhibit)),
    // T11: "Bit 4 is canceled" (seed line 45).
    row(11, from(S::operation_enabled), S::quick_stop_active, facts(F::quick_stop), {}, {},
        row_stop::immediate, interrupts | clears),
    t12_disable_voltage,
    t14_reaction_done,
    t15_fault_reset,
    // T16: "Bit 4 is set" with bits 0..3 still set (seed line 62).
    row(16, from(S::quick_stop_active), S::operation_enabled, facts(F::enable_operation)),
    // T17: "Bit 2 is canceled: switch-on inhibited, output stage disabled" (seed lines 64..66), from
    // the two states where T7 and T10 do not already cover it; the motor first stops on the
    // emergency ramp (KS300/B-AX2 STW bit 2, cia402-reference.md §6.1).
    row(17, from(S::operation_enabled, S::quick_stop_active), S::switch_on_disabled,
        facts(F::stop_and_inhibit), {}, {}, row_stop::quick_stop_ramp, interrupts),
};

constexpr std::array<option_spec, option_count> options = {{
    {0, 6},  // fast stop: emergency ramp, then hold in QUICK STOP ACTIVE
    {0, 0},  // T8 switches off at once
    {0, 1},  // T5 ramps
    {0, 1},  // no halt bit
    {0, 0},  // error response: output stage off at once (seed line 54)
    {0, 1},  // a lost connection is a fault
}};

constexpr profile make() noexcept {
  profile p = make_profile(
    "ax2000-profibus", "004_e07fd68605b3a8c6.txt",
    "Beckhoff AX2000 PROFIBUS DP: fast stop on bit 4, T17 on bit 2", decoder, stored_rows<rows>,
    standard_states(state_activity::hold), options);
  p.words = word_names::drivecom;  // STW / ZSW: bit 8 is jog, not halt
  return p;
}

constexpr profile base = make();

}  // namespace

const profile ax2000_profibus_profile = with_ordinary_cycles<base>();

}  // namespace cia402::detail
