// cia402.canopen.Axis: the project's master side in Python, one axis session (src/axis) over its
// CAN link (canopen::can_link: SDO, then PDOs with SYNC) on a VirtualBus, stepped with the drives
// (canopen_bus.hpp). Each request is the session's own (its planner, its refusals, its waits); a
// Python call starts one and waits for its end with the GIL released: on wall time for the wall
// clock, on virtual time by stepping the bus itself. A failure is a Python exception: SdoError with
// the abort code where the drive (or the object table) refused an object, AxisError otherwise.
#include <pybind11/stl.h>

#include <cmath>
#include <optional>

#include "canopen_bus.hpp"
#include "cia402/canopen/301/slave.hpp"
#include "cia402/hex_text.hpp"
#include "cia402/objects.hpp"
#include "cia402/state.hpp"

namespace cia402::python {
namespace {

using steady = std::chrono::steady_clock;
using request = std::function<std::uint64_t(axes::session&, axes::completion)>;

py::dict result_dict(const axes::result& r) {
  py::dict d;
  d["state"] = r.shown ? py::object(py::str(state_name(*r.shown))) : py::object(py::none());
  d["status_word"] = r.status_word;
  d["error_code"] = r.error_code;
  d["mode"] = r.mode ? py::object(py::int_(*r.mode)) : py::object(py::none());
  d["position"] = r.position ? py::object(py::int_(*r.position)) : py::object(py::none());
  d["velocity"] = r.velocity ? py::object(py::int_(*r.velocity)) : py::object(py::none());
  d["torque"] = r.torque ? py::object(py::int_(*r.torque)) : py::object(py::none());
  d["note"] = r.note;
  return d;
}

[[noreturn]] void raise_axis_error(const std::string& message, const axes::result& r) {
  py::object cls = py::module_::import("cia402._errors").attr("AxisError");
  py::object e = cls(message, r.shown ? py::object(py::str(state_name(*r.shown))) : py::object(py::none()),
                     r.status_word, r.error_code);
  PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(e.ptr())), e.ptr());
  throw py::error_already_set();
}

class axis_handle {
 public:
  axis_handle(std::shared_ptr<axis_host> host, std::uint8_t id, const std::function<void(bus_axis&)>& make)
      : core_(std::move(host)), axis_(std::make_shared<bus_axis>()) {
    axis_->node = id;
    py::gil_scoped_release nogil;
    std::lock_guard lock(core_->mutex_);
    make(*axis_);
    core_->add_axis_locked(axis_);
  }
  ~axis_handle() {
    std::lock_guard lock(core_->mutex_);
    core_->remove_axis_locked(axis_.get());
  }
  axis_handle(const axis_handle&) = delete;
  axis_handle& operator=(const axis_handle&) = delete;

  /// Starts `r` and waits up to `timeout_s` for its end; raises what it ended with.
  py::object run(const char* what, const request& r, double timeout_s) {
    const axes::result res = wait_for(what, r, timeout_s);
    if (!res.ok()) fail(res);
    return result_dict(res);
  }

  /// The result of `r`, unchecked (AxisError only when it did not end in time). With `started`, the
  /// wait ends once the request reports that progress (a jog turning): the request runs on, and
  /// wait() waits for its end later.
  axes::result wait_for(const char* what, const request& r, double timeout_s,
                        std::optional<axes::progress_kind> started = std::nullopt,
                        std::function<void(axes::progress_kind)> on_progress = nullptr) {
    if (!(timeout_s > 0) || timeout_s > 1e6) raise_argument_error("timeout is more than 0 s");
    auto b = std::make_shared<pending>();
    bool closed = false;
    // Taken under the mutex: a request that returned when it started (a jog) ends later on the
    // stepping thread, which writes *b then.
    bool done = false;
    bool began = false;
    axes::result out;
    {
      py::gil_scoped_release nogil;
      std::unique_lock lock(core_->mutex_);
      if (axis_->session == nullptr || (core_->closed_locked() && !core_->virtual_time())) {
        closed = true;
      } else {
        axes::session& s = *axis_->session;
        s.on_progress = [b, started, on_progress](axes::progress_kind kind, const axes::result& so_far) {
          if (on_progress) on_progress(kind);
          if (started && kind == *started && !b->started) {
            b->started = true;
            b->result = so_far;
          }
        };
        (void)r(s, [b](const axes::result& res) {
          b->result = res;
          b->done = true;
        });
        if (started) running_ = b;
        wait_locked(lock, *b, timeout_s);
        if (!b->done && !b->started) {
          // S20: the request fails with the time-out, and what it set moving is stopped before the
          // exception says so (the stop has a bound of its own: three stages of stop_timeout_us).
          s.cancel(std::string(what) + " did not end within " + std::to_string(timeout_s) + " s");
          wait_locked(lock, *b, 3 * axes::session_config{}.stop_timeout_us / 1e6 + 1);
        }
        done = b->done;
        began = b->started;
        out = b->result;
        if (began && !done) out.shown = s.status_known() ? std::optional<state>(s.observed()) : std::nullopt;
      }
    }
    if (closed) raise_argument_error("the bus or the axis is closed");
    if (!done && !began) {
      axes::result r2;
      r2.shown = observed();
      raise_axis_error(std::string(what) + " did not end within " + std::to_string(timeout_s) + " s", r2);
    }
    return out;
  }

  /// Waits for the end of the last request (one that returned when it started: a jog).
  py::object wait(double timeout_s) {
    if (!(timeout_s > 0) || timeout_s > 1e6) raise_argument_error("timeout is more than 0 s");
    bool any = false;
    bool done = false;
    axes::result out;
    {
      py::gil_scoped_release nogil;
      std::unique_lock lock(core_->mutex_);
      if (const std::shared_ptr<pending> b = running_) {
        any = true;
        b->started = false;  // only the end counts now
        wait_locked(lock, *b, timeout_s);
        done = b->done;
        out = b->result;
      }
    }
    if (!any) raise_argument_error("no request to wait for");
    if (!done) {
      axes::result r2;
      r2.shown = observed();
      raise_axis_error("the request did not end within " + std::to_string(timeout_s) + " s", r2);
    }
    if (!out.ok()) fail(out);
    return result_dict(out);
  }

  /// A cyclic synchronous stream (or the csp ramp) with each cycle sampled as it goes: the
  /// set-point sent and the actual value the drive showed, as the session sees them (on_cycle).
  py::object run_stream(const char* what, const request& r, std::uint16_t set_point, std::uint16_t actual,
                        double timeout_s) {
    auto samples = std::make_shared<std::vector<std::pair<std::optional<std::int64_t>, std::optional<std::int64_t>>>>();
    auto streaming = std::make_shared<bool>(false);  // from the first set-point of this stream on
    {
      py::gil_scoped_release nogil;
      std::lock_guard lock(core_->mutex_);
      if (axis_->session != nullptr) {
        axes::session& s = *axis_->session;
        s.on_cycle = [samples, streaming, &s, set_point, actual] {
          if (*streaming && s.busy()) samples->emplace_back(s.output(set_point), s.actual(actual));
        };
      }
    }
    const auto stop_sampling = [this] {
      py::gil_scoped_release nogil;
      std::lock_guard lock(core_->mutex_);
      if (axis_->session != nullptr) axis_->session->on_cycle = nullptr;
    };
    axes::result res;
    try {
      res = wait_for(what, r, timeout_s, std::nullopt, [streaming](axes::progress_kind kind) {
        if (kind == axes::progress_kind::stream_started) *streaming = true;
      });
    } catch (...) {
      stop_sampling();
      throw;
    }
    stop_sampling();
    if (!res.ok()) fail(res);
    py::dict d = result_dict(res);
    d["stream_from"] = res.stream_from;
    d["stream_to"] = res.stream_to;
    d["set_points"] = res.set_points;
    d["max_following_error"] = res.max_following_error;
    py::list sent, shown;
    for (const auto& [out, in] : *samples) {
      sent.append(out ? py::object(py::int_(*out)) : py::object(py::none()));
      shown.append(in ? py::object(py::int_(*in)) : py::object(py::none()));
    }
    py::dict trace;
    trace["set_point"] = sent;
    trace["actual"] = shown;
    d["trace"] = trace;
    return d;
  }

  [[noreturn]] void fail(const axes::result& res) { raise_axis_error(res.error, res); }

  py::object sdo_read(std::uint16_t index, std::uint8_t sub, double timeout_s) {
    const axes::result res = wait_for(
        "reading an object", [index, sub](axes::session& s, axes::completion d) { return s.read_object(index, sub, std::move(d)); },
        timeout_s);
    if (!res.ok()) {
      if (res.abort != sdo_abort::none) raise_sdo_error(res.abort, index, sub, "reading");
      fail(res);
    }
    const axes::object_value& v = *res.value;
    if (v.what == axes::value_format::kind::integer) {
      // An UNSIGNED64 above INT64_MAX keeps its bits: shown as the unsigned number.
      if (res.format && !res.format->is_signed && res.format->size == 8 && v.number < 0) {
        return py::int_(static_cast<unsigned long long>(v.number));
      }
      return py::int_(v.number);
    }
    if (v.what == axes::value_format::kind::text) return py::str(v.text);
    return py::bytes(std::string(v.bytes.begin(), v.bytes.end()));
  }

  void sdo_write(std::uint16_t index, std::uint8_t sub, const py::object& value, const std::optional<std::string>& type,
                 double timeout_s) {
    axes::object_value v;
    if (py::isinstance<py::bool_>(value)) raise_argument_error("an object value is an int, a str or bytes");
    if (py::isinstance<py::int_>(value)) {
      v = axes::object_value::of_integer(value.cast<std::int64_t>());
    } else if (py::isinstance<py::str>(value)) {
      v = axes::object_value::of_text(value.cast<std::string>());
    } else if (py::isinstance<py::bytes>(value)) {
      const auto s = value.cast<std::string>();
      v = axes::object_value::of_bytes(std::vector<std::uint8_t>(s.begin(), s.end()));
    } else {
      raise_argument_error("an object value is an int, a str or bytes");
    }
    if (type) {
      const std::optional<axes::value_format> asked = format_named(*type);
      if (!asked) {
        raise_argument_error("no type " + *type + " (unsigned8..unsigned64, integer8..integer64, visible_string, "
                             "octet_string, domain)");
      }
      std::optional<axes::value_format> known;
      {
        py::gil_scoped_release nogil;
        std::lock_guard lock(core_->mutex_);
        known = axis_->session->format_of(index, sub);
      }
      if (known && known->type_name() != asked->type_name()) {
        raise_argument_error(std::string(to_hex(index, 4).c_str()) + ":" + std::to_string(sub) + " is " + known->type_name() + ", not " + *type);
      }
      if (!known) {  // the type given decides the bytes
        std::vector<std::uint8_t> bytes;
        std::string why;
        if (!axes::encode_value(v, *asked, bytes, why)) raise_argument_error(why);
        v = axes::object_value::of_bytes(std::move(bytes));
      }
    }
    const axes::result res = wait_for(
        "writing an object",
        [index, sub, v](axes::session& s, axes::completion d) { return s.write_object(index, sub, v, std::move(d)); },
        timeout_s);
    if (!res.ok()) {
      if (res.abort != sdo_abort::none) raise_sdo_error(res.abort, index, sub, "writing");
      if (res.bad_input) raise_argument_error(res.error);
      fail(res);
    }
  }

  std::optional<state> observed() {
    std::lock_guard lock(core_->mutex_);
    if (axis_->session == nullptr || !axis_->session->status_known()) return std::nullopt;
    return axis_->session->observed();
  }
  template <typename T>
  T with_session(const std::function<T(axes::session&)>& f) {
    if (closed()) raise_argument_error("the axis is closed");
    py::gil_scoped_release nogil;
    std::lock_guard lock(core_->mutex_);
    return f(*axis_->session);
  }
  std::uint8_t node() const noexcept { return axis_->node; }
  bool closed() {
    py::gil_scoped_release nogil;
    std::lock_guard lock(core_->mutex_);
    return axis_->session == nullptr;
  }

  void close(double timeout_s) {
    py::gil_scoped_release nogil;
    std::unique_lock lock(core_->mutex_);
    if (axis_->session == nullptr) return;
    axis_->session->close(true);
    const auto deadline = steady::now() + std::chrono::duration_cast<steady::duration>(std::chrono::duration<double>(timeout_s));
    if (core_->virtual_time()) {
      for (std::uint64_t passed = 0; !axis_->session->closed() && passed < timeout_s * 1e6;) passed += core_->step_period_locked();
    } else {
      core_->arrived_.wait_until(lock, deadline, [&] { return axis_->session->closed() || core_->closed_locked(); });
    }
    core_->remove_axis_locked(axis_.get());
    axis_->session.reset();
    axis_->link.reset();
    axis_->channel.reset();
  }

 private:
  static std::optional<axes::value_format> format_named(const std::string& name) {
    for (const unsigned size : {1u, 2u, 4u, 8u}) {
      for (const bool is_signed : {false, true}) {
        const auto f = axes::value_format::integer(size, is_signed);
        if (f.type_name() == name) return f;
      }
    }
    for (const auto f : {axes::value_format::text(), axes::value_format::octets(false), axes::value_format::octets(true)}) {
      if (f.type_name() == name) return f;
    }
    return std::nullopt;
  }

  struct pending {
    bool done = false;
    bool started = false;  ///< the progress asked for came (the request runs on)
    axes::result result;
  };

  /// Until `b` ends (or starts, where asked), `timeout_s` at most: on virtual time by stepping the
  /// host, on wall time by waiting for its thread. The mutex is held.
  void wait_locked(std::unique_lock<std::mutex>& lock, pending& b, double timeout_s) {
    if (core_->virtual_time()) {
      const auto limit = static_cast<std::uint64_t>(timeout_s * 1e6);
      for (std::uint64_t passed = 0; !b.done && !b.started && passed < limit;) passed += core_->step_period_locked();
      core_->arrived_.notify_all();
    } else {
      const auto deadline = steady::now() + std::chrono::duration_cast<steady::duration>(
                                                std::chrono::duration<double>(timeout_s));
      core_->arrived_.wait_until(lock, deadline, [&] { return b.done || b.started || core_->closed_locked(); });
    }
  }

  std::shared_ptr<axis_host> core_;
  std::shared_ptr<bus_axis> axis_;
  std::shared_ptr<pending> running_;  ///< the last request started (guarded by the host's mutex)
};

std::uint64_t hold_us(double seconds) {
  if (!(seconds > 0) || seconds > 3600) raise_argument_error("hold is more than 0 s, 3600 s at most");
  return static_cast<std::uint64_t>(std::llround(seconds * 1e6));
}

/// A stream's set-point and actual objects, and the set-point's range (CiA 402-2: 0x607A and 0x60FF
/// INTEGER32, 0x6071 INTEGER16).
struct stream_objects {
  std::uint16_t set_point;
  std::uint16_t actual;
  std::int64_t low;
  std::int64_t high;
};
stream_objects stream_objects_of(std::int8_t m) {
  switch (m) {
    case mode::cyclic_synchronous_position:
      return {object_index::target_position, object_index::position_actual_value, INT32_MIN, INT32_MAX};
    case mode::cyclic_synchronous_velocity:
      return {object_index::target_velocity, object_index::velocity_actual_value, INT32_MIN, INT32_MAX};
    case mode::cyclic_synchronous_torque:
      return {object_index::target_torque, object_index::torque_actual_value, INT16_MIN, INT16_MAX};
    default: raise_argument_error("a stream runs in csp, csv or cst");
  }
}

std::int8_t mode_argument(const py::handle& m) {
  if (py::isinstance<py::int_>(m)) return static_cast<std::int8_t>(checked_integer(m.cast<std::int64_t>(), -128, 127, "a mode"));
  std::int8_t out = 0;
  if (py::isinstance<py::str>(m) && mode::parse(m.cast<std::string>(), out)) return out;
  raise_argument_error("a mode is pp, pv, tq, hm, csp, csv, cst or its number");
}

/// Jog, halt and the cyclic synchronous streams (the requests that run on past their call, or
/// sample each cycle).
void bind_axis_motion(py::class_<axis_handle, std::shared_ptr<axis_handle>>& axis) {
  axis      .def("halt", [](axis_handle& a, bool on, double t) {
             return a.run(on ? "halt on" : "halt off", [on](axes::session& s, axes::completion d) { return s.halt(on, std::move(d)); }, t);
           }, py::arg("on") = true, py::arg("timeout") = 5.0,
           "Control bit 8 (halt, 0x605D) set or cleared beside the running motion: a halted move resumes "
           "when it is cleared; a motion command is refused while it is set.")
      .def("jog", [](axis_handle& a, std::int64_t rpm, double hold_s, double t) {
             const auto v = static_cast<std::int32_t>(checked_integer(rpm, INT32_MIN, INT32_MAX, "velocity"));
             const std::uint64_t hold = hold_us(hold_s);
             const axes::result res = a.wait_for("jog", [v, hold](axes::session& s, axes::completion d) {
               return s.jog(v, hold, std::move(d));
             }, t, axes::progress_kind::jog_started);
             if (!res.ok()) a.fail(res);
             return result_dict(res);
           }, py::arg("rpm"), py::arg("hold") = 0.5, py::arg("timeout") = 5.0,
           "Jogs in pv (switching to it first) at `rpm`: returns once the velocity is set; the jog then "
           "lives `hold` s (renew_jog extends it, as a button still held) and brings the shaft to "
           "standstill by itself when it lapses. wait() waits for that end.")
      .def("renew_jog", [](axis_handle& a, double hold_s) {
             const std::uint64_t hold = hold_us(hold_s);
             a.with_session<bool>([hold](axes::session& s) {
               s.renew_jog(hold);
               return true;
             });
           }, py::arg("hold") = 0.5, "The running jog lives on for `hold` s from now (nothing without a jog).")
      .def("wait", &axis_handle::wait, py::arg("timeout") = 30.0,
           "Waits for the end of the last request (a jog runs on after jog() returns); its result.")
      .def("csp_stream", [](axis_handle& a, std::int64_t to, std::int64_t rpm, double t) {
             const auto target = static_cast<std::int32_t>(checked_integer(to, INT32_MIN, INT32_MAX, "to"));
             const auto v = static_cast<std::uint32_t>(checked_integer(rpm, 1, UINT32_MAX, "rpm"));
             return a.run_stream("csp stream", [target, v](axes::session& s, axes::completion d) {
               return s.csp_stream(target, v, std::move(d));
             }, object_index::target_position, object_index::position_actual_value, t);
           }, py::arg("to"), py::arg("rpm"), py::arg("timeout") = 30.0,
           "csp: a ramp of 0x607A from where the drive stands to `to` at `rpm`, one set-point a cycle, done "
           "when 0x6064 shows `to`. The result adds stream_from, stream_to, set_points, "
           "max_following_error and trace (set_point and actual, one entry a cycle).")
      .def("stream", [](axis_handle& a, const py::iterable& points, const py::object& wanted, double t) {
             const std::int8_t code = mode_argument(wanted);
             const auto objects = stream_objects_of(code);
             auto values = std::make_shared<std::vector<std::int64_t>>();
             for (const py::handle v : points) {
               if (py::isinstance<py::bool_>(v) || !py::hasattr(v, "__index__")) raise_argument_error("a set-point is an int");
               values->push_back(checked_integer(py::reinterpret_borrow<py::object>(v).attr("__index__")().cast<std::int64_t>(),
                                                 objects.low, objects.high, "a set-point"));
             }
             if (values->empty()) raise_argument_error("a stream has one set-point at least");
             auto next = std::make_shared<std::size_t>(0);
             return a.run_stream("stream", [code, values, next](axes::session& s, axes::completion d) {
               return s.stream(code, [values, next]() -> std::optional<std::int64_t> {
                 if (*next >= values->size()) return std::nullopt;
                 return (*values)[(*next)++];
               }, std::move(d));
             }, objects.set_point, objects.actual, t);
           }, py::arg("set_points"), py::arg("mode") = "csp", py::arg("timeout") = 30.0,
           "A cyclic synchronous stream (csp 0x607A, csv 0x60FF, cst 0x6071), one set-point a cycle "
           "from `set_points` (checked whole before anything is sent), done when the drive stands at the "
           "last; the result as csp_stream's. The set-point object must be in the cyclic outputs.")
      .def_property_readonly("busy", [](axis_handle& a) {
             return a.with_session<bool>([](axes::session& s) { return s.busy(); });
           }, "A request runs (a jog until it has stopped).");
}

}  // namespace

void bind_canopen_axis(py::module_& m, py::class_<bus_core, std::shared_ptr<bus_core>>& bus) {
  py::class_<axis_handle, std::shared_ptr<axis_handle>> axis(m, "Axis", R"doc(
The project's master for one drive on a VirtualBus: the axis session of `cia402 master` over its
CAN link (SDO, then PDOs with SYNC every `cycle_ms`). Each call starts one request and waits for its
end (`timeout` s: wall clock, or virtual time on a virtual-time bus, which the call then advances);
it returns a dict with what the drive showed at the end (state, status_word, error_code, mode,
position, velocity, torque, note). A refusal raises SdoError (with the abort code) where the drive
or the object table refused an object, AxisError (with the state, status word and error code)
otherwise, also when the request did not end in time.)doc");
  bind_axis_motion(axis);
  axis.def("enable", [](axis_handle& a, double t) {
             return a.run("enable", [](axes::session& s, axes::completion d) { return s.go_to(state::operation_enabled, std::move(d)); }, t);
           }, py::arg("timeout") = 5.0, "To OPERATION ENABLED through the core's planner.")
      .def("disable", [](axis_handle& a, double t) {
             return a.run("disable", [](axes::session& s, axes::completion d) { return s.go_to(state::switch_on_disabled, std::move(d)); }, t);
           }, py::arg("timeout") = 5.0, "To SWITCH ON DISABLED.")
      .def("reset", [](axis_handle& a, double t) {
             return a.run("reset", [](axes::session& s, axes::completion d) { return s.reset(std::move(d)); }, t);
           }, py::arg("timeout") = 5.0, "A fault-reset edge on a drive in FAULT; done in SWITCH ON DISABLED.")
      .def("quick_stop", [](axis_handle& a, double t) {
             return a.run("quick stop", [](axes::session& s, axes::completion d) { return s.quick_stop(std::move(d)); }, t);
           }, py::arg("timeout") = 10.0, "Quick stop, done when the stop has ended as 0x605A says.")
      .def("stop", [](axis_handle& a, double t) {
             return a.run("stop", [](axes::session& s, axes::completion d) { return s.stop(std::move(d)); }, t);
           }, py::arg("timeout") = 10.0, "Ends the motion and stops the shaft (halt), done at standstill.")
      .def("mode", [](axis_handle& a, const py::object& wanted, double t) {
             const std::int8_t code = mode_argument(wanted);
             return a.run("mode", [code](axes::session& s, axes::completion d) { return s.set_mode(code, std::move(d)); }, t);
           }, py::arg("mode"), py::arg("timeout") = 5.0, "0x6060 (\"pp\", \"pv\", \"hm\", ... or the number), done when 0x6061 shows it.")
      .def("move", [](axis_handle& a, std::int64_t target, bool relative, std::optional<std::int64_t> rpm, double t) {
             axes::move_request r;
             r.target = static_cast<std::int32_t>(checked_integer(target, INT32_MIN, INT32_MAX, "target"));
             r.relative = relative;
             if (rpm) r.velocity = static_cast<std::uint32_t>(checked_integer(*rpm, 1, UINT32_MAX, "velocity"));
             return a.run("move", [r](axes::session& s, axes::completion d) { return s.move(r, std::move(d)); }, t);
           }, py::arg("target"), py::arg("relative") = false, py::arg("velocity") = py::none(), py::arg("timeout") = 30.0,
           "A profile position move (switching to pp first): the set-point handshake, done at the target.")
      .def("home", [](axis_handle& a, std::optional<std::int64_t> method, std::optional<std::int64_t> offset, double t) {
             axes::home_request r;
             if (method) r.method = static_cast<std::int8_t>(checked_integer(*method, -128, 127, "method"));
             if (offset) r.offset = static_cast<std::int32_t>(checked_integer(*offset, INT32_MIN, INT32_MAX, "offset"));
             return a.run("home", [r](axes::session& s, axes::completion d) { return s.home(r, std::move(d)); }, t);
           }, py::arg("method") = py::none(), py::arg("offset") = py::none(), py::arg("timeout") = 30.0,
           "Homing (switching to hm first) with method 0x6098 and offset 0x607C where given.")
      .def("velocity", [](axis_handle& a, std::int64_t rpm, double t) {
             const auto v = static_cast<std::int32_t>(checked_integer(rpm, INT32_MIN, INT32_MAX, "velocity"));
             return a.run("velocity", [v](axes::session& s, axes::completion d) { return s.velocity(v, std::move(d)); }, t);
           }, py::arg("rpm"), py::arg("timeout") = 30.0, "Profile velocity (switching to pv first), done at the velocity.")
      .def("torque", [](axis_handle& a, std::int64_t permille, double t) {
             const auto v = static_cast<std::int16_t>(checked_integer(permille, INT16_MIN, INT16_MAX, "torque"));
             return a.run("torque", [v](axes::session& s, axes::completion d) { return s.torque(v, std::move(d)); }, t);
           }, py::arg("permille"), py::arg("timeout") = 10.0, "Profile torque (switching to tq first).")
      .def("state_of", [](axis_handle& a, double t) {
             return a.run("read state", [](axes::session& s, axes::completion d) { return s.read_state(std::move(d)); }, t);
           }, py::arg("timeout") = 5.0, "The state, status word and error code, read now.")
      .def("sdo_read", [](axis_handle& a, std::int64_t index, std::int64_t sub, double t) {
             return a.sdo_read(static_cast<std::uint16_t>(checked_integer(index, 0, 0xFFFF, "index")),
                               static_cast<std::uint8_t>(checked_integer(sub, 0, 255, "sub-index")), t);
           }, py::arg("index"), py::arg("sub") = 0, py::arg("timeout") = 5.0,
           "An object by SDO, as its type says: int, str (VISIBLE_STRING) or bytes (no type known).")
      .def("sdo_write", [](axis_handle& a, std::int64_t index, const py::object& value, std::int64_t sub,
                           std::optional<std::string> type, double t) {
             a.sdo_write(static_cast<std::uint16_t>(checked_integer(index, 0, 0xFFFF, "index")), static_cast<std::uint8_t>(checked_integer(sub, 0, 255, "sub-index")),
                         value, type, t);
           }, py::arg("index"), py::arg("value"), py::arg("sub") = 0, py::arg("type") = py::none(), py::arg("timeout") = 5.0,
           "An object by SDO (a cyclic output in the PDO instead). `type` (\"unsigned16\", \"integer32\", "
           "\"visible_string\", ...) gives the bytes of an object whose type is not known; for a known one it must agree.")
      .def_property_readonly("node", &axis_handle::node)
      .def_property_readonly("closed", &axis_handle::closed)
      .def_property_readonly("state", [](axis_handle& a) -> py::object {
             const auto s = a.observed();
             return s ? py::object(py::str(state_name(*s))) : py::object(py::none());
           }, "The state the cyclic status word last showed (None before the cyclic exchange runs).")
      .def_property_readonly("status_word", [](axis_handle& a) {
             return a.with_session<std::uint16_t>([](axes::session& s) { return s.status_word(); });
           })
      .def_property_readonly("position", [](axis_handle& a) {
             return a.with_session<std::optional<std::int64_t>>([](axes::session& s) { return s.actual(object_index::position_actual_value); });
           }, "0x6064 as last carried or polled.")
      .def("close", &axis_handle::close, py::arg("timeout") = 10.0,
           "Stops the drive first as 0x6007 says, then puts back the PDO set-up it changed.");

  bus.def("axis", [](const std::shared_ptr<bus_core>& core, std::int64_t node, double cycle_ms, bool map_position) {
        bool found = false;
        for (const std::uint8_t id : core->node_ids()) found = found || id == node;
        if (!found) raise_argument_error("no node " + std::to_string(node) + " on this bus");
        if (!(cycle_ms >= 1 && cycle_ms <= 1000)) raise_argument_error("cycle_ms is 1 .. 1000");
        const auto id = static_cast<std::uint8_t>(node);
        canopen::can_link_config c;
        c.node_id = id;
        c.bus_name = "cia402.canopen.VirtualBus";
        c.cycle_us = static_cast<std::uint32_t>(std::llround(cycle_ms * 1000));
        c.drive_profile = &core->profile_handle_ptr()->get();
        c.map_position = map_position;
        c.known_objects = canopen::node_objects(apps::drive_node_config(id));
        bus_core* raw = core.get();
        return make_axis(core, id, [raw, c](bus_axis& a) mutable {
          auto ch = raw->attach_locked();
          a.link = std::make_unique<canopen::can_link>(*ch, std::move(c));
          a.channel = std::move(ch);
        });
      }, py::arg("node"), py::arg("cycle_ms") = 10.0, py::arg("map_position") = false,
      "The project's master for that node (an Axis): the axis session of `cia402 master` over its own "
      "attachment to this bus, SYNC every `cycle_ms`; `map_position` sets up PDO 3 for csp.");
}

py::object make_axis(std::shared_ptr<axis_host> host, std::uint8_t id, const std::function<void(bus_axis&)>& make) {
  const profile* p = &host->profile_handle_ptr()->get();
  return py::cast(std::make_shared<axis_handle>(std::move(host), id, [&make, p](bus_axis& a) {
    make(a);
    axes::session_config s;
    s.drive_profile = p;
    a.session = std::make_unique<axes::session>(*a.link, s);
  }));
}

}  // namespace cia402::python
