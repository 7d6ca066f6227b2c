// A line of virtual drives (apps/virtual_drive_slave.hpp) on the in-process wire as our master's
// link, on virtual time: frames pass every controller in order at once; waiting runs the drives'
// applications. `cut`: no frame comes back; `exchange_us`: a slow line, the drives run while a frame
// travels. Shared by the master's tests (master_test.cpp), the session's steering over it
// (ecat_session_steering_test.cpp) and bench/ethercat_bench.cpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/profile.hpp"

namespace cia402::ethercat::testing {

class drive_line final : public master_link {
 public:
  explicit drive_line(std::size_t drives) {
    for (std::size_t i = 0; i < drives; ++i) {
      slaves.push_back(std::make_unique<apps::virtual_drive_slave>(standard_profile(), static_cast<std::uint32_t>(i + 1)));
      wire.add(slaves.back()->controller());
    }
  }
  bool exchange(std::vector<std::uint8_t>& frame) override {
    if (cut) return false;
    const bool ok = wire.pass(frame) == frame_error::none;
    if (exchange_us != 0) wait_us(exchange_us);
    return ok;
  }
  std::uint64_t now_us() override { return now; }
  void wait_us(std::uint32_t us) override {
    now += us;
    for (auto& s : slaves) s->step(us);
  }

  std::vector<std::unique_ptr<apps::virtual_drive_slave>> slaves;
  chain wire;
  std::uint64_t now = 0;
  bool cut = false;
  std::uint32_t exchange_us = 0;
};

}  // namespace cia402::ethercat::testing
