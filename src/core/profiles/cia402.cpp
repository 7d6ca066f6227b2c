// Profile `cia402`: the standard, as seed 002_522d2c0bb8f5a5f8.txt (CoE table 7.8) prints it, with
// the points it leaves open fixed by docs/semantics.md (S1..S17). docs/profiles/cia402.md cites each row.
#include "profiles/builtin.hpp"
#include "profiles/rows.hpp"

namespace cia402::detail {
namespace {

// Rows are tried in this order and the first match wins: T13 comes first because faults win over
// any command (S12); the others follow the seed's numbering.
constexpr transition_row rows[] = {
    t13_fault(),
    t0_power_on,
    t1_initialised,
    // S14: SWITCH ON DISABLED is not left while STO is active.
    row(2, from(S::switch_on_disabled), S::ready_to_switch_on, facts(F::shutdown), {}, facts(F::sto)),
    // S3: Enable operation here runs T3, then T4 in the next step. S13/S14: voltage, no STO.
    t3_switch_on,
    row(4, from(S::switched_on), S::operation_enabled, facts(F::enable_operation),
        facts(F::dc_link), facts(F::sto), row_stop::immediate, clears),
    row(5, from(S::operation_enabled), S::switched_on, facts(F::switch_on), {}, {},
        row_stop::disable_operation_option),
    // S14: under STO, SWITCHED ON goes to SWITCH ON DISABLED (T10), whatever the command.
    row(6, from(S::switched_on), S::ready_to_switch_on, facts(F::shutdown), {}, facts(F::sto)),
    // S14: STO acts as seed 002's "local signal" Disable voltage in T7 and T10.
    row(7, from(S::ready_to_switch_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::quick_stop, F::sto)),
    row(8, from(S::operation_enabled), S::ready_to_switch_on, facts(F::shutdown), {}, {},
        row_stop::shutdown_option),
    row(9, from(S::operation_enabled), S::switch_on_disabled, facts(F::disable_voltage), {}, {},
        row_stop::immediate, interrupts),
    row(10, from(S::switched_on), S::switch_on_disabled,
        facts(F::disable_voltage, F::quick_stop, F::sto)),
    row(11, from(S::operation_enabled), S::quick_stop_active, facts(F::quick_stop), {}, {},
        row_stop::immediate, interrupts),
    t12_disable_voltage,
    row(12, from(S::quick_stop_active), S::switch_on_disabled, facts(F::automatic),
        facts(F::quick_stop_ends, F::stop_complete)),
    t14_reaction_done,
    t15_fault_reset,
    row(16, from(S::quick_stop_active), S::operation_enabled, facts(F::enable_operation),
        facts(F::quick_stop_stays)),
};

constexpr std::array<option_spec, option_count> options = {{
    {value_range(0, 8), 2},  // 0x605A quick stop (S5)
    {value_range(0, 1), 1},  // 0x605B shutdown (S7)
    {value_range(0, 1), 1},  // 0x605C disable operation (S7)
    {value_range(1, 4), 1},  // 0x605D halt (S8)
    {value_range(0, 4), 2},  // 0x605E fault reaction (S9)
    {value_range(0, 3), 1},  // 0x6007 abort connection (S10)
}};

constexpr profile base = make_profile(
    "cia402", "002_522d2c0bb8f5a5f8.txt",
    "CiA 402 standard (CoE table 7.8)",
    standard_decoder, stored_rows<rows>,
    standard_states(state_activity::idle), options);

}  // namespace

const profile cia402_profile = with_ordinary_cycles<base>();

}  // namespace cia402::detail
