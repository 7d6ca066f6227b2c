// cia402.Drive: the core (cia402::drive's step, option codes) on an ideal plant whose inputs the
// caller gives by keyword, or on the simulator's plant (a one-axis sim::machine). And Outputs, what
// a step decided, which a machine's axes report too.
#include <pybind11/stl.h>

#include <cstdio>
#include <iterator>
#include <optional>
#include <string>
#include <variant>

#include "binding.hpp"
#include "cia402/master.hpp"
#include "cia402/objects.hpp"
#include "cia402/replay.hpp"
#include "sim_machine.hpp"

namespace cia402::python {
namespace {

/// The keyword inputs of Drive.step / Drive.settle: each given one changes that input, the others
/// keep their value (the inputs hold, as a plant's do).
struct input_args {
  std::optional<std::int64_t> control_word;
  std::optional<bool> dc_link;
  std::optional<bool> sto;
  std::optional<std::int64_t> fault;
  std::optional<std::int64_t> fault_class;
  std::optional<bool> standstill;
  std::optional<bool> brake_engaged;
  std::optional<bool> remote;
  std::optional<bool> connection_lost;
  std::optional<bool> local_enable;
  std::optional<bool> local_disable;
  std::optional<std::int64_t> status_bits;
  std::optional<std::int64_t> actual_speed_rpm;
};

// The keyword inputs by name. A call site's keyword is the interned string of its name, so a
// lookup is mostly a pointer comparison: a step with a keyword costs little more than one without
// (pybind11's own keyword matching looks every declared name up in the call's dict).
struct input_keyword {
  const char* name;
  std::variant<std::optional<std::int64_t> input_args::*, std::optional<bool> input_args::*> member;
};
const input_keyword input_keywords[] = {
    {"control_word", &input_args::control_word},
    {"dc_link", &input_args::dc_link},
    {"sto", &input_args::sto},
    {"fault", &input_args::fault},
    {"fault_class", &input_args::fault_class},
    {"standstill", &input_args::standstill},
    {"brake_engaged", &input_args::brake_engaged},
    {"remote", &input_args::remote},
    {"connection_lost", &input_args::connection_lost},
    {"local_enable", &input_args::local_enable},
    {"local_disable", &input_args::local_disable},
    {"status_bits", &input_args::status_bits},
    {"actual_speed_rpm", &input_args::actual_speed_rpm},
};
constexpr std::size_t input_keyword_count = std::size(input_keywords);

[[noreturn]] void raise_type_error(const std::string& message) {
  PyErr_SetString(PyExc_TypeError, message.c_str());
  throw py::error_already_set();
}

std::size_t keyword_of(PyObject* key, const char* function) {
  static PyObject* interned[input_keyword_count] = {};
  if (interned[0] == nullptr) {
    for (std::size_t i = 0; i < input_keyword_count; ++i) interned[i] = PyUnicode_InternFromString(input_keywords[i].name);
  }
  for (std::size_t i = 0; i < input_keyword_count; ++i) {
    if (key == interned[i]) return i;
  }
  for (std::size_t i = 0; i < input_keyword_count; ++i) {
    if (PyUnicode_Check(key) && PyUnicode_CompareWithASCIIString(key, input_keywords[i].name) == 0) return i;
  }
  raise_type_error(std::string(function) + "() got an unexpected keyword argument '" + py::str(key).cast<std::string>() + "'");
}

input_args parse_inputs(const py::kwargs& kwargs, const char* function) {
  input_args a;
  PyObject* key = nullptr;
  PyObject* value = nullptr;
  Py_ssize_t at = 0;
  while (PyDict_Next(kwargs.ptr(), &at, &key, &value)) {
    const input_keyword& k = input_keywords[keyword_of(key, function)];
    if (value == Py_None) continue;
    std::visit(
        [&](auto member) {
          using type = typename std::remove_reference_t<decltype(a.*member)>::value_type;
          if constexpr (std::is_same_v<type, bool>) {
            if (!PyBool_Check(value)) raise_type_error(std::string(function) + "(): " + k.name + " takes True or False");
            a.*member = value == Py_True;
          } else {
            if (PyFloat_Check(value) || !PyIndex_Check(value)) {
              raise_type_error(std::string(function) + "(): " + k.name + " takes an int");
            }
            const auto number = py::reinterpret_steal<py::object>(PyNumber_Index(value));
            int overflow = 0;
            const long long v = PyLong_AsLongLongAndOverflow(number.ptr(), &overflow);
            if (overflow != 0) raise_argument_error(std::string(k.name) + " is beyond 64 bits");
            a.*member = v;
          }
        },
        k.member);
  }
  return a;
}

// The objects an ideal drive answers besides its option codes: its control-word input and what
// its last step decided.
constexpr std::uint16_t error_register_index = 0x1001;

class drive_core {
 public:
  drive_core(profile_ptr p, const py::object& plant)
      : profile_(std::move(p)), axis_(make_axis(profile_->get())) {
    if (!plant.is_none() && !(py::isinstance<py::bool_>(plant) && !plant.cast<bool>())) {
      const py::object settings = py::isinstance<py::bool_>(plant) ? py::object(py::none()) : plant;
      plant_ = make_machine(1, py::cast(std::const_pointer_cast<profile_handle>(profile_)), settings, 1);
    }
  }

  step_outputs step(const input_args& in) {
    if (plant_) {
      apply_to_plant(in);
      machine_core::use busy(*plant_);
      plant_->step_cycles(1);
      return outputs_of(plant_->get().drive(0));
    }
    inputs_ = ideal_inputs(in);
    last_ = cia402::step(profile_->get(), axis_, inputs_);
    stepped_ = true;
    step_outputs o;
    o.out = last_;
    if (last_.transition != no_transition) o.transitions.push_back(last_.transition);
    return o;
  }

  step_outputs settle(const input_args& in) {
    if (plant_) {
      raise_argument_error("settle() runs the ideal plant; on a simulated plant step() or "
                           "machine.advance(ms) let it move");
    }
    inputs_ = ideal_inputs(in);
    const settle_result r = cia402::settle(profile_->get(), axis_, inputs_, stepped_ ? &last_ : nullptr);
    last_ = r.last;
    stepped_ = true;
    return {r.last, r.transitions, r.settled};
  }

  std::int64_t read(const object_key& k) const {
    if (plant_) {
      machine_core::use busy(*plant_);
      std::int64_t value = 0;
      check_access(plant_->get().drive(0).read(k.index, k.sub, value), k.index, k.sub, "reading");
      return value;
    }
    if (const auto fixed = ideal_object(k.index)) {
      check_access(k.sub != 0 ? sdo_abort::sub_index_does_not_exist : sdo_abort::none, k.index, k.sub, "reading");
      return *fixed;
    }
    std::int32_t value = 0;
    check_access(k.sub != 0 && option_object(k.index) ? sdo_abort::sub_index_does_not_exist
                                                       : read_option(profile_->get(), axis_, k.index, value),
                 k.index, k.sub, "reading");
    return value;
  }

  void write(const object_key& k, std::int64_t value) {
    if (plant_) {
      machine_core::use busy(*plant_);
      check_access(plant_->get().drive(0).write(k.index, k.sub, value), k.index, k.sub, "writing");
      return;
    }
    sdo_abort result = sdo_abort::none;
    if (k.index == object_index::control_word) {
      result = k.sub != 0 ? sdo_abort::sub_index_does_not_exist
               : value < 0 ? sdo_abort::value_too_low
               : value > 0xFFFF ? sdo_abort::value_too_high
                                : sdo_abort::none;
      if (result == sdo_abort::none) inputs_.control_word = static_cast<std::uint16_t>(value);
    } else if (ideal_object(k.index)) {
      result = k.sub != 0 ? sdo_abort::sub_index_does_not_exist : sdo_abort::read_only_object;
    } else if (k.sub != 0 && option_object(k.index)) {
      result = sdo_abort::sub_index_does_not_exist;
    } else if (value < INT32_MIN || value > INT32_MAX) {
      result = option_object(k.index) ? (value < 0 ? sdo_abort::value_too_low : sdo_abort::value_too_high)
                                      : sdo_abort::object_does_not_exist;
    } else {
      result = write_option(profile_->get(), axis_, k.index, static_cast<std::int32_t>(value));
    }
    check_access(result, k.index, k.sub, "writing");
  }

  py::dict inputs() const {
    std::optional<machine_core::use> busy;
    if (plant_) busy.emplace(*plant_);
    const drive_inputs in = plant_ ? plant_->get().drive(0).inputs() : inputs_;
    py::dict d;
    d["control_word"] = plant_ ? plant_->get().drive(0).control_word() : in.control_word;
    d["dc_link"] = in.dc_link;
    d["sto"] = in.sto;
    d["fault"] = in.fault_code;
    d["fault_class"] = in.fault_class;
    d["standstill"] = in.standstill;
    d["brake_engaged"] = in.brake_engaged;
    d["remote"] = in.remote;
    d["connection_lost"] = in.connection_lost;
    d["local_enable"] = in.local_enable;
    d["local_disable"] = in.local_disable;
    d["status_bits"] = in.status_bits;
    d["actual_speed_rpm"] = in.actual_speed_rpm;
    return d;
  }

  step_outputs last() const {
    if (plant_) {
      machine_core::use busy(*plant_);
      return outputs_of(plant_->get().drive(0));
    }
    step_outputs o;
    o.out = last_;
    if (last_.transition != no_transition) o.transitions.push_back(last_.transition);
    return o;
  }

  const axis& core_axis() const { return plant_ ? plant_->get().axis_at(0).core : axis_; }
  const profile_ptr& table() const noexcept { return profile_; }
  const machine_ptr& plant() const noexcept { return plant_; }

 private:
  static bool option_object(std::uint16_t index) {
    option o;
    return option_of_index(index, o);
  }

  std::optional<std::int64_t> ideal_object(std::uint16_t index) const {
    switch (index) {
      case object_index::control_word: return inputs_.control_word;
      case object_index::status_word: return last_.status_word;
      case object_index::error_code: return axis_.error_code;
      case error_register_index: return error_register_of(axis_.error_code);
      default: return std::nullopt;
    }
  }

  // Every argument is checked before any input changes.
  drive_inputs ideal_inputs(const input_args& a) const {
    drive_inputs in = inputs_;
    if (a.control_word) in.control_word = static_cast<std::uint16_t>(checked_integer(*a.control_word, 0, 0xFFFF, "control_word"));
    if (a.fault) in.fault_code = static_cast<std::uint16_t>(checked_integer(*a.fault, 0, 0xFFFF, "fault"));
    if (a.fault_class) in.fault_class = static_cast<std::uint8_t>(checked_integer(*a.fault_class, 0, 4, "fault_class"));
    if (a.status_bits) in.status_bits = static_cast<std::uint16_t>(checked_integer(*a.status_bits, 0, 0xFFFF, "status_bits"));
    if (a.actual_speed_rpm) {
      in.actual_speed_rpm = static_cast<std::int32_t>(checked_integer(*a.actual_speed_rpm, INT32_MIN, INT32_MAX, "actual_speed_rpm"));
    }
    if (a.dc_link) in.dc_link = *a.dc_link;
    if (a.sto) in.sto = *a.sto;
    if (a.standstill) in.standstill = *a.standstill;
    if (a.brake_engaged) in.brake_engaged = *a.brake_engaged;
    if (a.remote) in.remote = *a.remote;
    if (a.connection_lost) in.connection_lost = *a.connection_lost;
    if (a.local_enable) in.local_enable = *a.local_enable;
    if (a.local_disable) in.local_disable = *a.local_disable;
    return in;
  }

  void apply_to_plant(const input_args& a) {
    const char* plant_given = a.standstill ? "standstill" : a.brake_engaged ? "brake_engaged"
                              : a.status_bits ? "status_bits" : a.actual_speed_rpm ? "actual_speed_rpm"
                              : a.remote ? "remote" : a.local_enable ? "local_enable"
                              : a.local_disable ? "local_disable" : nullptr;
    if (plant_given) {
      raise_argument_error(std::string("the simulated plant gives '") + plant_given +
                           "' itself; a Drive without a plant takes it as an input");
    }
    const auto word = a.control_word ? std::optional(checked_integer(*a.control_word, 0, 0xFFFF, "control_word")) : std::nullopt;
    const auto code = a.fault ? std::optional(checked_integer(*a.fault, 0, 0xFFFF, "fault")) : std::nullopt;
    const auto error_class = checked_integer(a.fault_class.value_or(2), 0, 4, "fault_class");
    machine_core::use busy(*plant_);
    sim::drive_view d = plant_->get().drive(0);
    if (word) d.write(object_index::control_word, 0, *word);
    if (a.dc_link) d.set_dc_link(*a.dc_link);
    if (a.sto) d.set_sto(*a.sto);
    if (a.connection_lost) d.set_connection_lost(*a.connection_lost);
    if (code) {
      d.clear_faults();
      if (*code != 0) d.inject_fault(static_cast<std::uint16_t>(*code), static_cast<std::uint8_t>(error_class));
    }
  }

  profile_ptr profile_;
  axis axis_;
  drive_inputs inputs_;
  drive_outputs last_;
  bool stepped_ = false;
  machine_ptr plant_;  ///< the simulated plant, or null for the ideal one
};

py::object transition_or_none(std::uint8_t t) {
  return t == no_transition ? py::object(py::none()) : py::object(py::int_(t));
}

}  // namespace

void bind_outputs(py::module_& m) {
  py::class_<step_outputs>(m, "Outputs", R"doc(
What a drive decided in a step (for Drive.settle: in its last step, with every transition taken).
`state` is the state's name ("OPERATION_ENABLED"), `brake` "released" or "engaged", `ramp` the stop
running ("none", "slow_down", "quick_stop", "current_limit", "voltage_limit", "coast").)doc")
      .def_property_readonly("state", [](const step_outputs& o) { return state_name(o.out.current); })
      .def_property_readonly("status_word", [](const step_outputs& o) { return o.out.status_word; }, "0x6041")
      .def_property_readonly("transition", [](const step_outputs& o) { return transition_or_none(o.out.transition); },
                             "The transition the (last) step took, or None.")
      .def_readonly("transitions", &step_outputs::transitions, "Every transition taken, in order.")
      .def_property_readonly("torque", [](const step_outputs& o) { return o.out.torque; },
                             "The power stage is on (the drive function is enabled).")
      .def_property_readonly("brake", [](const step_outputs& o) { return brake_name(o.out.brake_released); })
      .def_property_readonly("brake_released", [](const step_outputs& o) { return o.out.brake_released; })
      .def_property_readonly("ramp", [](const step_outputs& o) { return stop_ramp_name(o.out.ramp); })
      .def_property_readonly("error_code", [](const step_outputs& o) { return o.out.error_code; }, "0x603F")
      .def_property_readonly("error_register", [](const step_outputs& o) { return o.out.error_register; }, "0x1001")
      .def_property_readonly("clear_setpoints", [](const step_outputs& o) { return o.out.clear_setpoints; },
                             "The motion side must drop its set-points now (T4).")
      .def_readonly("settled", &step_outputs::settled,
                    "False when a settle did not come to rest within 64 steps (True for a step).")
      .def("as_dict", [](const step_outputs& o) {
        py::dict d;
        d["state"] = state_name(o.out.current);
        d["status_word"] = o.out.status_word;
        d["transitions"] = o.transitions;
        d["torque"] = o.out.torque;
        d["brake"] = brake_name(o.out.brake_released);
        d["ramp"] = stop_ramp_name(o.out.ramp);
        d["error_code"] = o.out.error_code;
        return d;
      }, "state, status_word, transitions, torque, brake, ramp and error_code as a dict.")
      .def("__repr__", [](const step_outputs& o) {
        std::string t;
        for (const auto n : o.transitions) {
          if (!t.empty()) t += ", ";
          t += std::to_string(n);
        }
        char word[8];
        std::snprintf(word, sizeof word, "0x%04X", o.out.status_word);
        return std::string("Outputs(state='") + state_name(o.out.current) + "', status_word=" + word +
               ", transitions=[" + t + "], torque=" + (o.out.torque ? "True" : "False") + ", brake='" +
               brake_name(o.out.brake_released) + "', ramp='" + stop_ramp_name(o.out.ramp) + "')";
      });
}

void bind_drive(py::module_& m) {
  bind_outputs(m);
  const auto inputs_doc = R"doc(
Keyword inputs (each one given changes that input; the others keep their value): control_word
(0x6040), dc_link, sto, fault (the present fault cause's error code, 0 = none), fault_class (0..4),
standstill, brake_engaged, remote, connection_lost, local_enable, local_disable, status_bits,
actual_speed_rpm. On a simulated plant only control_word, dc_link, sto, fault, fault_class and
connection_lost: the plant gives the rest.)doc";

  py::class_<drive_core, std::shared_ptr<drive_core>>(m, "Drive", R"doc(
One drive: the core state machine of a profile (cia402::drive) on an ideal plant whose inputs are
given by keyword, or with plant=True / plant={...} on the simulator's plant (sim.Machine's keys).
`drive[0x605A] = 6` writes an object (option codes 0x605A..0x605E and 0x6007; 0x6040; 0x6041,
0x603F and 0x1001 read-only; on a simulated plant every object of cia402.objects()); a refused
access raises SdoError with its abort code.)doc")
      .def(py::init([](const py::object& profile, const py::object& plant) {
             return std::make_shared<drive_core>(profile_argument(profile), plant);
           }),
           py::arg("profile") = "cia402", py::arg("plant") = py::none())
      .def_static("from_file",
                  [](const std::string& path, const py::object& plant) {
                    return std::make_shared<drive_core>(profile_from_file(path), plant);
                  },
                  py::arg("path"), py::arg("plant") = py::none(),
                  "A drive on a TOML profile file; ProfileError with the line and reason.")
      .def("step", [](drive_core& d, const py::kwargs& inputs) { return d.step(parse_inputs(inputs, "step")); },
           (std::string("step(*, control_word=None, dc_link=None, sto=None, fault=None, fault_class=None, "
                        "standstill=None, brake_engaged=None, remote=None, connection_lost=None, "
                        "local_enable=None, local_disable=None, status_bits=None, actual_speed_rpm=None)\n\n"
                        "Runs one cycle and returns its Outputs.\n") + inputs_doc).c_str())
      .def("settle", [](drive_core& d, const py::kwargs& inputs) { return d.settle(parse_inputs(inputs, "settle")); },
           (std::string("settle(*, control_word=None, ...): the inputs of step()\n\n"
                        "Steps with these inputs until the drive is at rest (at most 64 steps), as a replay "
                        "line does; the Outputs list every transition taken.\n") + inputs_doc).c_str())
      .def("read", [](const drive_core& d, std::int64_t index, std::int64_t sub) {
             return d.read(object_key_of(py::make_tuple(index, sub)));
           }, py::arg("index"), py::arg("sub") = 0, "Reads an object; SdoError when refused.")
      .def("write", [](drive_core& d, std::int64_t index, std::int64_t value, std::int64_t sub) {
             d.write(object_key_of(py::make_tuple(index, sub)), value);
           }, py::arg("index"), py::arg("value"), py::arg("sub") = 0,
           "Writes an object; SdoError when refused (nothing changes then).")
      .def("__getitem__", [](const drive_core& d, const py::object& key) { return d.read(object_key_of(key)); })
      .def("__setitem__", [](drive_core& d, const py::object& key, std::int64_t value) {
        d.write(object_key_of(key), value);
      })
      .def_property_readonly("inputs", &drive_core::inputs, "The inputs the next step reads, as a dict.")
      .def_property_readonly("outputs", &drive_core::last, "The last step's Outputs.")
      .def_property_readonly("state", [](const drive_core& d) { return state_name(d.core_axis().current); })
      .def_property_readonly("status_word", [](const drive_core& d) { return d.last().out.status_word; })
      .def_property_readonly("error_code", [](const drive_core& d) { return d.core_axis().error_code; })
      .def_property_readonly("profile", [](const drive_core& d) { return std::const_pointer_cast<profile_handle>(d.table()); })
      .def_property_readonly("machine", [](const drive_core& d) -> py::object {
        if (!d.plant()) return py::none();
        return py::cast(d.plant());
      }, "The one-axis sim.Machine of a simulated plant (None on the ideal plant).")
      .def_property_readonly("axis", [](const drive_core& d) -> py::object {
        if (!d.plant()) return py::none();
        return py::cast(axis_handle{d.plant(), 0});
      }, "The sim.Axis of a simulated plant (None on the ideal plant).")
      .def("path", [](const drive_core& d, const std::string& to) {
        return path_steps(d.table()->get(), plan_path(d.table()->get(), d.core_axis(), state_argument(to)));
      }, py::arg("to_state"),
         "The planner's path from this drive as it is now to a state (list of PathStep, or None).")
      .def("replay", [](const drive_core& d, const py::object& lines) {
        return replay_dicts(d.table(), d.core_axis(), lines);
      }, py::arg("lines"), R"doc(
Runs `cia402 replay` on this drive's profile, with its present option codes as --set: a fresh
drive from power-up, one event a line (a str of lines or an iterable of lines). Returns the JSON
objects replay prints, as dicts: the power-up line first, then one per event line.)doc");
}

}  // namespace cia402::python
