// The page's one-click Enable and its jog, as the page states them for every drive (docs/
// instrument-page.md, "Enable, Stop and jog"): what blocks the way to OPERATION ENABLED, and the
// bounds of the jog's time-to-live the HTTP API takes. The walk itself (the core's planner, S17),
// the stop and the jog's dead-man are the axis session's (axis/session.hpp).
#pragma once

#include <cstdint>
#include <string>

#include "cia402/state.hpp"

namespace cia402::page::detail {

/// Why the drive cannot go on towards OPERATION ENABLED from its own inputs, or "" if nothing
/// does: a fault (FAULT or FAULT REACTION ACTIVE, with the error code 0x603F and its text; the
/// walk never resets it), STO asserted, no DC-link voltage, or the drive under local control
/// (status word bit 9 "remote" off: it does not take the control word, S11).
std::string enable_blocker(state shown, std::uint16_t error_code, bool sto, bool dc_link, bool remote);

/// The jog's time-to-live as the HTTP API takes it: default, least and most (ms).
inline constexpr std::uint64_t jog_ttl_default_ms = 300;
inline constexpr std::uint64_t jog_ttl_min_ms = 20;
inline constexpr std::uint64_t jog_ttl_max_ms = 1000;

}  // namespace cia402::page::detail
