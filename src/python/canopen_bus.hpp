// What the CANopen parts of the binding share (canopen_bus.cpp, canopen_axis.cpp): the bus with its
// drives and the axis sessions on it, stepped together under one mutex.
//
// Time: on wall time (the default) a thread of its own steps the drives and the sessions every
// period with the time that really passed, as `cia402 bus` does; it never touches a Python object,
// so it never takes the GIL. On virtual time nothing moves until advance(ms) (or an axis request,
// which advances until it ends). One mutex guards the bus, the drives, the sessions and the ports,
// and no thread holding it ever asks for the GIL, so the two locks cannot deadlock; a call that may
// wait for it (a step is under way) releases the GIL first, so other Python threads run.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "binding.hpp"
#include "cia402/apps/elapsed_clock.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/306/eds.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/axis/session.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"

namespace cia402::python {

/// An axis session (the project's master, src/axis) over its link: on CAN a can_link on a channel
/// of its own, on EtherCAT an ecat_link on the line.
struct bus_axis {
  std::uint8_t node = 0;  ///< CAN: the node-ID; EtherCAT: the position on the line
  std::unique_ptr<canopen::channel> channel;
  std::unique_ptr<axes::drive_link> link;
  std::unique_ptr<axes::session> session;
};

/// What the sessions run on (a VirtualBus, a VirtualLine): one mutex over everything, the
/// notification that something moved, and time in periods. The sessions are polled in step().
class axis_host {
 public:
  virtual ~axis_host() = default;
  virtual bool virtual_time() const noexcept = 0;
  virtual bool closed_locked() const noexcept = 0;
  /// One period of time, the mutex held by the caller (an axis request on virtual time).
  virtual std::uint32_t step_period_locked() = 0;
  virtual const profile_ptr& profile_handle_ptr() const noexcept = 0;

  /// Puts an axis session on the host (the mutex held by the caller); from now on it is stepped.
  void add_axis_locked(std::shared_ptr<bus_axis> a) { axes_.push_back(std::move(a)); }
  void remove_axis_locked(const bus_axis* a) {
    std::erase_if(axes_, [a](const std::shared_ptr<bus_axis>& x) { return x.get() == a; });
  }

  std::mutex mutex_;
  std::condition_variable arrived_;  ///< something moved: a frame queued, a request ended

 protected:
  /// One step of `elapsed_us` of time, the mutex held.
  virtual void step_locked(std::uint32_t elapsed_us) = 0;

  /// Virtual time: `us` of time in steps of at most `period_us` each, then the waiters woken.
  void advance_in_periods(std::uint64_t us, std::uint32_t period_us) {
    std::lock_guard lock(mutex_);
    while (us > 0) {
      const auto slice = static_cast<std::uint32_t>(std::min<std::uint64_t>(us, period_us));
      step_locked(slice);
      us -= slice;
    }
    arrived_.notify_all();
  }

  /// The stepping thread of a host on wall time: a step every `period_us` until closed, the mutex
  /// held but while waiting, waiters on arrived_ woken after each step; wake_ ends a wait early.
  void run_on_wall_time(std::uint32_t period_us) {
    apps::elapsed_clock clock;
    const auto period = std::chrono::microseconds(period_us);
    auto next = std::chrono::steady_clock::now();
    std::unique_lock lock(mutex_);
    while (!closed_locked()) {
      step_locked(clock.take());
      arrived_.notify_all();
      next += period;
      const auto now = std::chrono::steady_clock::now();
      if (next < now) next = now;  // held up (a loaded machine): go on from now, not in a burst
      wake_.wait_until(lock, next, [this] { return closed_locked(); });
    }
  }

  std::vector<std::shared_ptr<bus_axis>> axes_;
  std::condition_variable wake_;
};

using steady = std::chrono::steady_clock;

class bus_core final : public axis_host {
 public:
  bus_core(profile_ptr p, const std::vector<std::uint8_t>& nodes, bool virtual_time,
           std::uint32_t period_us, std::uint16_t heartbeat_ms)
      : profile_(std::move(p)), virtual_time_(virtual_time), period_us_(period_us), heartbeat_ms_(heartbeat_ms) {
    for (const std::uint8_t id : nodes) {
      drives_.push_back(std::make_unique<apps::virtual_drive_node>(
          profile_->get(), bus_.attach(), apps::drive_node_config(id, 1000000, heartbeat_ms)));
      node_ids_.push_back(id);
    }
    if (!virtual_time_) stepper_ = std::thread([this] { run_on_wall_time(period_us_); });
  }
  ~bus_core() { close(); }
  bus_core(const bus_core&) = delete;
  bus_core& operator=(const bus_core&) = delete;

  /// Stops the stepping thread; the drives stay as they are (advance() still refused on wall time).
  void close() {
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      closed_ = true;
    }
    wake_.notify_all();
    arrived_.notify_all();
    if (stepper_.joinable()) stepper_.join();
  }

  /// Virtual time: `us` of time for every drive, in periods.
  void advance(std::uint64_t us) { advance_in_periods(us, period_us_); }

  std::uint32_t step_period_locked() override {
    step(period_us_);
    return period_us_;
  }
  /// A channel on the bus, the mutex held by the caller.
  std::unique_ptr<canopen::virtual_channel> attach_locked() { return bus_.attach(); }
  bool closed_locked() const noexcept override { return closed_; }

  std::unique_ptr<canopen::virtual_channel> attach() {
    std::lock_guard lock(mutex_);
    return bus_.attach();
  }

  std::string eds(std::uint8_t node) const {
    // A freshly started node of the same profile and node-ID on a bus of its own: CiA 306 gives the
    // values at power-up, not those of the running drive.
    canopen::virtual_bus scratch;
    auto ch = scratch.attach();
    drive402::sim_device dev(profile_->get());
    canopen::slave n(dev, *ch, apps::drive_node_config(node, 1000000, heartbeat_ms_));
    canopen::eds_info info;
    info.description += std::string(", profile ") + profile_->get().name;
    info.created_by = "cia402 Python package";
    info.node_id = node;
    std::ostringstream out;
    canopen::write_eds(n, info, out);
    return out.str();
  }

  const std::vector<std::uint8_t>& node_ids() const noexcept { return node_ids_; }
  bool virtual_time() const noexcept override { return virtual_time_; }
  std::uint32_t period_us() const noexcept { return period_us_; }
  bool closed() {
    std::lock_guard lock(mutex_);
    return closed_;
  }
  std::uint64_t elapsed_us() {
    std::lock_guard lock(mutex_);
    return elapsed_us_;
  }
  std::uint64_t frames() {
    std::lock_guard lock(mutex_);
    return bus_.frames();
  }
  const profile_ptr& profile_handle_ptr() const noexcept override { return profile_; }

 private:
  // One pass as `cia402 bus` makes it (bus_host::advance): the time first, then the frames that came
  // in meanwhile; then the sessions, the drives' answer and the sessions again, as `cia402 master`
  // runs its sessions beside an in-process drive.
  void step(std::uint32_t elapsed) {
    for (auto& d : drives_) (void)d->node().process(elapsed);
    for (auto& d : drives_) (void)d->poll(0);
    if (!axes_.empty()) {
      for (auto& a : axes_) (void)a->session->poll(elapsed);
      for (auto& d : drives_) (void)d->poll(0);
      for (auto& a : axes_) (void)a->session->poll(0);
    }
    elapsed_us_ += elapsed;
  }

  void step_locked(std::uint32_t elapsed) override { step(elapsed); }

  profile_ptr profile_;
  bool virtual_time_;
  std::uint32_t period_us_;
  std::uint16_t heartbeat_ms_;
  canopen::virtual_bus bus_;
  std::vector<std::unique_ptr<apps::virtual_drive_node>> drives_;
  std::vector<std::uint8_t> node_ids_;
  std::uint64_t elapsed_us_ = 0;
  bool closed_ = false;
  std::thread stepper_;
};

/// Binds cia402.canopen.Axis and VirtualBus.axis() (canopen_axis.cpp).
void bind_canopen_axis(py::module_& m, py::class_<bus_core, std::shared_ptr<bus_core>>& bus);

/// Binds cia402.ethercat (ethercat_line.cpp); its Axis is canopen's.
void bind_ethercat(py::module_& m, const py::module_& canopen);

/// An Axis over a link `make` builds (the mutex held) on `host`, stepped by the host from then on.
py::object make_axis(std::shared_ptr<axis_host> host, std::uint8_t id, const std::function<void(bus_axis&)>& make);

}  // namespace cia402::python
