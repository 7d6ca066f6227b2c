// What the parts of the Python binding (_cia402) share: profiles kept alive by whatever runs on
// them, the outputs of a step as Python sees them, and the raising of the package's exceptions
// (cia402/_errors.py) from C++ results. Each area binds itself in its own file (bind_* below); a
// later fieldbus area (CANopen's virtual bus, the EtherCAT chain, the axis session) adds a file
// and a line in module.cpp.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402 {
struct command_path;
struct profile_file_error;
namespace sim {
struct scenario_error;
}
}  // namespace cia402

namespace cia402::python {

namespace py = pybind11;

/// A profile as Python holds it: a built-in (static) or one loaded from a file (owned here). Every
/// drive, machine and replay keeps a shared pointer to the one it runs on, so it outlives them.
struct profile_handle {
  std::shared_ptr<const custom_profile> owned;  ///< null for a built-in
  const profile* table = nullptr;
  const profile& get() const noexcept { return *table; }
};
using profile_ptr = std::shared_ptr<const profile_handle>;

/// The built-in profile of that name; ProfileError (line 0) when there is none.
profile_ptr builtin_profile_named(std::string_view name);
/// A TOML profile file; ProfileError with the line and reason.
profile_ptr profile_from_file(const std::string& path);
/// A profile argument: None (the standard profile), a built-in's name or a Profile.
profile_ptr profile_argument(const py::handle& value);

/// What one step or settle decided, as `Outputs`: the last step's outputs and every transition
/// taken (at most one for a step).
struct step_outputs {
  drive_outputs out;
  std::vector<std::uint8_t> transitions;
  bool settled = true;  ///< a settle came to rest (always true for a single step)
};

/// "released" / "engaged".
inline const char* brake_name(bool released) noexcept { return released ? "released" : "engaged"; }

// Raising the package's exceptions. Each sets the Python error and throws
// py::error_already_set, which pybind11 hands back to the interpreter.
[[noreturn]] void raise_sdo_error(sdo_abort code, std::uint16_t index, std::uint8_t sub,
                                  std::string_view action);
/// Raises SdoError unless the access succeeded.
inline void check_access(sdo_abort code, std::uint16_t index, std::uint8_t sub,
                         std::string_view action) {
  if (code != sdo_abort::none) raise_sdo_error(code, index, sub, action);
}
[[noreturn]] void raise_argument_error(const std::string& message);

/// The names of a table of named entries (each with a `name`), joined by ", ": what an
/// ArgumentError for a name the table lacks lists as the names there are.
template <typename Table>
std::string names_of(const Table& table) {
  std::string names;
  for (const auto& each : table) {
    if (!names.empty()) names += ", ";
    names += each.name;
  }
  return names;
}
[[noreturn]] void raise_profile_error(const profile_file_error& e);
[[noreturn]] void raise_profile_error(const std::string& message);
[[noreturn]] void raise_scenario_error(const sim::scenario_error& e);
[[noreturn]] void raise_busy_error(const std::string& message);

/// An object index and sub-index from `obj[0x6060]` or `obj[0x6099, 1]`; ArgumentError otherwise.
struct object_key {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
};
object_key object_key_of(const py::handle& key);
/// A value in [low, high]; ArgumentError naming `what` otherwise.
std::int64_t checked_integer(std::int64_t value, std::int64_t low, std::int64_t high,
                             std::string_view what);
/// A state by name or abbreviation ("OPERATION_ENABLED", "operation_enabled", "OE");
/// ArgumentError listing the states otherwise.
state state_argument(std::string_view name);

/// A planned path as Python's list of PathStep, or None when it does not reach its target.
py::object path_steps(const profile& p, const command_path& path);

/// `cia402 replay` on a fresh drive of profile p, with the option codes `options` holds written
/// first: the JSON objects it prints for `lines` (a str of lines or an iterable of lines), as dicts.
py::list replay_dicts(const profile_ptr& p, const axis& options, const py::object& lines);

void bind_errors(py::module_& m);
void bind_profiles(py::module_& m);
void bind_drive(py::module_& m);
void bind_replay(py::module_& m);
void bind_sim(py::module_& sim);
void bind_canopen(py::module_& canopen);
void bind_sim_traces(py::module_& sim);

}  // namespace cia402::python
