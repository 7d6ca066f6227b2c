// cia402.sim.Machine and cia402.sim.Axis: N virtual drives (core + plant, every operation mode) on
// virtual time. A machine steps with the GIL released; per-axis objects are read and written by
// index through the simulator's object interface, whose refusals are SDO abort codes.
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cia402/objects.hpp"
#include "sim_machine.hpp"

namespace cia402::python {
namespace {

/// An integer from a Python int or anything with __index__ (numpy's integers); ArgumentError else.
std::int64_t integer_of(const py::handle& h, const char* what) {
  if (PyFloat_Check(h.ptr())) raise_argument_error(std::string(what) + " takes integers, not floats");
  PyObject* index = PyNumber_Index(h.ptr());
  if (index == nullptr) {
    PyErr_Clear();
    raise_argument_error(std::string(what) + " takes integers");
  }
  const auto owned = py::reinterpret_steal<py::int_>(index);
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(owned.ptr(), &overflow);
  if (overflow != 0) raise_argument_error(std::string(what) + ": a value beyond 64 bits");
  return v;
}

/// A C-contiguous int64 buffer (a NumPy int64 array) of 1 or 2 dimensions, viewed in place (the
/// view keeps it alive); nothing for any other object.
std::optional<py::buffer_info> int64_buffer(const py::handle& values) {
  if (!py::isinstance<py::sequence>(values) || !PyObject_CheckBuffer(values.ptr())) return std::nullopt;
  py::buffer_info b = py::reinterpret_borrow<py::buffer>(values).request();
  if (b.itemsize != 8 || (b.format != "q" && b.format != "l") || b.ndim < 1 || b.ndim > 2) return std::nullopt;
  for (py::ssize_t d = b.ndim - 1, stride = 8; d >= 0; stride *= b.shape[static_cast<std::size_t>(d)], --d) {
    if (b.strides[static_cast<std::size_t>(d)] != stride) return std::nullopt;
  }
  return b;
}

std::span<const std::int64_t> values_of(const py::buffer_info& b) {
  return {static_cast<const std::int64_t*>(b.ptr), static_cast<std::size_t>(b.size)};
}

/// Values from a scalar (one value) or a flat sequence of scalars.
std::vector<std::int64_t> values_for(const py::handle& values, const char* what) {
  if (!py::isinstance<py::sequence>(values) && PyIndex_Check(values.ptr())) {
    return std::vector<std::int64_t>(1, integer_of(values, what));
  }
  if (const auto b = int64_buffer(values); b && b->ndim == 1) {
    const auto v = values_of(*b);
    return {v.begin(), v.end()};
  }
  if (py::isinstance<py::str>(values) || !py::hasattr(values, "__iter__")) {
    raise_argument_error(std::string(what) + " takes an int or a sequence of ints");
  }
  std::vector<std::int64_t> out;
  for (const py::handle v : py::iter(values)) out.push_back(integer_of(v, what));
  return out;
}

std::uint64_t cycles_in(const machine_core& m, double ms) {
  if (!(ms >= 0) || ms > 1e12) raise_argument_error("advance takes 0 ms or more");
  const double us = ms * 1000.0;
  const auto whole = static_cast<std::uint64_t>(std::llround(us));
  const std::uint32_t cycle = m.config().cycle_us;
  if (std::fabs(us - static_cast<double>(whole)) > 1e-6 || whole % cycle != 0) {
    raise_argument_error("advance(" + std::to_string(ms) + " ms) is not a whole number of " +
                         std::to_string(cycle) + " us cycles");
  }
  return whole / cycle;
}

void advance_cycles(machine_core& m, std::uint64_t cycles) {
  machine_core::use busy(m);
  py::gil_scoped_release nogil;
  m.step_cycles(cycles);
}

py::object column(char typecode, const py::object& data) {
  return py::module_::import("cia402.sim").attr("_column")(std::string(1, typecode), data);
}

py::object int_column(const std::vector<std::int64_t>& v) {
  return column('q', py::bytes(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(std::int64_t)));
}

void stream(machine_core& m, std::int64_t index, const py::object& values, std::int64_t sub) {
  const object_key k = object_key_of(py::make_tuple(index, sub));
  // A NumPy table is read where it is; anything else is gathered into `gathered` first.
  const std::optional<py::buffer_info> table = int64_buffer(values);
  std::vector<std::int64_t> gathered;
  std::span<const std::int64_t> flat;
  std::size_t width = 0;
  if (table) {
    flat = values_of(*table);
    width = table->ndim == 1 ? 1 : static_cast<std::size_t>(table->shape[1]);
  } else {
    if (py::isinstance<py::str>(values) || !py::hasattr(values, "__iter__")) {
      raise_argument_error("stream takes a sequence of rows");
    }
    for (const py::handle row : py::iter(values)) {
      const std::vector<std::int64_t> v = values_for(row, "stream");
      if (width == 0) width = v.size();
      if (v.size() != width) raise_argument_error("stream: every row has the same number of values");
      gathered.insert(gathered.end(), v.begin(), v.end());
    }
    flat = gathered;
  }
  if (flat.empty()) return;
  if (width != 1 && width != m.size()) {
    raise_argument_error("stream: every row is one value for all axes or one per axis (" +
                         std::to_string(m.size()) + ")");
  }
  m.check_writes(k.index, k.sub, flat);
  machine_core::use busy(m);
  py::gil_scoped_release nogil;
  m.stream(k.index, k.sub, flat, width);
}

void write_all(machine_core& m, const object_key& k, const py::object& values) {
  const std::vector<std::int64_t> v = values_for(values, "write");
  if (v.size() != 1 && v.size() != m.size()) {
    raise_argument_error("write takes one value for all axes or one per axis (" + std::to_string(m.size()) + ")");
  }
  m.check_writes(k.index, k.sub, v);
  machine_core::use busy(m);
  for (std::size_t i = 0; i < m.size(); ++i) {
    check_access(m.get().drive(i).write(k.index, k.sub, v[v.size() == 1 ? 0 : i]), k.index, k.sub, "writing");
  }
}

py::object read_all(machine_core& m, const object_key& k) {
  machine_core::use busy(m);
  std::vector<std::int64_t> v(m.size());
  for (std::size_t i = 0; i < m.size(); ++i) {
    check_access(m.get().drive(i).read(k.index, k.sub, v[i]), k.index, k.sub, "reading");
  }
  return int_column(v);
}

std::int64_t axis_read(const axis_handle& a, const object_key& k) {
  machine_core::use busy(*a.machine);
  std::int64_t value = 0;
  check_access(a.view().read(k.index, k.sub, value), k.index, k.sub, "reading");
  return value;
}

void axis_write(const axis_handle& a, const object_key& k, const py::handle& value) {
  const std::int64_t v = integer_of(value, "an object's value");
  machine_core::use busy(*a.machine);
  check_access(a.view().write(k.index, k.sub, v), k.index, k.sub, "writing");
}

std::int8_t mode_argument(const py::handle& value) {
  std::int8_t m = 0;
  if (py::isinstance<py::str>(value)) {
    if (!mode::parse(value.cast<std::string>(), m)) {
      raise_argument_error("unknown mode '" + value.cast<std::string>() + "' (pp, pv, tq, hm, csp, csv, cst or a number)");
    }
    return m;
  }
  return static_cast<std::int8_t>(checked_integer(integer_of(value, "mode"), -128, 127, "mode"));
}

template <typename F>
auto with_axis(F f) {
  return [f](const axis_handle& a) {
    machine_core::use busy(*a.machine);
    return f(a.view());
  };
}

}  // namespace

void bind_axis(py::module_& sim) {
  py::class_<axis_handle>(sim, "Axis", R"doc(
One virtual drive of a Machine (it keeps the machine alive). Objects by index: axis[0x6060] = 8,
axis[0x6099, 1] for a sub-index, axis.read(0x6064); a refused access raises SdoError with its abort
code and changes nothing.)doc")
      .def("read", [](const axis_handle& a, std::int64_t index, std::int64_t sub) {
             return axis_read(a, object_key_of(py::make_tuple(index, sub)));
           }, py::arg("index"), py::arg("sub") = 0)
      .def("write", [](const axis_handle& a, std::int64_t index, const py::object& value, std::int64_t sub) {
             axis_write(a, object_key_of(py::make_tuple(index, sub)), value);
           }, py::arg("index"), py::arg("value"), py::arg("sub") = 0)
      .def("__getitem__", [](const axis_handle& a, const py::object& key) { return axis_read(a, object_key_of(key)); })
      .def("__setitem__", [](const axis_handle& a, const py::object& key, const py::object& value) {
        axis_write(a, object_key_of(key), value);
      })
      .def_readonly("index", &axis_handle::index)
      .def_property_readonly("machine", [](const axis_handle& a) { return a.machine; })
      .def_property_readonly("state", with_axis([](sim::drive_view d) { return state_name(d.current()); }))
      .def_property_readonly("outputs", with_axis([](sim::drive_view d) { return outputs_of(d); }),
                             "What the last cycle decided (Outputs).")
      .def_property_readonly("status_word", with_axis([](sim::drive_view d) { return d.outputs().status_word; }))
      .def_property("control_word", with_axis([](sim::drive_view d) { return d.control_word(); }),
                    [](const axis_handle& a, const py::object& v) { axis_write(a, {object_index::control_word, 0}, v); },
                    "0x6040: what the next cycle reads.")
      .def_property_readonly("error_code", with_axis([](sim::drive_view d) { return d.outputs().error_code; }))
      .def_property("mode", with_axis([](sim::drive_view d) { return d.operation_mode(); }),
                    [](const axis_handle& a, const py::object& v) {
                      axis_write(a, {object_index::modes_of_operation, 0}, py::int_(mode_argument(v)));
                    },
                    "0x6061, the mode running; set it (0x6060) by number or short name: 'pp', 'pv', 'csp', ...")
      .def_property_readonly("velocity_rpm", with_axis([](sim::drive_view d) {
                               return static_cast<double>(d.velocity_micro_rpm()) / 1e6;
                             }), "The actual velocity, exact (0x606C is this rounded towards zero).")
      .def_property_readonly("position", with_axis([](sim::drive_view d) { return d.position(); }), "0x6064")
      .def_property_readonly("position_demand", with_axis([](sim::drive_view d) { return d.position_demand(); }), "0x6062")
      .def_property_readonly("following_error", with_axis([](sim::drive_view d) { return d.following_error(); }), "0x60F4")
      .def_property_readonly("torque_permille", with_axis([](sim::drive_view d) { return d.torque(); }), "0x6077")
      .def_property_readonly("digital_inputs", with_axis([](sim::drive_view d) { return d.digital_inputs(); }), "0x60FD")
      .def_property_readonly("brake_engaged", with_axis([](sim::drive_view d) { return d.brake_engaged(); }))
      .def_property_readonly("homing_phase", with_axis([](sim::drive_view d) {
                               return motion::homing_phase_name(d.homing_phase());
                             }), "What a homing run is doing, in words.")
      .def_property("sto", with_axis([](sim::drive_view d) { return d.sto(); }),
                    [](const axis_handle& a, bool on) { machine_core::use busy(*a.machine); a.view().set_sto(on); },
                    "Safe torque off active.")
      .def_property("dc_link", with_axis([](sim::drive_view d) { return d.dc_link(); }),
                    [](const axis_handle& a, bool on) { machine_core::use busy(*a.machine); a.view().set_dc_link(on); },
                    "DC-link (main) voltage present.")
      .def_property("connection_lost", with_axis([](sim::drive_view d) { return d.connection_lost(); }),
                    [](const axis_handle& a, bool on) {
                      machine_core::use busy(*a.machine);
                      a.view().set_connection_lost(on);
                    },
                    "The fieldbus connection is lost (0x6007 decides what the drive does).")
      .def_property_readonly("fault_cause", with_axis([](sim::drive_view d) { return d.fault_cause(); }),
                             "The fault cause the drive sees (the newest), 0 if none.")
      .def("inject_fault", [](const axis_handle& a, std::int64_t code, std::int64_t error_class) {
             const auto c = static_cast<std::uint16_t>(checked_integer(code, 1, 0xFFFF, "fault code"));
             const auto k = static_cast<std::uint8_t>(checked_integer(error_class, 0, 4, "error_class"));
             machine_core::use busy(*a.machine);
             return a.view().inject_fault(c, k);
           }, py::arg("code") = 0x1000, py::arg("error_class") = 2,
           "A fault cause appears (error code, class 0..4). False when the oldest of 4 causes was dropped.")
      .def("clear_fault", [](const axis_handle& a, std::optional<std::int64_t> code) {
             machine_core::use busy(*a.machine);
             if (!code) {
               a.view().clear_faults();
               return true;
             }
             return a.view().clear_fault(static_cast<std::uint16_t>(checked_integer(*code, 1, 0xFFFF, "fault code")));
           }, py::arg("code") = py::none(), "The cause with this code (every cause when None) is gone.")
      .def("record", [](const axis_handle& a, bool on) {
             machine_core::use busy(*a.machine);
             a.machine->record(a.index, on);
           }, py::arg("on") = true, "Starts (or stops) recording this axis's cycles for trace().")
      .def("trace", [](const axis_handle& a) { return std::const_pointer_cast<trace_data>(a.machine->trace(a.index)); },
           "What this axis recorded (a Trace).")
      .def("__repr__", [](const axis_handle& a) {
        machine_core::use busy(*a.machine);
        return "cia402.sim.Axis(" + std::to_string(a.index) + ", state='" + state_name(a.view().current()) + "')";
      });
}

void bind_sim(py::module_& sim) {
  bind_axis(sim);
  py::class_<machine_core, machine_ptr>(sim, "Machine", R"doc(
N virtual drives (the core plus a plant: motor in every operation mode, brake, DC link, STO)
sharing one profile and one plant, on virtual time. `plant` takes plant_config's keys (cycle_us,
brake_fitted, brake_engage_delay_us, ..., see `Machine().plant`). `trace` lists the axes to record
from the start (True: all). advance() and stream() run with the GIL released.)doc")
      .def(py::init([](std::int64_t axes, const py::object& profile, const py::object& plant, std::int64_t threads,
                       const py::object& trace) {
             machine_ptr m = make_machine(axes, profile, plant, threads);
             if (py::isinstance<py::bool_>(trace)) {
               if (trace.cast<bool>()) {
                 for (std::size_t i = 0; i < m->size(); ++i) m->record(i, true);
               }
             } else if (!trace.is_none()) {
               for (const py::handle i : py::iter(trace)) m->record(m->checked_axis(integer_of(i, "trace")), true);
             }
             return m;
           }),
           py::arg("axes") = 1, py::arg("profile") = "cia402", py::arg("plant") = py::none(),
           py::arg("threads") = 1, py::arg("trace") = py::none())
      .def("advance", [](machine_core& m, double ms) { advance_cycles(m, cycles_in(m, ms)); }, py::arg("ms"),
           "Runs the machine for `ms` milliseconds of virtual time (a whole number of cycles).")
      .def("step", [](machine_core& m, std::int64_t cycles) {
             advance_cycles(m, static_cast<std::uint64_t>(checked_integer(cycles, 0, INT64_MAX, "cycles")));
           }, py::arg("cycles") = 1, "Runs this many cycles.")
      .def("stream", &stream, py::arg("index"), py::arg("values"), py::arg("sub") = 0, R"doc(
One cycle per row of `values`, writing the row to index:sub of every axis before its cycle (a
cyclic master's set-point before SYNC): each row one value for all axes or one per axis; a 2-D
NumPy int64 array is taken as it is. Every value is checked first: a refused one raises SdoError
before any cycle runs.)doc")
      .def("write", [](machine_core& m, std::int64_t index, const py::object& values, std::int64_t sub) {
             write_all(m, object_key_of(py::make_tuple(index, sub)), values);
           }, py::arg("index"), py::arg("values"), py::arg("sub") = 0,
           "Writes one value to every axis, or one value per axis; checked first, so a refusal changes nothing.")
      .def("read", [](machine_core& m, std::int64_t index, std::int64_t sub) {
             return read_all(m, object_key_of(py::make_tuple(index, sub)));
           }, py::arg("index"), py::arg("sub") = 0,
           "The object's value on every axis (a NumPy int64 array where NumPy is installed, else a list).")
      .def("states", [](machine_core& m) {
             machine_core::use busy(m);
             py::list names;
             for (std::size_t i = 0; i < m.size(); ++i) names.append(state_name(m.get().drive(i).current()));
             return column('U', names);
           }, "Every axis's state name.")
      .def("axis", [](const machine_ptr& m, std::int64_t i) { return axis_handle{m, m->checked_axis(i)}; },
           py::arg("i"))
      .def("__len__", &machine_core::size)
      .def("__iter__", [](const machine_ptr& m) {
        py::list axes;
        for (std::size_t i = 0; i < m->size(); ++i) axes.append(axis_handle{m, i});
        return py::iter(axes);
      }, "The axes, in order.")
      .def("__getitem__", [](const machine_ptr& m, std::int64_t i) { return axis_handle{m, m->checked_axis(i)}; })
      .def("record", [](machine_core& m, std::int64_t axis, bool on) {
             machine_core::use busy(m);
             m.record(m.checked_axis(axis), on);
           }, py::arg("axis"), py::arg("on") = true, "Starts (or stops) recording an axis's cycles.")
      .def("trace", [](machine_core& m, std::int64_t axis) {
             machine_core::use busy(m);
             return std::const_pointer_cast<trace_data>(m.trace(m.checked_axis(axis)));
           }, py::arg("axis") = 0, "What an axis recorded, one row per cycle (a Trace).")
      .def("clear_trace", [](machine_core& m, std::int64_t axis) {
             machine_core::use busy(m);
             m.clear_trace(m.checked_axis(axis));
           }, py::arg("axis"))
      .def_property_readonly("cycle", [](const machine_core& m) { return m.get().cycle(); }, "Cycles run so far.")
      .def_property_readonly("time_us", [](const machine_core& m) { return m.get().time_us(); },
                             "The virtual time of the next cycle, in microseconds.")
      .def_property_readonly("cycle_us", [](const machine_core& m) { return m.config().cycle_us; })
      .def_property_readonly("threads", [](const machine_core& m) { return m.get().threads(); })
      .def_property_readonly("profile", [](const machine_core& m) { return std::const_pointer_cast<profile_handle>(m.table()); })
      .def_property_readonly("plant", [](const machine_core& m) { return plant_config_dict(m.config()); },
                             "The plant's settings, every key.")
      .def("__repr__", [](const machine_core& m) {
        return "cia402.sim.Machine(axes=" + std::to_string(m.size()) + ", profile='" + m.table()->get().name +
               "', time_us=" + std::to_string(m.get().time_us()) + ")";
      });
}

}  // namespace cia402::python
