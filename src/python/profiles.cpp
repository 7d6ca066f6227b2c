// Profiles (built-in or from a TOML file), the planner's path, the object table, the state and
// mode names: the package's vocabulary, each read from the core's one table.
#include <pybind11/stl.h>

#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "binding.hpp"
#include "cia402/master.hpp"
#include "cia402/objects.hpp"
#include "cia402/profile_file.hpp"
#include "cia402/state.hpp"
#include "cia402/words.hpp"

namespace cia402::python {
namespace {

std::string builtin_names() {
  std::string list;
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    if (i != 0) list += ", ";
    list += builtin_profile(i).name;
  }
  return list;
}

profile_ptr loaded(profile_load_result result) {
  if (const auto* error = std::get_if<profile_file_error>(&result)) raise_profile_error(*error);
  auto handle = std::make_shared<profile_handle>();
  auto owned = std::make_shared<const custom_profile>(std::get<custom_profile>(result));
  handle->table = &owned->get();
  handle->owned = std::move(owned);
  return handle;
}

/// One cycle of a planned path, as `PathStep`.
struct path_step_view {
  std::uint16_t control_word = 0;
  std::uint8_t transition = no_transition;
  state after = state::start;
  std::string command;
};

py::object transition_or_none(std::uint8_t t) {
  return t == no_transition ? py::object(py::none()) : py::object(py::int_(t));
}


py::dict option_specs(const profile& p) {
  py::dict options;
  for (int i = 0; i < option_count; ++i) {
    const option_spec& spec = p.options[static_cast<std::size_t>(i)];
    if (!spec.exists()) continue;
    py::list values;
    for (int v = 0; v < 16; ++v) {
      if (spec.allows(v)) values.append(v);
    }
    py::dict entry;
    entry["default"] = int{spec.default_value};
    entry["values"] = values;
    options[py::int_(option_index(static_cast<option>(i)))] = entry;
  }
  return options;
}

py::dict describe_object(const object_description& o) {
  py::dict d;
  d["index"] = o.index;
  d["sub"] = o.sub;
  d["name"] = o.name;
  d["unit"] = o.unit;
  d["type"] = type_name(o.type);
  d["access"] = o.access == object_access::read_only    ? "ro"
                : o.access == object_access::write_only ? "wo"
                                                        : "rw";
  d["pdo_mappable"] = o.pdo_mappable;
  d["low"] = o.low;
  d["high"] = o.high;
  d["default"] = o.default_value;
  return d;
}

}  // namespace

py::object path_steps(const profile& p, const command_path& path) {
  if (!path.reachable) return py::none();
  py::list steps;
  for (std::size_t k = 0; k < path.length; ++k) {
    const path_step& s = path.steps[k];
    std::string cmd = command_name(p.decode(s.control_word));
    if (s.control_word & control_bit::fault_reset) cmd = "FAULT_RESET + " + cmd;
    steps.append(path_step_view{s.control_word, s.transition, s.after, cmd});
  }
  return steps;
}

profile_ptr profile_from_file(const std::string& path) { return loaded(load_profile_toml_file(path)); }

profile_ptr builtin_profile_named(std::string_view name) {
  // One handle per built-in, made once: a built-in is static and needs no owner.
  static const std::vector<profile_ptr> handles = [] {
    std::vector<profile_ptr> v;
    for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
      auto h = std::make_shared<profile_handle>();
      h->table = &builtin_profile(i);
      v.push_back(std::move(h));
    }
    return v;
  }();
  for (const profile_ptr& h : handles) {
    if (name == h->get().name) return h;
  }
  raise_profile_error("unknown profile '" + std::string(name) + "' (built-in: " + builtin_names() +
                      ")");
}

profile_ptr profile_argument(const py::handle& value) {
  if (value.is_none()) return builtin_profile_named(standard_profile().name);
  if (py::isinstance<py::str>(value)) return builtin_profile_named(value.cast<std::string>());
  if (py::isinstance<profile_handle>(value)) return value.cast<std::shared_ptr<profile_handle>>();
  raise_argument_error("a profile is a built-in's name or a cia402.Profile");
}

void bind_profiles(py::module_& m) {
  py::class_<profile_handle, std::shared_ptr<profile_handle>>(m, "Profile", R"doc(
A drive variant: its transition table, decoder, option codes and status patterns.

``Profile("lexium32")`` is a built-in (``cia402.profiles()`` lists them);
``Profile.from_file(path)`` and ``Profile.from_toml(text)`` load a TOML profile file
(examples/profiles/custom-drive.toml) and raise ProfileError with the line and reason.)doc")
      .def(py::init([](const std::string& name) {
             return std::const_pointer_cast<profile_handle>(builtin_profile_named(name));
           }),
           py::arg("name") = "cia402", "The built-in profile of that name (ProfileError if none).")
      .def_static("from_file",
                  [](const std::string& path) {
                    return std::const_pointer_cast<profile_handle>(profile_from_file(path));
                  },
                  py::arg("path"), "Loads a TOML profile file; ProfileError with the line and reason.")
      .def_static("from_toml",
                  [](const std::string& text, const std::string& source) {
                    return std::const_pointer_cast<profile_handle>(loaded(load_profile_toml(text, source)));
                  },
                  py::arg("text"), py::arg("source") = "<profile>",
                  "Parses a profile from TOML text; `source` labels errors.")
      .def_property_readonly("name", [](const profile_handle& h) { return h.get().name; })
      .def_property_readonly("title", [](const profile_handle& h) { return h.get().title; })
      .def_property_readonly("seed", [](const profile_handle& h) { return h.get().seed; })
      .def_property_readonly("builtin", [](const profile_handle& h) { return h.owned == nullptr; },
                             "True for a built-in profile, False for one loaded from a file.")
      .def_property_readonly("error_classes", [](const profile_handle& h) { return h.get().error_classes; },
                             "Whether the profile honours fault classes 0..4 (seed 001).")
      .def_property_readonly("options", [](const profile_handle& h) { return option_specs(h.get()); },
                             "The option-code objects it has: {index: {'default': d, 'values': [...]}}.")
      .def_property_readonly("transitions",
                             [](const profile_handle& h) {
                               std::vector<int> numbers;
                               for (std::size_t i = 0; i < h.get().row_count; ++i) {
                                 numbers.push_back(h.get().row(i).number);
                               }
                               return numbers;
                             },
                             "The transition number of each row of its table, in table order.")
      .def("to_toml", [](const profile_handle& h) { return dump_profile_toml(h.get()); },
           "The profile as a self-contained TOML file that loads back to the same tables.")
      .def("__repr__", [](const profile_handle& h) {
        return std::string("cia402.Profile('") + h.get().name + "'" + (h.owned ? ", from a file" : "") + ")";
      });

  m.def("profiles",
        [] {
          std::vector<std::string> names;
          for (std::size_t i = 0; i < builtin_profile_count(); ++i) names.emplace_back(builtin_profile(i).name);
          return names;
        },
        "The names of the built-in profiles.");

  py::class_<path_step_view>(m, "PathStep", "One cycle of a planned command path.")
      .def_readonly("control_word", &path_step_view::control_word, "The control word to send (owned bits only).")
      .def_property_readonly("transition", [](const path_step_view& s) { return transition_or_none(s.transition); },
                             "The transition the drive takes in this cycle, or None.")
      .def_property_readonly("state", [](const path_step_view& s) { return state_name(s.after); },
                             "The drive's state after this cycle.")
      .def_readonly("command", &path_step_view::command, "The command the word decodes to.")
      .def("__repr__", [](const path_step_view& s) {
        return "PathStep(control_word=" + std::to_string(s.control_word) + ", command='" + s.command +
               "', transition=" + (s.transition == no_transition ? std::string("None") : std::to_string(s.transition)) +
               ", state='" + state_name(s.after) + "')";
      });

  m.def("path",
        [](const std::string& from, const std::string& to, const py::object& profile_value,
           const std::optional<std::map<int, int>>& options) {
          const profile_ptr p = profile_argument(profile_value);
          const state start = state_argument(from);
          const state target = state_argument(to);
          axis options_from = make_axis(p->get());
          for (const auto& [index, value] : options.value_or(std::map<int, int>{})) {
            const auto i = static_cast<std::uint16_t>(checked_integer(index, 0, 0xFFFF, "index"));
            check_access(write_option(p->get(), options_from, i, value), i, 0, "writing");
          }
          return path_steps(p->get(), plan_path_from_status(p->get(), options_from, start, false, target));
        },
        py::arg("from_state"), py::arg("to_state"), py::arg("profile") = py::none(),
        py::arg("options") = py::none(), R"doc(
The planner's path (cia402::plan_path): the fewest-cycles command sequence from a drive at rest in
`from_state` to `to_state`, as `cia402 path` prints it. States by name or abbreviation ("OE").
`options` are option codes written first ({0x605A: 6}). A path to any state but OPERATION ENABLED
never passes through it (S17). Returns the list of PathStep ([] when already there), or None
when no command sequence reaches the target.)doc");

  m.def("states",
        [] {
          std::vector<std::string> names;
          for (int i = 1; i < state_count; ++i) names.emplace_back(state_name(static_cast<state>(i)));
          return names;
        },
        "The names of the states a drive reports, in the standard's order.");

  m.def("objects",
        [] {
          py::list list;
          for (std::size_t i = 0; i < drive_object_count(); ++i) list.append(describe_object(drive_object(i)));
          return list;
        },
        "The drive profile's object table (index, sub, name, unit, type, access, limits, default).");

  m.def("sdo_abort_text",
        [](std::uint32_t code) { return sdo_abort_text(static_cast<sdo_abort>(code)); },
        py::arg("code"), "The text of a CiA 301 SDO abort code.");
}

}  // namespace cia402::python
