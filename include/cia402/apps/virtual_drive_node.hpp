// The virtual CiA 402 drive as a CANopen node: the drive (drive402::sim_device) mounted unchanged on
// a CiA 301 node (canopen/301/slave.hpp) with the drive's objects and CiA 402's predefined PDO set, on
// a channel the node owns. What `cia402 bus`, `cia402 master`'s virtual bus, the tests and the
// benchmarks put on a bus, built one way.
//
// It lives in apps, the composition layer, and not in drive402: the drive stays a fieldbus-neutral
// device (it links the device interface and the simulator, nothing of CAN or EtherCAT), and its
// EtherCAT twin (virtual_drive_slave.hpp) needs the CoE slave, which lies beside canopen, not below
// drive402.
#pragma once

#include <cstdint>
#include <memory>

#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/can/channel.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/profile.hpp"
#include "cia402/sim/plant.hpp"

namespace cia402::apps {

/// A node configuration serving the virtual drive's objects (drive402::drive_objects(), serial number
/// = node-ID) with CiA 402's predefined PDO set (cia402::pdo_maps::can_rpdo / can_tpdo).
canopen::slave_config drive_node_config(std::uint8_t node_id, std::uint32_t sdo_timeout_us = 1000000,
                                        std::uint16_t heartbeat_ms = 0);

class virtual_drive_node {
 public:
  /// The profile must outlive the node. `config` defaults to drive_node_config(node ID 1).
  virtual_drive_node(const profile& p, std::unique_ptr<canopen::channel> ch,
                     const canopen::slave_config& config = drive_node_config(1),
                     const sim::plant_config& plant = {})
      : device_(std::make_unique<drive402::sim_device>(p, plant)),
        channel_(std::move(ch)),
        node_(std::make_unique<canopen::slave>(*device_, *channel_, config)) {}

  /// Every frame waiting on the node's channel, then `elapsed_us` of the node's and drive's time.
  std::uint32_t poll(std::uint32_t elapsed_us) { return node_->poll(*channel_, elapsed_us); }

  canopen::slave& node() noexcept { return *node_; }
  drive402::sim_device& device() noexcept { return *device_; }
  sim::virtual_drive& drive() noexcept { return device_->drive(); }
  canopen::channel& bus_channel() noexcept { return *channel_; }

 private:
  // Declared in this order so the node, which refers to both, goes first.
  std::unique_ptr<drive402::sim_device> device_;
  std::unique_ptr<canopen::channel> channel_;
  std::unique_ptr<canopen::slave> node_;
};

}  // namespace cia402::apps
