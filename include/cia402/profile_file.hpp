// User profiles as TOML files: load one into a cia402::custom_profile, or write any profile (the
// built-ins included) as a file that loads back to the same tables. The format is described in
// examples/profiles/custom-drive.toml. This layer is C++20 and may allocate; the core stays below
// it.
#pragma once

#include <string>
#include <string_view>
#include <variant>

#include "cia402/profile.hpp"

namespace cia402 {

/// Why a profile file was refused. `line` and `column` are 1-based and point at the offending key
/// or value; 0 means the whole file (e.g. it could not be read).
struct profile_file_error {
  int line = 0;
  int column = 0;
  std::string reason;
  std::string source_name;  ///< the file name or the name given to load_profile_toml

  /// "custom-drive.toml:12:9: unknown fact 'fualt'".
  std::string message() const;
};

/// Either a complete, checked profile or the reason there is none: never anything in between.
using profile_load_result = std::variant<custom_profile, profile_file_error>;

/// Parses a profile from TOML text. Syntax errors, unknown or duplicate keys, wrong types, unknown
/// names, values out of range and every fault cia402::check_profile finds are refused with the line
/// and column they are on. `source_name` only labels errors.
profile_load_result load_profile_toml(std::string_view text,
                                      std::string_view source_name = "<profile>");

/// Reads and parses a profile file.
profile_load_result load_profile_toml_file(const std::string& path);

/// Writes a profile as a self-contained file (no `base`): every decoder rule, row, state and
/// option, so that load_profile_toml() gives back identical tables.
std::string dump_profile_toml(const profile& p);

/// The spelling of a row's stop in profile files: "immediate", "shutdown_option", ...; never null.
const char* row_stop_name(row_stop s) noexcept;
/// The spelling of a state's activity in profile files: "idle", "hold", "run", ...; never null.
const char* state_activity_name(state_activity a) noexcept;

}  // namespace cia402
