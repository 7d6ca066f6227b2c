// Profile `s300-profibus`: the PROFIBUS "instrument control" page of seed 003_83442f2f4b0b2bb9.txt
// (STW / ZSW). Transitions are written there as control-word bit changes; we read them as levels
// decoded like S1 (docs/profiles/s300-profibus.md gives the reasons and cites each row).
#include "profiles/builtin.hpp"
#include "profiles/rows.hpp"

namespace cia402::detail {
namespace {

// First match wins; T13 first. The output stage is on from T3 ("Drive has torque", seed line 88),
// so SWITCHED ON holds torque, and T6, T8, T9, T10, T12 switch it off at once ("motor loses torque").
constexpr transition_row rows[] = {
    t13_fault(),
    t0_power_on,
    t1_initialised,
    // T2: bits 1 and 2 set (shutdown), DC-link voltage present (seed lines 73..74).
    row(2, from(S::switch_on_disabled), S::ready_to_switch_on, facts(F::shutdown),
        facts(F::dc_link), facts(F::sto)),
    t3_switch_on,
    row(4, from(S::switched_on), S::operation_enabled, facts(F::enable_operation),
        facts(F::dc_link), facts(F::sto)),
    // T5: "braked, using the relevant ramp" (seed line 109).
    row(5, from(S::operation_enabled), S::switched_on, facts(F::switch_on), {}, {},
        row_stop::slow_down_ramp),
    row(6, from(S::switched_on), S::ready_to_switch_on, facts(F::shutdown)),
    // T7 also when the DC link goes: "Ready for switch-on: DC-link voltage must be applied" (seed
    // line 26). S14: STO acts as a local Disable voltage.
    row(7, from(S::ready_to_switch_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::quick_stop, F::undervoltage, F::sto)),
    row(8, from(S::operation_enabled), S::ready_to_switch_on, facts(F::shutdown), {}, {},
        row_stop::immediate, interrupts),
    row(9, from(S::operation_enabled), S::switch_on_disabled, facts(F::disable_voltage), {}, {},
        row_stop::immediate, interrupts),
    // No STO trigger on T10: SWITCHED ON holds torque here, so STO is a fault (S14, T13 first).
    row(10, from(S::switched_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::quick_stop)),
    // T11: emergency ramp, output stage stays on, set-points cancelled (seed line 169).
    row(11, from(S::operation_enabled), S::quick_stop_active, facts(F::quick_stop), {}, {},
        row_stop::immediate, interrupts | clears),
    t12_disable_voltage,
    t14_reaction_done,
    t15_fault_reset,
    // T16: "Bit 2 is set" with bits 0, 1, 3 still set: Enable operation (seed line 215).
    row(16, from(S::quick_stop_active), S::operation_enabled, facts(F::enable_operation)),
};

// PROFIBUS has none of these objects; the defaults say what the seed's text does.
constexpr std::array<option_spec, option_count> options = {{
    {0, 6},  // fast stop: emergency ramp, then hold in QUICK STOP ACTIVE (seed line 38)
    {0, 0},  // T8 switches off at once
    {0, 1},  // T5 ramps
    {0, 1},  // no halt bit (STW bit 8 is jog)
    {0, 0},  // "the power stage is switched off immediately" (seed line 42)
    {0, 1},  // a lost connection is a fault
}};

constexpr profile make() noexcept {
  profile p = make_profile(
    "s300-profibus", "003_83442f2f4b0b2bb9.txt",
    "PROFIBUS instrument control (STW/ZSW): fast stop on bit 2, T16 on bit 2 set",
    standard_decoder, stored_rows<rows>, standard_states(state_activity::hold), options);
  p.words = word_names::drivecom;  // STW / ZSW: bit 8 is jog, not halt
  return p;
}

constexpr profile base = make();

}  // namespace

const profile s300_profibus_profile = with_ordinary_cycles<base>();

}  // namespace cia402::detail
