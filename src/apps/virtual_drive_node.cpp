#include "cia402/apps/virtual_drive_node.hpp"

#include "cia402/drive402/drive_objects.hpp"
#include "cia402/pdo_maps.hpp"

namespace cia402::apps {

canopen::slave_config drive_node_config(std::uint8_t node_id, std::uint32_t sdo_timeout_us,
                                        std::uint16_t heartbeat_ms) {
  canopen::slave_config c;
  c.node_id = node_id;
  c.sdo_timeout_us = sdo_timeout_us;
  c.heartbeat_ms = heartbeat_ms;
  c.objects = drive402::drive_objects();
  c.rpdo = pdo_maps::can_rpdo;
  c.tpdo = pdo_maps::can_tpdo;
  return c;
}

}  // namespace cia402::apps
