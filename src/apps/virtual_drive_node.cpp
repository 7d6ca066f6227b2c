#include "cia402/apps/virtual_drive_node.hpp"

#include <sstream>

#include "cia402/canopen/306/eds.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
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
  c.store_eds = true;
  return c;
}

std::string virtual_drive_node::powered_up_eds(const profile& p, const canopen::slave_config& config,
                                               const sim::plant_config& plant) {
  // A node of its own, on a bus of its own: the values at power-up, whatever the running node was
  // told since.
  canopen::virtual_bus bus;
  auto ch = bus.attach();
  drive402::sim_device dev(p, plant);
  canopen::slave_config fresh = config;
  fresh.eds_text = nullptr;
  canopen::slave node(dev, *ch, fresh);
  canopen::eds_info info;
  info.description += std::string(", profile ") + p.name;
  info.node_id = config.node_id;
  std::ostringstream out;
  canopen::write_eds(node, info, out);
  return out.str();
}

canopen::slave_config virtual_drive_node::with_stored_eds(const profile& p, canopen::slave_config config,
                                                          const sim::plant_config& plant) {
  if (config.store_eds && !config.eds_text) {
    canopen::slave_config of_it = config;
    config.eds_text = [&p, of_it, plant] { return powered_up_eds(p, of_it, plant); };
  }
  return config;
}

}  // namespace cia402::apps
