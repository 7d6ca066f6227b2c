// `cia402 demo`: one drive taken through power-up, enable, a quick stop, a fault and its reset, one
// printed line per cycle, so a reader sees torque, brake and ramp follow the state machine.
#pragma once

#include <cstdint>
#include <iosfwd>

#include "cia402/profile.hpp"
#include "cia402/words.hpp"

namespace cia402::cli {

/// Runs the demo on the profile and prints it.
void run_demo(const profile& p, std::ostream& out);

}  // namespace cia402::cli
