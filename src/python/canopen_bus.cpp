// cia402.canopen.VirtualBus: the in-process CAN bus of `cia402 bus` (canopen::virtual_bus) with
// virtual CiA 402 drives on it (apps::virtual_drive_node, the same nodes `cia402 bus` serves), and
// ports on it for Python (a python-can bus, cia402/_python_can.py, wraps one).
// Time and locking: canopen_bus.hpp.
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <set>

#include "canopen_bus.hpp"
#include "cia402/hex_text.hpp"

namespace cia402::python {
namespace {


/// A frame as Python gets it: (arbitration_id, data, is_extended_id, is_remote_frame, dlc).
using frame_tuple = std::tuple<std::uint32_t, py::bytes, bool, bool, std::uint8_t>;

/// One attachment of Python to the bus: what a python-can bus sends and receives through.
class bus_port {
 public:
  explicit bus_port(std::shared_ptr<bus_core> core) : core_(std::move(core)), channel_(core_->attach()) {}
  ~bus_port() { close(); }
  bus_port(const bus_port&) = delete;
  bus_port& operator=(const bus_port&) = delete;

  void send(std::uint32_t id, const std::string& data, bool extended, bool rtr, int dlc) {
    if (id > (extended ? canopen::max_extended_id : canopen::max_base_id)) {
      raise_argument_error("CAN identifier " + std::string(to_hex(id, 1).c_str()) + " beyond " + (extended ? "29" : "11") + " bits");
    }
    if (data.size() > 8) raise_argument_error("a classic CAN frame carries at most 8 data bytes");
    if (rtr && (dlc < 0 || dlc > 8)) raise_argument_error("a remote frame's DLC is 0..8");
    canopen::frame f;
    f.id = id;
    f.extended = extended;
    f.rtr = rtr;
    f.len = static_cast<std::uint8_t>(rtr ? dlc : static_cast<int>(data.size()));
    if (!rtr) std::copy(data.begin(), data.end(), f.data.begin());
    std::error_code failed;
    {
      py::gil_scoped_release nogil;
      std::lock_guard lock(core_->mutex_);
      if (channel_ == nullptr) {
        failed = std::make_error_code(std::errc::not_connected);
      } else {
        failed = channel_->send(f);
      }
    }
    core_->arrived_.notify_all();  // another port takes it
    if (failed) raise_argument_error("the frame was not sent: " + failed.message());
  }

  /// The next frame, waiting up to `timeout` seconds (None: until one comes or the port closes).
  std::optional<frame_tuple> recv(std::optional<double> timeout) {
    if (timeout && !(*timeout >= 0)) raise_argument_error("recv takes a timeout of 0 s or more");
    const auto deadline = timeout ? steady::now() + std::chrono::duration_cast<steady::duration>(
                                                        std::chrono::duration<double>(std::min(*timeout, 1e6)))
                                  : steady::time_point::max();
    canopen::frame f;
    for (;;) {
      bool got = false;
      bool over = false;
      {
        py::gil_scoped_release nogil;
        std::unique_lock lock(core_->mutex_);
        // Wait in slices so that a Ctrl-C reaches the interpreter during a long wait.
        const auto slice_end = std::min(deadline, steady::now() + std::chrono::milliseconds(100));
        for (;;) {
          if (channel_ != nullptr && channel_->receive(f)) {
            got = true;
            break;
          }
          if (channel_ == nullptr) {
            over = true;
            break;
          }
          if (core_->arrived_.wait_until(lock, slice_end) == std::cv_status::timeout) {
            got = channel_ != nullptr && channel_->receive(f);
            over = got || steady::now() >= deadline;
            break;
          }
        }
      }
      if (got) {
        std::string data(f.rtr ? 0 : f.len, '\0');
        std::copy_n(f.data.begin(), data.size(), data.begin());
        return frame_tuple{f.id, py::bytes(data), f.extended, f.rtr, f.len};
      }
      if (over) return std::nullopt;
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  /// Frames this port's queue dropped because Python did not take them in time.
  std::uint64_t overruns() {
    py::gil_scoped_release nogil;
    std::lock_guard lock(core_->mutex_);
    return channel_ == nullptr ? 0 : channel_->overruns();
  }

  void close() {
    {
      std::lock_guard lock(core_->mutex_);
      channel_.reset();
    }
    core_->arrived_.notify_all();
  }

 private:
  std::shared_ptr<bus_core> core_;
  std::unique_ptr<canopen::virtual_channel> channel_;
};

/// Node-IDs from an int N (1..N) or an iterable of node-IDs; ArgumentError unless each is 1..127
/// and appears once.
std::vector<std::uint8_t> node_ids_of(const py::handle& nodes) {
  std::vector<std::int64_t> ids;
  if (py::isinstance<py::int_>(nodes)) {
    const auto n = nodes.cast<std::int64_t>();
    checked_integer(n, 1, canopen::max_node_id, "nodes (a count)");
    for (std::int64_t i = 1; i <= n; ++i) ids.push_back(i);
  } else if (py::hasattr(nodes, "__iter__") && !py::isinstance<py::str>(nodes)) {
    for (const py::handle h : py::iter(nodes)) {
      if (!py::isinstance<py::int_>(h)) raise_argument_error("nodes takes node-IDs (ints 1..127)");
      ids.push_back(h.cast<std::int64_t>());
    }
  } else {
    raise_argument_error("nodes takes a count or an iterable of node-IDs");
  }
  if (ids.empty()) raise_argument_error("a VirtualBus needs at least one node");
  std::set<std::int64_t> seen;
  std::vector<std::uint8_t> out;
  for (const std::int64_t id : ids) {
    checked_integer(id, 1, canopen::max_node_id, "a node-ID");
    if (!seen.insert(id).second) raise_argument_error("node-ID " + std::to_string(id) + " given twice");
    out.push_back(static_cast<std::uint8_t>(id));
  }
  return out;
}

std::uint8_t node_on(const bus_core& core, std::int64_t node) {
  for (const std::uint8_t id : core.node_ids()) {
    if (id == node) return id;
  }
  raise_argument_error("no node " + std::to_string(node) + " on this bus");
}

}  // namespace

void bind_canopen(py::module_& m) {
  py::class_<bus_port, std::shared_ptr<bus_port>>(
      m, "Port",
      "One attachment to a VirtualBus: frames sent on it reach the drives and every other port; it "
      "receives every frame others send. VirtualBus.python_can_bus() wraps one in a can.BusABC.")
      .def("send", &bus_port::send, py::arg("arbitration_id"), py::arg("data"), py::arg("is_extended_id") = false,
           py::arg("is_remote_frame") = false, py::arg("dlc") = 0,
           "Puts one frame on the bus (ArgumentError for an identifier or a length CAN has not).")
      .def("recv", &bus_port::recv, py::arg("timeout") = py::none(),
           "The next frame as (arbitration_id, data, is_extended_id, is_remote_frame, dlc), waiting up "
           "to `timeout` s (None: until one comes); None when none came or the port is closed.")
      .def_property_readonly("overruns", &bus_port::overruns,
                             "Frames dropped because this port's queue (4096 frames) was full.")
      .def("close", &bus_port::close, py::call_guard<py::gil_scoped_release>(),
           "Detaches the port from the bus; recv then returns None and send refuses.");

  py::class_<bus_core, std::shared_ptr<bus_core>> bus(
      m, "VirtualBus",
      "The virtual CAN bus of `cia402 bus` with its virtual CiA 402 drives in this process "
      "(see cia402.canopen.VirtualBus).");
  bus.def(py::init([](const py::object& nodes, const py::object& profile, bool virtual_time, double period_ms,
                       int heartbeat_ms) {
             if (!(period_ms >= 0.1 && period_ms <= 100.0)) raise_argument_error("period_ms is 0.1 .. 100");
             const auto period_us = static_cast<std::uint32_t>(std::llround(period_ms * 1000.0));
             checked_integer(heartbeat_ms, 0, 65535, "heartbeat_ms");
             const auto ids = node_ids_of(nodes);
             auto p = profile_argument(profile);
             py::gil_scoped_release nogil;
             return std::make_shared<bus_core>(std::move(p), ids, virtual_time, period_us,
                                               static_cast<std::uint16_t>(heartbeat_ms));
           }),
           py::arg("nodes") = 1, py::arg("profile") = py::none(), py::kw_only(), py::arg("virtual_time") = false,
           py::arg("period_ms") = 1.0, py::arg("heartbeat_ms") = 0)
      .def(
          "attach", [](const std::shared_ptr<bus_core>& core) { return std::make_shared<bus_port>(core); },
          "A new Port on the bus.")
      .def(
          "advance",
          [](bus_core& core, double ms) {
            if (!core.virtual_time()) {
              raise_argument_error("advance() is for a bus on virtual time (VirtualBus(virtual_time=True)); "
                                   "this one follows the wall clock");
            }
            if (!(ms >= 0) || ms > 1e9) raise_argument_error("advance takes 0 ms or more");
            const auto us = static_cast<std::uint64_t>(std::llround(ms * 1000.0));
            py::gil_scoped_release nogil;
            core.advance(us);
          },
          py::arg("ms"), "Virtual time only: steps every drive through `ms` milliseconds, a period at a time.")
      .def(
          "eds", [](const bus_core& core, std::int64_t node) { return core.eds(node_on(core, node)); },
          py::arg("node"), "The CiA 306 EDS of that node (its objects and their values at power-up).")
      .def_property_readonly(
          "nodes", [](const bus_core& core) { return std::vector<int>(core.node_ids().begin(), core.node_ids().end()); },
          "The node-IDs of the drives, in the order given.")
      .def_property_readonly(
          "profile", [](const bus_core& core) { return std::const_pointer_cast<profile_handle>(core.profile_handle_ptr()); }, "The drives' profile.")
      .def_property_readonly("virtual_time", &bus_core::virtual_time)
      .def_property_readonly(
          "time_ms", [](bus_core& core) { return static_cast<double>(core.elapsed_us()) / 1000.0; },
          py::call_guard<py::gil_scoped_release>(), "Time the drives have been stepped through, in ms.")
      .def_property_readonly("frames", &bus_core::frames, py::call_guard<py::gil_scoped_release>(),
                             "Frames the bus has carried so far.")
      .def_property_readonly("closed", &bus_core::closed, py::call_guard<py::gil_scoped_release>())
      .def("close", &bus_core::close, py::call_guard<py::gil_scoped_release>(),
           "Stops the stepping thread (wall time); the drives stop where they are.");
  bind_canopen_axis(m, bus);
}

}  // namespace cia402::python
