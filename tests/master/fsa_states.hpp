// The eight states of the CiA 402 state machine a drive can be in (all but START), for the master's
// tests that plan from and to every one of them.
#pragma once

#include "cia402/state.hpp"

namespace cia402::test {

inline constexpr state fsa_states[] = {
    state::not_ready_to_switch_on, state::switch_on_disabled, state::ready_to_switch_on,
    state::switched_on,            state::operation_enabled,  state::quick_stop_active,
    state::fault_reaction_active,  state::fault,
};

}  // namespace cia402::test
