// The state machine of a profile drawn from its transition table: state boxes and numbered
// transition arrows, as Graphviz DOT or Mermaid text. Tools layer (allocates; not for the cycle).
#pragma once

#include <string>

#include "cia402/profile.hpp"

namespace cia402 {

/// Graphviz DOT. Every state node has id "state.NAME" and class "state"; every arrow has id
/// "t<N>.FROM.TO" and class "transition t<N>", so an SVG rendered from it can be styled per state
/// and per transition number (the instrument page does). A row that leaves three or more states
/// (T13) is one arrow, id "t<N>.ANY.TO", from a dashed frame around those states.
std::string diagram_dot(const profile& p);

/// Mermaid stateDiagram-v2.
std::string diagram_mermaid(const profile& p);

}  // namespace cia402
