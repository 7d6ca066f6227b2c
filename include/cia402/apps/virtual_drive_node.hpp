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
#include <string>

#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/can/channel.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/profile.hpp"
#include "cia402/sim/plant.hpp"

namespace cia402::apps {

/// A node configuration serving the virtual drive's objects (drive402::drive_objects(), serial number
/// = node-ID) with CiA 402's predefined PDO set (cia402::pdo_maps::can_rpdo / can_tpdo), and 0x1021 /
/// 0x1022 (its EDS stored in the node; virtual_drive_node fills 0x1021).
canopen::slave_config drive_node_config(std::uint8_t node_id, std::uint32_t sdo_timeout_us = 1000000,
                                        std::uint16_t heartbeat_ms = 0);

class virtual_drive_node {
 public:
  /// The profile must outlive the node. `config` defaults to drive_node_config(node ID 1). With
  /// config.store_eds and no eds_text of its own, 0x1021 gives the EDS `cia402 eds --node N` writes
  /// for it (of a node of this profile and configuration as it powers up; the date aside), made when
  /// first read.
  virtual_drive_node(const profile& p, std::unique_ptr<canopen::channel> ch,
                     const canopen::slave_config& config = drive_node_config(1),
                     const sim::plant_config& plant = {})
      : device_(std::make_unique<drive402::sim_device>(p, plant)),
        channel_(std::move(ch)),
        node_(std::make_unique<canopen::slave>(*device_, *channel_, with_stored_eds(p, config, plant))) {}

  /// Every frame waiting on the node's channel, then `elapsed_us` of the node's and drive's time.
  std::uint32_t poll(std::uint32_t elapsed_us) { return node_->poll(*channel_, elapsed_us); }

  canopen::slave& node() noexcept { return *node_; }
  drive402::sim_device& device() noexcept { return *device_; }
  sim::virtual_drive& drive() noexcept { return device_->drive(); }
  canopen::channel& bus_channel() noexcept { return *channel_; }

  /// The EDS of a freshly powered-up node of profile `p` and configuration `config` (as `cia402 eds`
  /// writes it, for config.node_id).
  static std::string powered_up_eds(const profile& p, const canopen::slave_config& config, const sim::plant_config& plant);

 private:
  static canopen::slave_config with_stored_eds(const profile& p, canopen::slave_config config, const sim::plant_config& plant);

  // Declared in this order so the node, which refers to both, goes first.
  std::unique_ptr<drive402::sim_device> device_;
  std::unique_ptr<canopen::channel> channel_;
  std::unique_ptr<canopen::slave> node_;
};

}  // namespace cia402::apps
