// The session's private pieces shared by its source files: an operation (a list of steps run in
// order) and an object job (one transfer).
#pragma once

#include <string>
#include <vector>

#include "cia402/axis/session.hpp"

namespace cia402::axes {

struct session::operation {
  std::uint64_t id = 0;
  std::string name;
  std::vector<step> steps;
  std::size_t at = 0;
  bool started = false;
  bool motion = false;      // commands the shaft: superseded by the lease, refused without DC link
  bool fault_ok = false;    // a drive in FAULT is what it works on (reset, state)
  bool streaming = false;   // source_ is its set-point source
  bool jogging = false;     // turning at a jog velocity until released
  bool commanded = false;   // it has given the drive a word (a target, a command, an edge)
  bool stop = false;        // a stop the session runs: not cancelled, not stopped again
  bool limited = false;     // status bit 11 was seen while it ran (internal limit active)
  completion done;
  result res;
  std::string error;        // set by the step that failed
  std::vector<std::uint16_t> polls;  // objects polled for it (need())
};

struct session::job {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  bool download = false;
  std::vector<std::uint8_t> bytes;
  transfer_done done;
};

/// "0x6041:0".
std::string object_name(std::uint16_t index, std::uint8_t sub);
/// "0x2310 (continuous over-current)".
std::string error_code_words(std::uint16_t code);
/// "0x06090030 (invalid value for parameter)", or the link's words when there is no code.
std::string transfer_failure(const transfer_result& r);
/// "0x0237".
std::string word_hex(std::uint16_t w);
/// "pp (1)", "mode 2".
std::string mode_words(std::int64_t m);

}  // namespace cia402::axes
