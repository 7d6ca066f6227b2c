// A `cia402 bus` node: the simulator's virtual drive (sim_device) behind a CiA 301 node with the
// CiA 402 drive dictionary, on a channel it owns. What the bus server, `cia402 master`'s virtual bus,
// the tests and the benchmarks put on a bus, built one way.
#pragma once

#include <cstdint>
#include <memory>

#include "cia402/canopen/can/channel.hpp"
#include "cia402/canopen/402/drive_objects.hpp"
#include "cia402/canopen/402/sim_device.hpp"
#include "cia402/canopen/301/slave.hpp"
#include "cia402/profile.hpp"

namespace cia402::canopen {

class virtual_drive_node {
 public:
  /// The profile must outlive the node. `config` defaults to drive_node_config(node ID 1).
  virtual_drive_node(const profile& p, std::unique_ptr<channel> ch,
                     const slave_config& config = drive_node_config(1))
      : device_(std::make_unique<sim_device>(p)),
        channel_(std::move(ch)),
        node_(std::make_unique<slave>(*device_, *channel_, config)) {}

  /// Every frame waiting on the node's channel, then `elapsed_us` of the node's and drive's time.
  std::uint32_t poll(std::uint32_t elapsed_us) { return node_->poll(*channel_, elapsed_us); }

  slave& node() noexcept { return *node_; }
  sim_device& device() noexcept { return *device_; }
  sim::virtual_drive& drive() noexcept { return device_->drive(); }
  channel& bus_channel() noexcept { return *channel_; }

 private:
  // Declared in this order so the node, which refers to both, goes first.
  std::unique_ptr<sim_device> device_;
  std::unique_ptr<channel> channel_;
  std::unique_ptr<slave> node_;
};

}  // namespace cia402::canopen
