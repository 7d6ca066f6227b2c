// The communication objects of CiA 301 that the node serves itself, beside the services that use
// them (the error history 0x1003 and EMCY 0x1014, SYNC 0x1005, heartbeat 0x1016 / 0x1017, SDO server 0x1200, PDOs 0x1400..0x1BFF),
// with the defaults of the predefined connection set (CiA 301 §7.3.5) and the PDO defaults the
// layer above gives (slave_config::rpdo / tpdo).
#include <algorithm>
#include <stdexcept>
#include <string>

#include "cia402/dictionary/error_history.hpp"
#include "cia402/hex_text.hpp"
#include "cia402/dictionary/object_builders.hpp"
#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/can/frame.hpp"

namespace cia402::canopen {
namespace {

void add_pdos(std::vector<dictionary::object_entry>& t, const slave_config& c) {
  for (const bool transmit : {false, true}) {
    const std::string kind = transmit ? "TPDO" : "RPDO";
    const std::uint16_t offset = transmit ? 0x400 : 0;
    for (int n = 0; n < pdo_count; ++n) {
      const pdo_map& m = (transmit ? c.tpdo : c.rpdo)[static_cast<std::size_t>(n)];
      const auto name = kind + std::to_string(n + 1);
      const std::uint32_t cob_id = (m.count == 0 || !m.valid ? pdo_cob_invalid : 0u) +
                                   (transmit ? cob::tpdo1 : cob::rpdo1) + 0x100u * static_cast<std::uint32_t>(n);
      std::vector<dictionary::sub_entry> parameters = {
          variable(0, "Highest sub-index supported", data_type::unsigned8, dictionary::access::ro, transmit ? 5 : 2),
          plus_node_id(variable(1, "COB-ID used by " + kind, data_type::unsigned32, dictionary::access::rw, cob_id)),
          variable(2, "Transmission type", data_type::unsigned8, dictionary::access::rw, m.transmission_type)};
      if (transmit) {
        parameters.push_back(variable(3, "Inhibit time", data_type::unsigned16, dictionary::access::rw, m.inhibit_100us));
        parameters.push_back(variable(5, "Event timer", data_type::unsigned16, dictionary::access::rw, m.event_timer_ms));
      }
      t.push_back(group(static_cast<std::uint16_t>(0x1400 + offset + n), name + " communication parameter",
                        dictionary::object_code::record, dictionary::object_category::optional, std::move(parameters)));
      t.push_back(dictionary::pdo_mapping(static_cast<std::uint16_t>(0x1600 + offset + n), name + " mapping parameter", m,
                              max_mapped_objects));
    }
  }
}

}  // namespace

std::vector<dictionary::object_entry> communication_objects(const slave_config& c) {
  using enum dictionary::object_category;
  std::vector<dictionary::object_entry> t;
  t.push_back(dictionary::error_history_object());
  t.push_back(single(0x1005, optional, variable(0, "COB-ID SYNC message", data_type::unsigned32, dictionary::access::rw, cob::sync)));
  t.push_back(single(0x1014, optional,
                     plus_node_id(variable(0, "COB-ID EMCY", data_type::unsigned32, dictionary::access::ro, cob::emcy))));
  std::vector<dictionary::sub_entry> consumers;
  consumers.push_back(variable(0, "Highest sub-index supported", data_type::unsigned8, dictionary::access::ro, heartbeat_consumers));
  for (int i = 1; i <= heartbeat_consumers; ++i) {
    consumers.push_back(variable(static_cast<std::uint8_t>(i), "Consumer heartbeat time " + std::to_string(i),
                                 data_type::unsigned32, dictionary::access::rw));
  }
  t.push_back(group(0x1016, "Consumer heartbeat time", dictionary::object_code::array, optional, std::move(consumers)));
  t.push_back(single(0x1017, optional,
                     variable(0, "Producer heartbeat time", data_type::unsigned16, dictionary::access::rw, c.heartbeat_ms)));
  t.push_back(group(0x1200, "SDO server parameter", dictionary::object_code::record, optional,
                    {variable(0, "Highest sub-index supported", data_type::unsigned8, dictionary::access::ro, 2),
                     plus_node_id(variable(1, "COB-ID client to server", data_type::unsigned32, dictionary::access::ro, cob::sdo_rx)),
                     plus_node_id(variable(2, "COB-ID server to client", data_type::unsigned32, dictionary::access::ro, cob::sdo_tx))}));
  if (c.store_eds) {
    t.push_back(single(0x1021, optional, text(0, "Store EDS", dictionary::access::ro, "", 0)));
    t.push_back(single(0x1022, optional, variable(0, "Store format", data_type::unsigned8, dictionary::access::ro, 0)));
  }
  add_pdos(t, c);
  return t;
}

std::vector<dictionary::object_entry> node_objects(const slave_config& c) {
  std::vector<dictionary::object_entry> t = communication_objects(c);
  for (const dictionary::object_entry& o : c.objects) {
    if (std::any_of(t.begin(), t.end(), [&](const dictionary::object_entry& mine) { return mine.index == o.index; })) {
      throw std::invalid_argument("the device's table has " + std::string(to_hex(o.index, 4).c_str()) +
                                  ", a communication object the CiA 301 node serves itself");
    }
  }
  t.insert(t.end(), c.objects.begin(), c.objects.end());
  std::sort(t.begin(), t.end(), [](const dictionary::object_entry& a, const dictionary::object_entry& b) { return a.index < b.index; });
  return t;
}

}  // namespace cia402::canopen
