// candump's log format (linux-can can-utils: `candump -l` writes it, `canplayer` replays it;
// python-can's CanutilsLogReader / CanutilsLogWriter read and write it): a recorded bus, one frame
// a line,
//   (1700000000.123456) can0 183#3706
// the time in seconds with microseconds, the interface, the identifier in hexadecimal (3 digits for
// an 11-bit identifier, 8 for a 29-bit one), '#', the data as contiguous hexadecimal; a remote frame
// is "R", followed by its length when that is not 0 ("123#R", "123#R2").
//
// Reading takes what those tools write: python-can's trailing direction (" R" / " T") is allowed.
// A line that is not a classic CAN frame is refused with the reason and gives nothing: CAN FD
// ("123##1..."), error frames (identifier bit 29), data of an odd number of digits or over 8 bytes,
// an 11-bit identifier above 0x7FF, a time that is not SECONDS.FRACTION.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "cia402/canopen/can/frame.hpp"

namespace cia402::canopen::candump {

/// One line of a log.
struct log_entry {
  std::uint64_t time_us = 0;  ///< microseconds since the Unix epoch (or whatever zero the log has)
  std::string interface;      ///< "can0"
  frame f;
};

/// The frame as candump writes it: "183#3706", "01ABCDEF#DEAD", "701#R".
std::string format_frame(const frame& f);
/// The line for one frame, without the newline: "(1700000000.123456) can0 183#3706".
std::string format_line(const frame& f, std::uint64_t time_us, std::string_view interface);

/// Reads one line (a trailing '\r' or '\n' is allowed). False with the reason, and `out`
/// unchanged, when it is not a classic CAN frame in the format above.
bool parse_line(std::string_view line, log_entry& out, std::string& why);

}  // namespace cia402::canopen::candump
