// A machine: N virtual drives (up to many thousands) sharing one profile and one plant
// configuration, stepped together on one clock of virtual time. Each axis is one axis_state in a
// contiguous array, so a cycle of the machine is one pass over memory. With more than one thread
// the array is cut into contiguous parts, one per thread; axes never touch one another, so a
// machine on any number of threads gives the same states bit for bit.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <type_traits>
#include <vector>

#include "cia402/profile.hpp"
#include "cia402/sim/plant.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::sim {

class machine {
 public:
  /// Bytes of simulator state per axis (the core's axis included).
  static constexpr std::size_t bytes_per_axis = sizeof(axis_state);
  /// Below this many axes a thread's part takes less time than handing it over: one thread.
  static constexpr std::size_t axes_per_thread_at_least = 64;

  /// Throws std::invalid_argument when check_plant_config() refuses the configuration. The profile
  /// must outlive the machine. `threads` steps the axes on that many threads (the caller's
  /// included; 0 = one per hardware thread), fewer when there are not axes_per_thread_at_least
  /// axes for each. The helpers wait between cycles, busy for a few microseconds and then asleep.
  machine(const profile& p, std::size_t axes, const plant_config& config = {}, unsigned threads = 1);
  machine(const machine&) = delete;  // views point into it
  machine& operator=(const machine&) = delete;
  ~machine();

  /// One cycle of every axis; then the clock advances. Writes through drive() must not overlap a
  /// step (the caller's thread does both, as a master's cycle does).
  void step() noexcept {
    if (helpers_.empty()) {
      step_part(0);
    } else {
      step_on_threads();
    }
    ++cycle_;
  }

  /// One cycle in which `master(drive_view, std::size_t axis)` runs right before each axis steps,
  /// on the thread that steps it: a cyclic master's set-points (an RPDO before SYNC), written where
  /// the axis is hot in cache and spread over the threads. It must touch only the axis it is given
  /// and must not throw (the step is noexcept).
  template <typename Master>
  void step(Master&& master) noexcept {
    // The loop over a thread's part is instantiated here, with the master's call inlined in it.
    master_ = {&master, [](void* m, const profile& p, const plant_constants& k, axis_state* axes,
                           std::size_t first, std::size_t last) noexcept {
                 auto& each = *static_cast<std::remove_reference_t<Master>*>(m);
                 for (std::size_t i = first; i < last; ++i) {
                   each(drive_view(p, k, axes[i]), i);
                   step_axis(p, k, axes[i]);
                 }
               }};
    if (helpers_.empty()) {
      step_part(0);
    } else {
      step_on_threads();
    }
    master_ = {};
    ++cycle_;
  }

  std::size_t size() const noexcept { return axes_.size(); }
  drive_view drive(std::size_t i) noexcept { return {*profile_, constants_, axes_[i]}; }
  const axis_state& axis_at(std::size_t i) const noexcept { return axes_[i]; }

  std::uint64_t cycle() const noexcept { return cycle_; }
  std::uint64_t time_us() const noexcept { return cycle_ * constants_.cycle_us; }
  const plant_constants& constants() const noexcept { return constants_; }
  const profile& table() const noexcept { return *profile_; }
  /// The threads a cycle runs on, the caller's included.
  unsigned threads() const noexcept { return parts_; }

 private:
  void step_on_threads() noexcept;
  void step_part(std::size_t part) noexcept;
  void helper(std::size_t part) noexcept;
  void stop_helpers() noexcept;

  const profile* profile_;
  plant_constants constants_;
  std::vector<axis_state> axes_;
  std::uint64_t cycle_ = 0;
  struct per_axis_master {
    void* master = nullptr;
    // Steps axes [first, last), each after the master's call for it.
    void (*call)(void*, const profile&, const plant_constants&, axis_state*, std::size_t,
                 std::size_t) noexcept = nullptr;
  };
  per_axis_master master_;  // set during step(master) only

  // A cycle on threads: the caller bumps `go_`, each helper steps its part and counts `left_` down.
  std::atomic<std::uint64_t> go_{0};
  std::atomic<unsigned> left_{0};
  std::atomic<bool> stopping_{false};
  unsigned parts_ = 1;
  std::vector<std::thread> helpers_;
};

}  // namespace cia402::sim
