// The package's exceptions, raised from C++ results. The classes are Python's (cia402/_errors.py),
// so they carry attributes a caller reads (code, text, line, ...) and pickle like any exception.
#include <stdexcept>
#include <string>

#include "binding.hpp"
#include "cia402/profile_file.hpp"
#include "cia402/sim/scenario.hpp"

namespace cia402::python {
namespace {

py::object error_class(const char* name) {
  return py::module_::import("cia402._errors").attr(name);
}

[[noreturn]] void raise_instance(const py::object& exception) {
  PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(exception.ptr())), exception.ptr());
  throw py::error_already_set();
}

[[noreturn]] void raise_message(const char* cls, const std::string& message) {
  raise_instance(error_class(cls)(message));
}

}  // namespace

void raise_sdo_error(sdo_abort code, std::uint16_t index, std::uint8_t sub,
                     std::string_view action) {
  raise_instance(error_class("SdoError")(static_cast<std::uint32_t>(code), sdo_abort_text(code),
                                         index, sub, std::string(action)));
}

void raise_argument_error(const std::string& message) { raise_message("ArgumentError", message); }

void raise_busy_error(const std::string& message) { raise_message("BusyError", message); }

void raise_profile_error(const profile_file_error& e) {
  raise_instance(error_class("ProfileError")(e.line, e.column, e.reason, e.source_name, e.message()));
}

void raise_profile_error(const std::string& message) {
  raise_instance(error_class("ProfileError")(0, 0, message, "", message));
}

void raise_scenario_error(const sim::scenario_error& e) {
  raise_instance(error_class("ScenarioError")(e.line, e.column, e.reason, e.source_name, e.message()));
}

object_key object_key_of(const py::handle& key) {
  object_key k;
  py::handle index = key;
  if (py::isinstance<py::tuple>(key)) {
    const auto t = py::reinterpret_borrow<py::tuple>(key);
    if (t.size() != 2) raise_argument_error("an object key is INDEX or (INDEX, SUB)");
    index = t[0];
    if (!py::isinstance<py::int_>(t[1])) raise_argument_error("a sub-index is an int 0..255");
    k.sub = static_cast<std::uint8_t>(checked_integer(t[1].cast<std::int64_t>(), 0, 255, "sub-index"));
  }
  if (!py::isinstance<py::int_>(index)) raise_argument_error("an object index is an int 0..0xFFFF");
  k.index = static_cast<std::uint16_t>(checked_integer(index.cast<std::int64_t>(), 0, 0xFFFF, "index"));
  return k;
}

std::int64_t checked_integer(std::int64_t value, std::int64_t low, std::int64_t high,
                             std::string_view what) {
  if (value < low || value > high) {
    raise_argument_error(std::string(what) + " " + std::to_string(value) + " is not in " +
                         std::to_string(low) + ".." + std::to_string(high));
  }
  return value;
}

state state_argument(std::string_view name) {
  state s;
  if (parse_state(name, s) && s != state::start) return s;
  std::string message = "unknown state '" + std::string(name) + "'; the states are";
  for (int i = 1; i < state_count; ++i) {
    const auto each = static_cast<state>(i);
    message += std::string(i == 1 ? " " : ", ") + state_name(each) + " (" +
               state_abbreviation(each) + ")";
  }
  raise_argument_error(message);
}

void bind_errors(py::module_&) {
  // A plant configuration a constructor refuses (std::invalid_argument, sim/plant.hpp) is an
  // argument the package refuses; every other C++ exception keeps pybind11's mapping.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(error_class("ArgumentError").ptr(), e.what());
    }
  });
}

}  // namespace cia402::python
