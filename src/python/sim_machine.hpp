// The machine Python holds (cia402.sim.Machine, and the simulated plant of cia402.Drive): a
// sim::machine with the profile it runs on, the traces of the axes it records, and a guard that
// refuses a second thread while it steps with the GIL released.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "binding.hpp"
#include "cia402/sim/machine.hpp"
#include "cia402/sim/trace.hpp"

namespace cia402::python {

/// A plant configuration from a dict of plant_config's field names (`cycle_us`, `brake_fitted`,
/// `home_switch_position`, ...; None for an optional switch position means none fitted).
/// ArgumentError for an unknown key, a wrong type or a configuration check_plant_config refuses.
sim::plant_config plant_config_from(const py::handle& plant);
/// Every field of a configuration, by the same names.
py::dict plant_config_dict(const sim::plant_config& c);

/// The recorded cycles of one axis, with what a trace file says about its source.
struct trace_data {
  std::vector<sim::trace_row> rows;
  sim::trace_info info;
};
using trace_ptr = std::shared_ptr<const trace_data>;

class machine_core {
 public:
  machine_core(profile_ptr p, std::size_t axes, const sim::plant_config& config, unsigned threads);

  /// Held while one call uses the machine; a second thread's call raises BusyError.
  class use {
   public:
    explicit use(machine_core& m);
    ~use() { m_.busy_.store(false, std::memory_order_release); }
    use(const use&) = delete;
    use& operator=(const use&) = delete;

   private:
    machine_core& m_;
  };

  sim::machine& get() noexcept { return machine_; }
  const sim::machine& get() const noexcept { return machine_; }
  const profile_ptr& table() const noexcept { return profile_; }
  const sim::plant_config& config() const noexcept { return config_; }
  std::size_t size() const noexcept { return machine_.size(); }
  /// ArgumentError unless i < size().
  std::size_t checked_axis(std::int64_t i) const;

  /// Steps `cycles` cycles, recording the traced axes. Call with the GIL released and a `use` held.
  void step_cycles(std::uint64_t cycles) noexcept;
  /// Steps one cycle per row of `values` (cycles x width, width 1 or size()), writing row k to
  /// index:sub of every axis before cycle k. The values are checked beforehand. Call with the GIL
  /// released and a `use` held.
  void stream(std::uint16_t index, std::uint8_t sub, std::span<const std::int64_t> values,
              std::size_t width) noexcept;
  /// Refuses (SdoError) a write of any of `values` to index:sub before anything is written: the
  /// result of a write depends only on the profile, the object and the value.
  void check_writes(std::uint16_t index, std::uint8_t sub, std::span<const std::int64_t> values) const;

  /// Starts (on) or stops recording an axis's cycles; a stopped trace keeps its rows until
  /// clear_trace().
  void record(std::size_t axis, bool on);
  bool recording(std::size_t axis) const;
  void clear_trace(std::size_t axis) { traces_.erase(axis); }
  /// A copy of what an axis recorded (empty when it never was).
  trace_ptr trace(std::size_t axis) const;

 private:
  void step_once() noexcept;

  profile_ptr profile_;
  sim::plant_config config_;
  sim::machine machine_;
  std::map<std::size_t, std::vector<sim::trace_row>> traces_;
  std::vector<std::size_t> recording_;  ///< the traced axes, in order
  std::atomic<bool> busy_{false};
};
using machine_ptr = std::shared_ptr<machine_core>;

/// One axis of a machine, as `Axis`: it keeps the machine alive.
struct axis_handle {
  machine_ptr machine;
  std::size_t index = 0;
  sim::drive_view view() const noexcept { return machine->get().drive(index); }
};

/// The outputs an axis's last cycle decided, as `Outputs`.
step_outputs outputs_of(const sim::drive_view& d);

/// Binds Axis (used by Machine and by a Drive on a simulated plant).
void bind_axis(py::module_& sim);
/// Makes a machine for Python, checking its arguments.
machine_ptr make_machine(std::int64_t axes, const py::object& profile, const py::object& plant,
                         std::int64_t threads);

}  // namespace cia402::python
