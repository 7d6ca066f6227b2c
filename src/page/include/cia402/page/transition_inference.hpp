// The transition numbers a remote observer infers from the states it sees. A drive on a bus reports
// its state (status word 0x6041), not the transition it took; the page of seed
// 003_83442f2f4b0b2bb9.txt accents "the last transition's number", so for a remote drive the page
// shows a number inferred from the profile's rows, and says that it is inferred.
//
// The rule: a row fits an observed change old -> new when its `from` set holds old and its `to` is
// new. Where several rows fit (T7 and T10 both end in SWITCH ON DISABLED, seed 001's T12 has two
// forms, ...), the row whose trigger is the command the observer last sent wins; then a row that
// needs no command (automatic, a fault, a stop that completes); then the first row in the table.
// Where no single row fits, the observer missed a state in between (status words are sampled, and
// S3's T3 then T4 run in consecutive cycles): the shortest chain of rows (at most
// max_inferred_chain) is taken, scored the same way row by row.
#pragma once

#include <cstdint>
#include <vector>

#include "cia402/profile.hpp"
#include "cia402/state.hpp"

namespace cia402::page {

inline constexpr std::size_t max_inferred_chain = 3;

struct inferred_transition {
  std::uint8_t number = no_transition;
  state from = state::start;
  state to = state::start;
};

/// The facts an observer may take as present after sending `control_word`: the command it decodes
/// to under the profile, and fault_reset if `reset_edge_sent` (bit 7 rose since the last change).
fact_set observer_facts(const profile& p, std::uint16_t control_word, bool reset_edge_sent) noexcept;

/// The rows that most likely took the drive from `from` to `to`, in order; empty when from == to or
/// when no chain of at most max_inferred_chain rows connects them.
std::vector<inferred_transition> infer_transitions(const profile& p, state from, state to,
                                                   fact_set sent);

}  // namespace cia402::page
