// `cia402 demo`: one drive taken through power-up, enable, a quick stop, a fault and its reset, one
// printed line per cycle, so a reader sees torque, brake and ramp follow the state machine.
#pragma once

#include <cstdint>
#include <iosfwd>

#include "cia402/profile.hpp"
#include "cia402/words.hpp"

namespace cia402::cli {

/// The lowest control word the profile decodes to `c` (0x06 shutdown, 0x0F enable operation, ...
/// in the standard; 0x1F enable operation in seed 004, where bit 4 must be set), so the demo speaks
/// each profile's own dialect. 0 if no word decodes to `c`.
std::uint16_t control_word_for(const profile& p, command c);

/// Runs the demo on the profile and prints it.
void run_demo(const profile& p, std::ostream& out);

}  // namespace cia402::cli
