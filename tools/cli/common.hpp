// Small pieces every subcommand of the `cia402` tool shares: number parsing, hex and JSON text,
// and choosing a profile by name or file.
#pragma once

#include <csignal>
#include <cstdint>
#include <ios>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

#include "cia402/profile.hpp"
#include "cia402/support/text.hpp"

namespace CLI {
class App;
}

namespace cia402::cli {

/// Parses a decimal ("15", "-1") or hexadecimal ("0x0F") integer, the whole text. Refuses anything
/// else, including values that do not fit 32 bits signed or unsigned.
std::optional<std::int64_t> parse_number(std::string_view text);

/// "0x0237": 0x and `digits` upper-case hex digits.
using support::hex;

/// The profile a command runs on: a built-in by name, or a profile file. Keeps a loaded file alive.
class profile_choice {
 public:
  profile_choice() = default;
  profile_choice(const profile_choice&) = delete;  // get() may point into loaded_
  profile_choice& operator=(const profile_choice&) = delete;
  /// Resolves the choice; on failure writes a message to `err` and returns false.
  bool resolve(const std::string& name, const std::string& file, std::ostream& err);
  const profile& get() const noexcept { return *profile_; }

 private:
  custom_profile loaded_;
  const profile* profile_ = &standard_profile();
};

/// While it lives, SIGINT and SIGTERM set a flag instead of ending the process (and the handlers
/// before it come back after): how the tool's loops (bus, ecat-slave, monitor, master) learn that
/// they are to stop and end cleanly. One at a time.
class stop_signals {
 public:
  stop_signals();
  ~stop_signals();
  stop_signals(const stop_signals&) = delete;
  stop_signals& operator=(const stop_signals&) = delete;
  bool requested() const noexcept { return flag() != 0; }
  /// The flag itself, for a loop that takes one (apps::bus_host::run).
  static const volatile std::sig_atomic_t& flag() noexcept;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

/// Opens `path` for writing (mode: std::ios::binary and the like); if it cannot, says
/// "cia402 COMMAND: cannot write PATH" on err and returns false.
bool open_output(std::ofstream& file, const std::string& path, std::string_view command, std::ostream& err,
                 std::ios::openmode mode = std::ios::out);

/// "cia402, no-quick-stop, ..." for messages.
std::string builtin_profile_names();

/// The two ways a subcommand is given its profile, which exclude each other: `--profile NAME` (a
/// built-in; `name_help` says what it is for, the names follow) or `--profile-file FILE`.
void add_profile_options(CLI::App& cmd, std::string& name, std::string& file,
                         const std::string& name_help = "built-in profile");

}  // namespace cia402::cli
