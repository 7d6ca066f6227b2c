#include "cia402/apps/virtual_drive_slave.hpp"

#include "cia402/drive402/drive_objects.hpp"
#include "cia402/pdo_maps.hpp"

namespace cia402::apps {

ethercat::coe_slave_config drive_slave_config(std::uint32_t serial, std::uint32_t cycle_us) {
  ethercat::coe_slave_config c;
  c.application_cycle_us = cycle_us;
  c.objects = drive402::drive_objects(serial);
  c.rx_pdo = pdo_maps::ecat_rxpdo;
  c.tx_pdo = pdo_maps::ecat_txpdo;
  c.vendor_name = "cia402 project";
  c.group_name = "Drives";
  return c;
}

}  // namespace cia402::apps
