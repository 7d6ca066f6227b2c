// `cia402 diagram`: the profile's state machine drawn from its table, as DOT, Mermaid or SVG (SVG
// through Graphviz's `dot`, when it is installed).
#pragma once

#include <iosfwd>
#include <string>

#include "cia402/profile.hpp"

namespace cia402::cli {

/// Writes the diagram to `out`; returns 0, or 1 with a message when SVG is asked for and Graphviz
/// cannot be run, 2 for an unknown format.
int run_diagram(const profile& p, const std::string& format, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
