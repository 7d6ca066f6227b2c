// Shorthand for writing transition tables, so a built-in profile reads like its seed's table.
#pragma once

#include "cia402/profile.hpp"

namespace cia402::detail {

using S = state;
using F = fact;

constexpr std::uint16_t from(S a) noexcept { return state_bit(a); }
constexpr std::uint16_t from(S a, S b) noexcept { return state_bit(a) | state_bit(b); }

/// T13 leaves every state but FAULT REACTION ACTIVE and FAULT (S4); START is left by T0 alone.
inline constexpr std::uint16_t every_state_but_fault =
    state_bit(S::not_ready_to_switch_on) | state_bit(S::switch_on_disabled) |
    state_bit(S::ready_to_switch_on) | state_bit(S::switched_on) |
    state_bit(S::operation_enabled) | state_bit(S::quick_stop_active);

constexpr fact_set facts() noexcept { return fact_set(); }
template <typename... More>
constexpr fact_set facts(F first, More... more) noexcept {
  return fact_set(first) | facts(more...);
}

constexpr transition_row row(std::uint8_t number, std::uint16_t from_states, S to, fact_set any,
                             fact_set all = {}, fact_set none = {},
                             row_stop stop = row_stop::immediate, std::uint8_t flags = 0) noexcept {
  return transition_row{number, to, from_states, any, all, none, stop, flags};  // the fields' order
}

inline constexpr std::uint8_t interrupts = row_flag::interrupts_stop;
inline constexpr std::uint8_t clears = row_flag::clears_setpoints;

/// The standard's decoding of bits 0..3, first match wins (S1).
inline constexpr decoder_rule standard_decoder[] = {
    {0x02, 0x00, command::disable_voltage},
    {0x04, 0x00, command::quick_stop},
    {0x01, 0x00, command::shutdown},
    {0x08, 0x00, command::switch_on},
};

/// Status bits 0..3, 5, 6 of each state (cia402-reference.md §1.1; S11 sets bit 5 in RTSO, SO, OE).
constexpr std::array<state_info, state_count> standard_states(state_activity switched_on) noexcept {
  std::array<state_info, state_count> s{};
  s[static_cast<int>(S::start)] = {0x00, state_activity::idle};
  s[static_cast<int>(S::not_ready_to_switch_on)] = {0x00, state_activity::idle};
  s[static_cast<int>(S::switch_on_disabled)] = {0x40, state_activity::idle};
  s[static_cast<int>(S::ready_to_switch_on)] = {0x21, state_activity::idle};
  s[static_cast<int>(S::switched_on)] = {0x23, switched_on};
  s[static_cast<int>(S::operation_enabled)] = {0x27, state_activity::run};
  s[static_cast<int>(S::quick_stop_active)] = {0x07, state_activity::quick_stop};
  s[static_cast<int>(S::fault_reaction_active)] = {0x0F, state_activity::fault_reaction};
  s[static_cast<int>(S::fault)] = {0x08, state_activity::idle};
  return s;
}

/// Bits v0, v1, ... set: the supported values of an option code.
constexpr std::uint16_t values() noexcept { return 0; }
template <typename... More>
constexpr std::uint16_t values(int first, More... more) noexcept {
  return static_cast<std::uint16_t>((1u << first) | values(more...));
}
constexpr std::uint16_t value_range(int lo, int hi) noexcept {
  std::uint16_t m = 0;
  for (int v = lo; v <= hi; ++v) m = static_cast<std::uint16_t>(m | (1u << v));
  return m;
}

/// The rows every seed prints alike. T13 from the states it leaves (every state but the two fault
/// states, S4), first in every table because faults win over any command (S12).
constexpr transition_row t13_fault(std::uint16_t from_states = every_state_but_fault) noexcept {
  return row(13, from_states, S::fault_reaction_active, facts(F::fault), {}, {}, row_stop::immediate,
             interrupts);
}
/// T0 and T1: power on, then the drive's own initialisation, each by itself.
inline constexpr transition_row t0_power_on =
    row(0, from(S::start), S::not_ready_to_switch_on, facts(F::automatic));
inline constexpr transition_row t1_initialised =
    row(1, from(S::not_ready_to_switch_on), S::switch_on_disabled, facts(F::automatic));
/// T14: the fault reaction has stopped the motor (S4); every seed's.
inline constexpr transition_row t14_reaction_done =
    row(14, from(S::fault_reaction_active), S::fault, facts(F::automatic), facts(F::stop_complete));
/// T15: a fault reset edge (S2) once no fault cause is present, in every seed without error classes.
inline constexpr transition_row t15_fault_reset =
    row(15, from(S::fault), S::switch_on_disabled, facts(F::fault_reset), {}, facts(F::fault_present));

/// The rows the standard's way where a seed follows it. T3: Switch on, or Enable operation (which
/// runs T3 then T4, S3), with DC-link voltage (S13) and no STO (S14).
inline constexpr transition_row t3_switch_on =
    row(3, from(S::ready_to_switch_on), S::switched_on, facts(F::switch_on, F::enable_operation),
        facts(F::dc_link), facts(F::sto));
/// T12 on Disable voltage, whatever 0x605A says.
inline constexpr transition_row t12_disable_voltage =
    row(12, from(S::quick_stop_active), S::switch_on_disabled, facts(F::disable_voltage));

/// Puts the pieces together and derives the lookup tables.
template <std::size_t NDecoder, std::size_t NRows, std::size_t NSets>
constexpr profile make_profile(const char* name, const char* seed, const char* title,
                               const decoder_rule (&decoder)[NDecoder],
                               const stored_table<NRows, NSets>& rows,
                               std::array<state_info, state_count> states,
                               std::array<option_spec, option_count> options) noexcept {
  static_assert(NDecoder <= max_decoder_rules, "too many decoder rules");
  static_assert(NRows <= max_rows, "too many rows");
  profile p;
  p.name = name;
  p.seed = CIA402_PROFILE_TEXT ? seed : "";
  p.title = CIA402_PROFILE_TEXT ? title : "";
  p.decoder = decoder;
  p.decoder_size = static_cast<std::uint8_t>(NDecoder);
  p.use_rows(rows);
  p.states = states;
  p.options = options;
  p.finalize();
  return p;
}

/// A built-in profile's ordinary cycles (profile::ordinary), compiled with it at compile time.
template <const profile& Base>
inline constexpr ordinary_tables ordinary_cycles_of = [] {
  ordinary_tables t{};
  profile p = Base;
  p.finalize(&t);
  return t;
}();

/// The built-in profile, pointed at its compiled ordinary cycles. A build for size (-Os: a firmware)
/// leaves them out, so its step is the full step every cycle (as drive.hpp's step() is there) and
/// the 21.5 KiB a profile stay out of its flash (bench/cortex_m4).
template <const profile& Base>
constexpr profile with_ordinary_cycles() noexcept {
  profile p = Base;
#if !defined(__OPTIMIZE_SIZE__)
  p.ordinary = &ordinary_cycles_of<Base>;
#endif
  return p;
}

}  // namespace cia402::detail
