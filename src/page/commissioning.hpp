// The page's one-click Enable and its jog's dead-man, decided alike for every backend (docs/
// instrument-page.md, "Enable, Stop and jog"): what blocks the way to OPERATION ENABLED, the next
// planned step of the walk there (the core's planner, S17), and the jog's time-to-live. A backend
// only gets the words to its drive its own way and reports the outcome.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "cia402/state.hpp"

namespace cia402::page::detail {

/// Why the drive cannot go on towards OPERATION ENABLED from its own inputs, or "" if nothing
/// does: a fault (FAULT or FAULT REACTION ACTIVE, with the error code 0x603F and its text; the
/// walk never resets it), STO asserted, no DC-link voltage.
std::string enable_blocker(state shown, std::uint16_t error_code, bool sto, bool dc_link);

/// The next cycle of the walk to OPERATION ENABLED from the state the status word shows.
struct walk_step {
  bool there = false;       ///< already OPERATION ENABLED
  std::string refusal;      ///< no planned path (the reason); else the step below
  std::uint16_t word = 0;   ///< the whole control word (bits the state machine does not own kept)
  state after = state::start;  ///< what the status word must show before the next step
  int transition = -1;      ///< the transition this step fires, -1 for none
};
/// The first step of cia402::plan_path_from_status towards OPERATION ENABLED (S17: the only target
/// the walk has, so no path runs through it to elsewhere); `options_from` gives the option codes.
walk_step next_enable_step(const profile& p, const axis& options_from, state shown,
                           std::uint16_t control_word);

/// One-click enable in progress: the result it reports and the step it waits for.
struct enable_walk {
  std::uint64_t id = 0;
  std::optional<state> expected;  ///< what the last step's word leads to
  std::uint64_t deadline = 0;     ///< the step is refused unconfirmed after this (backend's clock)
  std::vector<int> transitions;
};

/// A jog that runs while its keep-alive comes: the dead-man (time in the backend's clock, us).
struct jog_run {
  std::uint64_t id = 0;
  std::string action;
  std::int64_t velocity_rpm = 0;
  std::uint64_t time_to_live_us = 0;
  std::uint64_t started_us = 0;
  std::uint64_t expires_us = 0;  ///< 0x60FF = 0 goes out in the first cycle at or after this
  void renew(std::uint64_t now_us) { expires_us = now_us + time_to_live_us; }
};

/// How long one step of the walk may wait for the status word to confirm it.
inline constexpr std::uint64_t enable_step_wait_us = 500000;

/// The jog's time-to-live as the HTTP API takes it: default, least and most (ms).
inline constexpr std::uint64_t jog_ttl_default_ms = 300;
inline constexpr std::uint64_t jog_ttl_min_ms = 20;
inline constexpr std::uint64_t jog_ttl_max_ms = 1000;

}  // namespace cia402::page::detail
