// cia402.sim.Trace (what an axis recorded, by column; the CSV, JSONL, VCD and SVG the simulator
// writes) and scenarios from TOML: loaded, run with the GIL released, their log, expectations and
// trace.
#include <pybind11/stl.h>

#include <cstring>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "cia402/sim/scenario.hpp"
#include "sim_machine.hpp"

namespace cia402::python {
namespace {

/// One column of a trace: its name (the CSV's), how Python gets it ('q' int64, 'd' float64, '?'
/// bool, 'U' str) and its value in a row.
struct trace_column {
  const char* name;
  char typecode;
  std::variant<std::int64_t (*)(const sim::trace_row&), double (*)(const sim::trace_row&),
               bool (*)(const sim::trace_row&), const char* (*)(const sim::trace_row&)>
      value;
};

using row = sim::trace_row;
const trace_column trace_columns[] = {
    {"time_us", 'q', +[](const row& r) { return static_cast<std::int64_t>(r.time_us); }},
    {"controlword", 'q', +[](const row& r) { return std::int64_t{r.control_word}; }},
    {"statusword", 'q', +[](const row& r) { return std::int64_t{r.status_word}; }},
    {"state", 'U', +[](const row& r) { return state_name(r.current); }},
    {"transition", 'q', +[](const row& r) {
       return r.transition == no_transition ? std::int64_t{-1} : std::int64_t{r.transition};
     }},
    {"velocity_rpm", 'd', +[](const row& r) { return static_cast<double>(r.velocity) / 1e6; }},
    {"target_rpm", 'q', +[](const row& r) { return std::int64_t{r.target_velocity}; }},
    {"torque", '?', +[](const row& r) { return r.torque; }},
    {"brake_released", '?', +[](const row& r) { return r.brake_released; }},
    {"brake_engaged", '?', +[](const row& r) { return r.brake_engaged; }},
    {"ramp", 'U', +[](const row& r) { return stop_ramp_name(r.ramp); }},
    {"error_code", 'q', +[](const row& r) { return std::int64_t{r.error_code}; }},
    {"fault_cause", 'q', +[](const row& r) { return std::int64_t{r.fault_cause}; }},
    {"dc_link", '?', +[](const row& r) { return r.dc_link; }},
    {"sto", '?', +[](const row& r) { return r.sto; }},
    {"position", 'q', +[](const row& r) { return r.position; }},
    {"position_demand", 'q', +[](const row& r) { return r.position_demand; }},
    {"torque_permille", 'q', +[](const row& r) { return std::int64_t{r.torque_permille}; }},
    {"mode", 'q', +[](const row& r) { return std::int64_t{r.mode}; }},
    {"digital_inputs", 'q', +[](const row& r) { return std::int64_t{r.digital_inputs}; }},
};

template <typename T>
py::bytes packed(const std::vector<sim::trace_row>& rows, T (*value)(const sim::trace_row&)) {
  std::string bytes(rows.size() * sizeof(T), '\0');
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const T v = value(rows[i]);
    std::memcpy(bytes.data() + i * sizeof(T), &v, sizeof(T));
  }
  return py::bytes(bytes);
}

py::object column_of(const trace_data& t, const trace_column& c) {
  py::object data = std::visit(
      [&](auto value) -> py::object {
        using result = decltype(value(std::declval<const sim::trace_row&>()));
        if constexpr (std::is_same_v<result, const char*>) {
          py::list names;
          for (const auto& r : t.rows) names.append(value(r));
          return names;
        } else {
          return packed(t.rows, value);
        }
      },
      c.value);
  return py::module_::import("cia402.sim").attr("_column")(std::string(1, c.typecode), data);
}

const trace_column& find_column(const std::string& name) {
  for (const trace_column& c : trace_columns) {
    if (name == c.name) return c;
  }
  raise_argument_error("no trace column '" + name + "' (the columns: " + names_of(trace_columns) + ")");
}

template <typename Write>
std::string written(Write write) {
  std::ostringstream out;
  write(out);
  return out.str();
}

using scenario_ptr = std::shared_ptr<const sim::scenario>;

scenario_ptr loaded(sim::scenario_load_result result) {
  if (const auto* e = std::get_if<sim::scenario_error>(&result)) raise_scenario_error(*e);
  return std::make_shared<const sim::scenario>(std::move(std::get<sim::scenario>(result)));
}

/// A scenario's run, as `ScenarioResult`.
struct scenario_outcome {
  sim::run_result result;
  std::shared_ptr<trace_data> trace;  ///< null when the trace was not recorded
};

std::shared_ptr<scenario_outcome> run(const scenario_ptr& s, bool record_trace) {
  auto outcome = std::make_shared<scenario_outcome>();
  {
    py::gil_scoped_release nogil;
    outcome->result = sim::run_scenario(*s, {record_trace});
  }
  if (record_trace) {
    outcome->trace = std::make_shared<trace_data>();
    outcome->trace->rows = std::move(outcome->result.trace);
    outcome->result.trace.clear();
    outcome->trace->info.title = s->name;
    outcome->trace->info.profile_name = s->drive_profile.get().name;
    outcome->trace->info.cycle_us = s->plant.cycle_us;
    outcome->trace->info.brake_fitted = s->plant.brake_fitted;
  }
  return outcome;
}

const char* log_kind_name(sim::log_entry::kind k) {
  switch (k) {
    case sim::log_entry::kind::event: return "event";
    case sim::log_entry::kind::transition: return "transition";
    case sim::log_entry::kind::expectation: return "expectation";
    case sim::log_entry::kind::note: return "note";
  }
  return "note";
}

py::list entries(const scenario_outcome& o, bool expectations_only, bool failed_only) {
  py::list list;
  for (const sim::log_entry& e : o.result.log) {
    if (expectations_only && e.what != sim::log_entry::kind::expectation) continue;
    if (failed_only && !e.failed) continue;
    list.append(e);
  }
  return list;
}

scenario_ptr scenario_argument(const py::object& value) {
  if (py::isinstance<sim::scenario>(value)) return value.cast<std::shared_ptr<sim::scenario>>();
  const std::string path = py::str(py::module_::import("os").attr("fspath")(value));
  return loaded(sim::load_scenario_file(path));
}

}  // namespace

void bind_sim_traces(py::module_& sim) {
  py::class_<trace_data, std::shared_ptr<trace_data>>(sim, "Trace", R"doc(
One axis's recorded cycles, by column: trace["velocity_rpm"] is a NumPy array where NumPy is
installed, else a list. The columns are the CSV's (docs/simulator.md): time_us, controlword,
statusword, state, transition (-1: none), velocity_rpm (exact micro-rpm as float), target_rpm,
torque, brake_released, brake_engaged, ramp, error_code, fault_cause, dc_link, sto, position,
position_demand, torque_permille, mode, digital_inputs (0x60FD).)doc")
      .def_property_readonly_static("columns", [](const py::object&) {
        std::vector<std::string> names;
        for (const trace_column& c : trace_columns) names.emplace_back(c.name);
        return py::tuple(py::cast(names));
      })
      .def("__len__", [](const trace_data& t) { return t.rows.size(); })
      .def("__iter__", [](const trace_data&) {
        py::list names;
        for (const trace_column& c : trace_columns) names.append(c.name);
        return py::iter(names);
      }, "The column names, as a mapping's keys.")
      .def("__getitem__", [](const trace_data& t, const std::string& name) { return column_of(t, find_column(name)); })
      .def("__contains__", [](const trace_data&, const std::string& name) {
        for (const trace_column& c : trace_columns) {
          if (name == c.name) return true;
        }
        return false;
      })
      .def("as_dict", [](const trace_data& t) {
        py::dict d;
        for (const trace_column& c : trace_columns) d[c.name] = column_of(t, c);
        return d;
      }, "Every column by name.")
      .def("to_csv", [](const trace_data& t, std::size_t every) {
        return written([&](std::ostream& o) { sim::write_csv(o, t.rows, every); });
      }, py::arg("every") = 1, "The CSV `cia402 simulate --trace out.csv` writes (every: keep every N-th row and each change).")
      .def("to_jsonl", [](const trace_data& t, std::size_t every) {
        return written([&](std::ostream& o) { sim::write_jsonl(o, t.rows, every); });
      }, py::arg("every") = 1, "JSON Lines, one object a row.")
      .def("to_vcd", [](const trace_data& t, bool standard) {
        sim::trace_info info = t.info;
        info.vcd_standard = standard;
        return written([&](std::ostream& o) { sim::write_vcd(o, t.rows, info); });
      }, py::arg("standard") = false, "A value change dump for GTKWave (standard: IEEE 1364 only).")
      .def("to_svg", [](const trace_data& t) {
        return written([&](std::ostream& o) { sim::write_svg_plot(o, t.rows, t.info); });
      }, "The SVG plot `cia402 simulate --plot` draws.")
      .def_property_readonly("title", [](const trace_data& t) { return t.info.title; })
      .def_property_readonly("profile", [](const trace_data& t) { return t.info.profile_name; })
      .def_property_readonly("cycle_us", [](const trace_data& t) { return t.info.cycle_us; })
      .def("__repr__", [](const trace_data& t) {
        return "cia402.sim.Trace('" + t.info.title + "', " + std::to_string(t.rows.size()) + " rows)";
      });

  py::class_<sim::log_entry>(sim, "LogEntry", "One line of a scenario's log.")
      .def_readonly("time_us", &sim::log_entry::time_us)
      .def_property_readonly("kind", [](const sim::log_entry& e) { return log_kind_name(e.what); },
                             "'event', 'transition', 'expectation' or 'note'.")
      .def_readonly("failed", &sim::log_entry::failed)
      .def_readonly("text", &sim::log_entry::text)
      .def("__str__", &sim::format_log_entry, "The line as `cia402 simulate` prints it.")
      .def("__repr__", [](const sim::log_entry& e) { return "LogEntry(" + sim::format_log_entry(e) + ")"; });

  py::class_<scenario_outcome, std::shared_ptr<scenario_outcome>>(sim, "ScenarioResult", "What a scenario's run found.")
      .def_property_readonly("passed", [](const scenario_outcome& o) { return o.result.passed(); })
      .def_property_readonly("checks", [](const scenario_outcome& o) { return o.result.checks; })
      .def_property_readonly("failures", [](const scenario_outcome& o) { return o.result.failures; })
      .def_property_readonly("log", [](const scenario_outcome& o) { return entries(o, false, false); })
      .def_property_readonly("expectations", [](const scenario_outcome& o) { return entries(o, true, false); },
                             "The log's expectation lines, each with .failed.")
      .def_property_readonly("failed", [](const scenario_outcome& o) { return entries(o, false, true); },
                             "Every line that failed (expectations, and events that did not go as written).")
      .def_property_readonly("trace", [](const scenario_outcome& o) -> py::object {
        if (!o.trace) return py::none();
        return py::cast(o.trace);
      })
      .def("__bool__", [](const scenario_outcome& o) { return o.result.passed(); })
      .def("__repr__", [](const scenario_outcome& o) {
        return std::string("ScenarioResult(passed=") + (o.result.passed() ? "True" : "False") +
               ", checks=" + std::to_string(o.result.checks) + ", failures=" + std::to_string(o.result.failures) + ")";
      });

  py::class_<sim::scenario, std::shared_ptr<sim::scenario>>(sim, "Scenario", R"doc(
A simulator scenario (examples/scenarios/README.md): a drive, timed events and expectations, read
from TOML and checked; a refused file raises ScenarioError with the line and reason.)doc")
      .def_static("from_file", [](const py::object& path) { return std::const_pointer_cast<sim::scenario>(scenario_argument(path)); },
                  py::arg("path"))
      .def_static("from_toml", [](const std::string& text, const std::string& source, const std::string& base_dir) {
                    return std::const_pointer_cast<sim::scenario>(loaded(sim::load_scenario_toml(text, source, base_dir)));
                  },
                  py::arg("text"), py::arg("source") = "<scenario>", py::arg("base_dir") = ".",
                  "`base_dir` resolves a relative profile_file.")
      .def_readonly("name", &sim::scenario::name)
      .def_readonly("source", &sim::scenario::source_name)
      .def_property_readonly("profile", [](const sim::scenario& s) { return s.drive_profile.get().name; })
      .def_property_readonly("cycle_us", [](const sim::scenario& s) { return s.plant.cycle_us; })
      .def_readonly("cycles", &sim::scenario::cycles, "Cycles run: at 0, one cycle, ..., the duration.")
      .def("run", [](const std::shared_ptr<sim::scenario>& s, bool trace) { return run(s, trace); },
           py::arg("trace") = true, "Runs it on a fresh virtual drive; a ScenarioResult.")
      .def("__repr__", [](const sim::scenario& s) { return "cia402.sim.Scenario('" + s.name + "')"; });

  sim.def("load_scenario", [](const py::object& path) { return std::const_pointer_cast<sim::scenario>(scenario_argument(path)); },
          py::arg("path"), "Reads a scenario file; ScenarioError with the line and reason.");
  sim.def("run_scenario", [](const py::object& scenario, bool trace) { return run(scenario_argument(scenario), trace); },
          py::arg("scenario"), py::arg("trace") = true,
          "Runs a scenario (a Scenario or a file's path) and returns its ScenarioResult.");
}

}  // namespace cia402::python
