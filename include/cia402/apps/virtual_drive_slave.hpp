// The virtual CiA 402 drive as an EtherCAT slave: the drive (drive402::sim_device) mounted unchanged on
// a CoE slave (ethercat/slave/coe_slave.hpp) with the drive's objects and the default process data of
// the one table (cia402::pdo_maps::ecat_rxpdo / ecat_txpdo). What `cia402 ecat-slave`, the tests, the
// fuzz targets and the benchmarks put on a line, built one way; the CANopen twin is
// virtual_drive_node.hpp.
#pragma once

#include <cstdint>
#include <memory>

#include "cia402/drive402/sim_device.hpp"
#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "cia402/ethercat/slave/coe_slave.hpp"
#include "cia402/profile.hpp"
#include "cia402/sim/plant.hpp"

namespace cia402::apps {

/// A CoE slave configuration serving the virtual drive's objects (drive402::drive_objects(serial))
/// with the default RxPDO 0x1600 / TxPDO 0x1A00.
/// `cycle_us`: the time each step() is given (0x1C32:05, the shortest SYNC0 cycle it takes).
ethercat::coe_slave_config drive_slave_config(std::uint32_t serial = 0, std::uint32_t cycle_us = 1000);

class virtual_drive_slave {
 public:
  /// `serial` goes into 0x1018 sub 4 and the SII (the slave's position, say, so drives differ). The
  /// profile must outlive the slave.
  explicit virtual_drive_slave(const profile& p, std::uint32_t serial = 0, const sim::plant_config& plant = {},
                               std::uint32_t cycle_us = 1000)
      : device_(std::make_unique<drive402::sim_device>(p, plant)),
        slave_(std::make_unique<ethercat::coe_slave>(*device_, drive_slave_config(serial, cycle_us))) {}

  ethercat::esc& controller() noexcept { return slave_->controller(); }
  /// The application's cycle: AL requests, mailboxes, process data, then `elapsed_us` of the drive
  /// and of the watchdog.
  void step(std::uint32_t elapsed_us) { slave_->step(elapsed_us); }
  ethercat::al_state state() const noexcept { return slave_->state(); }
  const ethercat::slave_description& description() const noexcept { return slave_->description(); }
  std::uint16_t output_bytes() const noexcept { return slave_->output_bytes(); }
  std::uint16_t input_bytes() const noexcept { return slave_->input_bytes(); }
  ethercat::coe_slave& slave() noexcept { return *slave_; }
  drive402::sim_device& device() noexcept { return *device_; }

 private:
  // Declared in this order so the slave, which refers to the device, goes first.
  std::unique_ptr<drive402::sim_device> device_;
  std::unique_ptr<ethercat::coe_slave> slave_;
};

}  // namespace cia402::apps
