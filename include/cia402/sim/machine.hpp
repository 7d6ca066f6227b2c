// A machine: N virtual drives (up to many thousands) sharing one profile and one plant
// configuration, stepped together on one clock of virtual time. Each axis is one axis_state in a
// contiguous array, so a cycle of the machine is one pass over memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cia402/profile.hpp"
#include "cia402/sim/plant.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::sim {

class machine {
 public:
  /// Bytes of simulator state per axis (the core's axis included).
  static constexpr std::size_t bytes_per_axis = sizeof(axis_state);

  /// Throws std::invalid_argument when check_plant_config() refuses the configuration. The profile
  /// must outlive the machine.
  machine(const profile& p, std::size_t axes, const plant_config& config = {});
  machine(const machine&) = delete;  // views point into it
  machine& operator=(const machine&) = delete;

  /// One cycle of every axis, in index order; then the clock advances.
  void step() noexcept {
    for (axis_state& a : axes_) step_axis(*profile_, constants_, a);
    ++cycle_;
  }

  std::size_t size() const noexcept { return axes_.size(); }
  drive_view drive(std::size_t i) noexcept { return {*profile_, constants_, axes_[i]}; }
  const axis_state& axis_at(std::size_t i) const noexcept { return axes_[i]; }

  std::uint64_t cycle() const noexcept { return cycle_; }
  std::uint64_t time_us() const noexcept { return cycle_ * constants_.cycle_us; }
  const plant_constants& constants() const noexcept { return constants_; }
  const profile& table() const noexcept { return *profile_; }

 private:
  const profile* profile_;
  plant_constants constants_;
  std::vector<axis_state> axes_;
  std::uint64_t cycle_ = 0;
};

}  // namespace cia402::sim
