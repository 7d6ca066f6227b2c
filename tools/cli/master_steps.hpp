// The steps of `cia402 master`, read in order from its command line: each step with its operands and
// the options that follow it (`move 20000 --velocity 600 --relative`). Values are checked against
// the core's object table here, before anything is sent.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cia402::cli {

struct master_step {
  std::string verb;  ///< state, enable, ..., "sdo read", "sdo write", nmt
  std::string text;  ///< the step as given, for messages ("move 20000 --velocity 600")
  std::int64_t number = 0;   ///< move POS, velocity RPM, torque PERMILLE, jog RPM, wait MS
  std::int64_t number2 = 0;  ///< jog MS
  std::optional<std::int64_t> velocity, to, offset, method;
  bool relative = false;
  bool on = false;            ///< halt on|off
  std::int8_t mode = 0;       ///< mode MODE
  std::uint16_t index = 0;    ///< sdo
  std::uint8_t sub = 0;
  std::string value;          ///< sdo write: the value as written, parsed with the object's type
  std::string nmt;            ///< nmt: start, stop, preop, reset, reset-communication
};

/// The steps after "master" in `raw` (the whole command line), skipping the global options. Nothing,
/// with `why`, for a word that is no step, a missing or bad operand, or an option no step before it
/// takes.
std::optional<std::vector<master_step>> parse_master_steps(const std::vector<std::string>& raw, std::string& why);

}  // namespace cia402::cli
