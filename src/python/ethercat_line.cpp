// cia402.ethercat.VirtualLine: a chain of virtual EtherCAT drives (apps::virtual_drive_slave, what
// `cia402 ecat-slave` puts on a line) and the project's master over it (ethercat::ecat_line, what
// `cia402 master --ecat` runs), in this process and on virtual time: a frame the master sends goes
// through every drive's controller in order and back, as on a real line, and the time the master
// waits is the drives' time. The line is brought to OP when it is made; axis(position) is an Axis
// (canopen_axis.cpp) over that drive's ecat_link, stepped with the line.
#include <pybind11/stl.h>

#include <cmath>
#include <csignal>
#include <thread>

#include "canopen_bus.hpp"
#include "cia402/apps/elapsed_clock.hpp"
#include "cia402/apps/ethercat_host.hpp"
#include "cia402/apps/ethercat_link.hpp"
#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/axis/ecat_link.hpp"
#include "cia402/ethercat/esc/esc.hpp"

namespace cia402::python {
namespace {

/// The in-process wire: frames through the chain of controllers, time through the drives.
class wire final : public ethercat::master_link {
 public:
  bool exchange(std::vector<std::uint8_t>& frame) override {
    return chain.pass(frame) == ethercat::frame_error::none;
  }
  std::uint64_t now_us() override { return now; }
  void wait_us(std::uint32_t us) override {
    now += us;
    for (auto& s : slaves) s->step(us);
  }

  std::vector<std::unique_ptr<apps::virtual_drive_slave>> slaves;
  ethercat::chain chain;
  std::uint64_t now = 0;
};

/// The drives and the master on the two ends of a real network interface pair (a veth pair): the
/// drives hosted as `cia402 ecat-slave` hosts them, on a thread of their own; the master's frames
/// through a raw socket and the kernel, on wall time.
struct wired_line {
  wired_line(const profile& p, int drives, std::uint32_t cycle_us) : host(p, drives, cycle_us), link(20000) {}
  apps::ethercat_host host;
  apps::ethercat_link link;
  volatile std::sig_atomic_t stop = 0;
  std::thread drives_thread;
};

class line_core final : public axis_host {
 public:
  /// In process, on virtual time.
  line_core(profile_ptr p, int drives, std::uint32_t cycle_us) : profile_(std::move(p)), cycle_us_(cycle_us) {
    for (int i = 0; i < drives; ++i) {
      wire_.slaves.push_back(std::make_unique<apps::virtual_drive_slave>(profile_->get(), static_cast<std::uint32_t>(i + 1)));
      wire_.chain.add(wire_.slaves.back()->controller());
    }
    drives_ = static_cast<std::size_t>(drives);
    line_ = std::make_unique<ethercat::ecat_line>(wire_, profile_->get(), cycle_us, "cia402.ethercat.VirtualLine");
    if (!line_->scan() || !line_->bring_to_operational()) error_ = line_->error();
  }

  /// Over network interfaces, on wall time: the master on `master_if`, the drives on `drives_if`.
  line_core(profile_ptr p, int drives, std::uint32_t cycle_us, const std::string& master_if, const std::string& drives_if)
      : profile_(std::move(p)), cycle_us_(cycle_us), wired_(std::make_unique<wired_line>(profile_->get(), drives, cycle_us)) {
    drives_ = static_cast<std::size_t>(drives);
    if (const auto e = wired_->host.open(drives_if)) {
      error_ = "the drives' interface " + drives_if + ": " + e.message();
      return;
    }
    if (const auto e = wired_->link.open(master_if)) {
      error_ = "the master's interface " + master_if + ": " + e.message();
      return;
    }
    wired_->drives_thread = std::thread([w = wired_.get()] { w->host.run(w->stop); });
    line_ = std::make_unique<ethercat::ecat_line>(wired_->link, profile_->get(), cycle_us, "cia402.ethercat.VirtualLine " + master_if);
    if (!line_->scan() || !line_->bring_to_operational()) {
      error_ = line_->error();
      return;
    }
    // Over an interface: a cycle of the master every cycle_us of wall time, as `cia402 master --ecat`.
    stepper_ = std::thread([this] { run_on_wall_time(cycle_us_); });
  }

  ~line_core() override {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    wake_.notify_all();
    arrived_.notify_all();
    if (stepper_.joinable()) stepper_.join();
    if (wired_) {
      wired_->stop = 1;
      if (wired_->drives_thread.joinable()) wired_->drives_thread.join();
    }
  }
  line_core(const line_core&) = delete;
  line_core& operator=(const line_core&) = delete;

  const std::string& bring_up_error() const noexcept { return error_; }
  bool virtual_time() const noexcept override { return wired_ == nullptr; }
  bool closed_locked() const noexcept override { return closed_; }
  const profile_ptr& profile_handle_ptr() const noexcept override { return profile_; }
  std::uint32_t step_period_locked() override {
    step(cycle_us_);
    return cycle_us_;
  }

  void advance(std::uint64_t us) { advance_in_periods(us, cycle_us_); }

  std::uint64_t now_us() {
    std::lock_guard lock(mutex_);
    return wired_ ? elapsed_us_ : wire_.now;
  }
  std::uint64_t cycles() {
    std::lock_guard lock(mutex_);
    return line_->cycles();
  }
  /// The drive's own AL state in process; over an interface, as the master last read it (the
  /// drives run on their own thread there).
  std::string al_state(std::size_t position) {
    std::lock_guard lock(mutex_);
    const auto state = wired_ ? line_->master().slaves()[position].al_state & 0x0F
                              : static_cast<std::uint8_t>(wire_.slaves[position]->state());
    return ethercat::line_state_name(static_cast<std::uint8_t>(state));
  }
  /// What the master found, copied under the mutex (over an interface its thread cycles the line).
  std::vector<ethercat::ecat_slave> slaves() {
    py::gil_scoped_release nogil;
    std::lock_guard lock(mutex_);
    return line_->master().slaves();
  }
  std::size_t drives() const noexcept { return drives_; }
  ethercat::ecat_line& line() noexcept { return *line_; }

 private:
  // The drives' time (in process), then the master's: a cycle when one is due (the line's service,
  // driven by the first session that polls), each session's work. Without a session the line is
  // cycled here, so the process data keeps flowing and the drives' watchdogs stay fed.
  void step(std::uint32_t elapsed) {
    if (!wired_) wire_.wait_us(elapsed);
    if (axes_.empty()) {
      if (line_->operational()) (void)line_->service();
    } else {
      for (auto& a : axes_) (void)a->session->poll(elapsed);
    }
    elapsed_us_ += elapsed;
  }

  void step_locked(std::uint32_t elapsed) override { step(elapsed); }

  profile_ptr profile_;
  std::uint32_t cycle_us_;
  wire wire_;
  std::unique_ptr<wired_line> wired_;
  std::unique_ptr<ethercat::ecat_line> line_;
  std::size_t drives_ = 0;
  std::string error_;
  std::uint64_t elapsed_us_ = 0;
  bool closed_ = false;
  std::thread stepper_;
};

py::dict slave_dict(const ethercat::ecat_slave& s) {
  py::dict d;
  d["position"] = s.position;
  d["station"] = s.station;
  d["name"] = s.sii.device_name;
  d["vendor_id"] = s.sii.vendor_id;
  d["product_code"] = s.sii.product_code;
  d["revision"] = s.sii.revision;
  d["serial"] = s.sii.serial;
  d["output_bytes"] = s.output_bytes;
  d["input_bytes"] = s.input_bytes;
  d["mapping_source"] = s.mapping_source;
  return d;
}

}  // namespace

void bind_ethercat(py::module_& m, const py::module_& canopen) {
  m.attr("Axis") = canopen.attr("Axis");
  py::class_<line_core, std::shared_ptr<line_core>>(m, "VirtualLine", R"doc(
A chain of virtual CiA 402 drives as EtherCAT slaves (what `cia402 ecat-slave` runs) and the
project's EtherCAT master over it (what `cia402 master --ecat` runs), in this process, on virtual
time. VirtualLine(drives=1, profile=None, cycle_us=1000): the master scans the line, reads each
drive's SII and PDO mapping and brings the line to OP when it is made (cia402.Error naming why if it
cannot). axis(position) is the master's Axis for a drive; advance(ms) lets time pass.
With interfaces=(master_if, drives_if) (two ends of a veth pair, say; raw sockets: root or
CAP_NET_RAW) the drives answer on drives_if as `cia402 ecat-slave` does and the master's frames go
out on master_if through the kernel, on wall time.)doc")
      .def(py::init([](int drives, const py::object& profile, std::int64_t cycle_us, const py::object& interfaces) {
             checked_integer(drives, 1, 64, "drives");
             checked_integer(cycle_us, 250, 100000, "cycle_us");
             auto p = profile_argument(profile);
             std::optional<std::pair<std::string, std::string>> ends;
             if (!interfaces.is_none()) {
               const auto pair = interfaces.cast<std::vector<std::string>>();
               if (pair.size() != 2 || pair[0].empty() || pair[1].empty() || pair[0] == pair[1]) {
                 raise_argument_error("interfaces is (the master's interface, the drives' interface): two names");
               }
               ends.emplace(pair[0], pair[1]);
             }
             std::shared_ptr<line_core> line;
             {
               py::gil_scoped_release nogil;
               if (ends) {
                 line = std::make_shared<line_core>(std::move(p), drives, static_cast<std::uint32_t>(cycle_us), ends->first, ends->second);
               } else {
                 line = std::make_shared<line_core>(std::move(p), drives, static_cast<std::uint32_t>(cycle_us));
               }
             }
             if (!line->bring_up_error().empty()) {
               const std::string why = line->bring_up_error();
               {
                 py::gil_scoped_release nogil;
                 line.reset();  // its threads joined without the GIL
               }
               py::object e = py::module_::import("cia402._errors").attr("Error")("the line did not reach OP: " + why);
               PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(e.ptr())), e.ptr());
               throw py::error_already_set();
             }
             return line;
           }),
           py::arg("drives") = 1, py::arg("profile") = py::none(), py::arg("cycle_us") = 1000, py::kw_only(),
           py::arg("interfaces") = py::none())
      .def("advance", [](line_core& l, double ms) {
             if (!(ms >= 0) || ms > 1e9) raise_argument_error("advance takes 0 ms or more");
             if (!l.virtual_time()) raise_argument_error("a line over network interfaces runs on wall time: nothing to advance");
             const auto us = static_cast<std::uint64_t>(std::llround(ms * 1000.0));
             py::gil_scoped_release nogil;
             l.advance(us);
           }, py::arg("ms"), "Lets `ms` milliseconds pass for the drives and the master, a cycle at a time.")
      .def("axis", [](const std::shared_ptr<line_core>& l, std::int64_t position) {
             checked_integer(position, 0, static_cast<std::int64_t>(l->drives()) - 1, "position");
             line_core* raw = l.get();
             const auto pos = static_cast<std::size_t>(position);
             return make_axis(l, static_cast<std::uint8_t>(position), [raw, pos](bus_axis& a) {
               a.link = std::make_unique<ethercat::ecat_link>(raw->line(), pos);
             });
           }, py::arg("position"),
           "The master's Axis for the drive at `position` (0: the first after the master), over its "
           "process data and CoE SDO.")
      .def_property_readonly("slaves", [](line_core& l) {
             py::list out;
             for (const auto& s : l.slaves()) out.append(slave_dict(s));
             return out;
           }, "What the master found on the line: position, station, name, identity, PDO sizes, mapping source.")
      .def("al_state", [](line_core& l, std::int64_t position) {
             checked_integer(position, 0, static_cast<std::int64_t>(l.drives()) - 1, "position");
             return l.al_state(static_cast<std::size_t>(position));
           }, py::arg("position"), "The drive's own AL state (\"OP\", \"SAFE-OP\", ...).")
      .def_property_readonly("time_ms", [](line_core& l) { return static_cast<double>(l.now_us()) / 1000.0; },
                             "Virtual time since the line was made, in ms.")
      .def_property_readonly("cycles", &line_core::cycles, "Process-data cycles the master ran since OP.");
}

}  // namespace cia402::python
