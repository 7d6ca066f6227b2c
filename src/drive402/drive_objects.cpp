#include "cia402/canopen/402/drive_objects.hpp"

#include <string>

#include "cia402/objects.hpp"

namespace cia402::canopen {
namespace {

sub_entry var(std::uint8_t sub, std::string name, data_type t, access a, std::int64_t def = 0) {
  sub_entry e;
  e.sub = sub;
  e.name = std::move(name);
  e.type = t;
  e.acc = a;
  e.default_value = def;
  return e;
}

sub_entry mappable(sub_entry e) {
  e.pdo_mappable = true;
  return e;
}

sub_entry on_device(sub_entry e) {
  e.where = backing::device;
  return e;
}

sub_entry plus_node(sub_entry e) {
  e.plus_node_id = true;
  return e;
}

sub_entry limited(sub_entry e, std::int64_t low, std::int64_t high) {
  e.has_limits = true;
  e.low = low;
  e.high = high;
  return e;
}

sub_entry text(std::uint8_t sub, std::string name, access a, std::string def, std::size_t cap) {
  sub_entry e = var(sub, std::move(name), data_type::visible_string, a);
  e.default_text = std::move(def);
  e.capacity = cap;
  return e;
}

object_entry single(std::uint16_t index, object_category c, sub_entry e) {
  object_entry o;
  o.index = index;
  o.name = e.name;
  o.code = object_code::var;
  o.category = c;
  o.subs.push_back(std::move(e));
  return o;
}

object_entry group(std::uint16_t index, std::string name, object_code code, object_category c,
                   std::vector<sub_entry> subs) {
  object_entry o;
  o.index = index;
  o.name = std::move(name);
  o.code = code;
  o.category = c;
  o.subs = std::move(subs);
  return o;
}

std::uint32_t map_entry(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) {
  return (static_cast<std::uint32_t>(index) << 16) | (static_cast<std::uint32_t>(sub) << 8) | bits;
}

constexpr std::uint32_t pdo_invalid = 0x80000000u;

object_entry pdo_mapping(std::uint16_t index, std::string name,
                         const std::vector<std::uint32_t>& defaults) {
  std::vector<sub_entry> subs;
  subs.push_back(limited(var(0, "Number of mapped objects", data_type::unsigned8, access::rw,
                             static_cast<std::int64_t>(defaults.size())),
                         0, max_mapped_objects));
  for (int i = 1; i <= max_mapped_objects; ++i) {
    const std::uint32_t def = i <= static_cast<int>(defaults.size()) ? defaults[i - 1] : 0;
    subs.push_back(var(static_cast<std::uint8_t>(i), "Mapped object " + std::to_string(i),
                       data_type::unsigned32, access::rw, def));
  }
  return group(index, std::move(name), object_code::record, object_category::optional,
               std::move(subs));
}

}  // namespace

std::vector<object_entry> drive_objects() {
  using enum object_category;
  std::vector<object_entry> t;

  t.push_back(single(0x1000, mandatory, var(0, "Device type", data_type::unsigned32, access::ro,
                                            device_type_cia402_servo)));
  // 0x1001 is the drive's register; the node adds bit 4 (communication) for its own errors.
  t.push_back(single(0x1001, mandatory, mappable(on_device(var(0, "Error register",
                                                               data_type::unsigned8, access::ro)))));
  t.push_back(single(0x1005, optional,
                     var(0, "COB-ID SYNC message", data_type::unsigned32, access::rw, 0x80)));
  t.push_back(single(0x1008, optional, text(0, "Manufacturer device name", access::constant,
                                            virtual_drive_device_name, 0)));
  t.push_back(single(0x1009, optional,
                     text(0, "Manufacturer hardware version", access::constant, "virtual", 0)));
  t.push_back(single(0x100A, optional,
                     text(0, "Manufacturer software version", access::constant, "0.1.0", 0)));
  t.push_back(single(0x1014, optional,
                     plus_node(var(0, "COB-ID EMCY", data_type::unsigned32, access::ro, 0x80))));
  {
    std::vector<sub_entry> subs;
    subs.push_back(var(0, "Highest sub-index supported", data_type::unsigned8, access::ro,
                       heartbeat_consumers));
    for (int i = 1; i <= heartbeat_consumers; ++i) {
      subs.push_back(var(static_cast<std::uint8_t>(i), "Consumer heartbeat time " + std::to_string(i),
                         data_type::unsigned32, access::rw));
    }
    t.push_back(group(0x1016, "Consumer heartbeat time", object_code::array, optional,
                      std::move(subs)));
  }
  t.push_back(single(0x1017, optional,
                     var(0, "Producer heartbeat time", data_type::unsigned16, access::rw)));
  t.push_back(group(0x1018, "Identity object", object_code::record, mandatory,
                    {var(0, "Highest sub-index supported", data_type::unsigned8, access::ro, 4),
                     var(1, "Vendor-ID", data_type::unsigned32, access::ro, 0),
                     var(2, "Product code", data_type::unsigned32, access::ro, 0x402),
                     var(3, "Revision number", data_type::unsigned32, access::ro, 0x00010000),
                     plus_node(var(4, "Serial number", data_type::unsigned32, access::ro, 0))}));
  t.push_back(group(
      0x1200, "SDO server parameter", object_code::record, optional,
      {var(0, "Highest sub-index supported", data_type::unsigned8, access::ro, 2),
       plus_node(var(1, "COB-ID client to server", data_type::unsigned32, access::ro, 0x600)),
       plus_node(var(2, "COB-ID server to client", data_type::unsigned32, access::ro, 0x580))}));

  // CiA 402 predefined PDO set. PDO 3 carries the position for a cyclic synchronous position
  // master: taken at (RPDO) and sent on (TPDO) every SYNC.
  const std::vector<std::uint32_t> rpdo_maps[pdo_count] = {
      {map_entry(0x6040, 0, 16)},
      {map_entry(0x6040, 0, 16), map_entry(0x6060, 0, 8)},
      {map_entry(0x6040, 0, 16), map_entry(0x607A, 0, 32)},
      {map_entry(0x6040, 0, 16), map_entry(0x60FF, 0, 32)}};
  constexpr std::int64_t event_driven = 255;
  constexpr std::int64_t every_sync = 1;
  const std::int64_t transmission[pdo_count] = {event_driven, event_driven, every_sync, event_driven};
  // A master can rely on each TPDO at least every second (event timer), and the one that carries the
  // velocity sends at most every 10 ms while the drive ramps (inhibit time): without them a ramping
  // drive sent about 850 frames/s. The status word alone (TPDO1) has no inhibit time, so every
  // state change arrives.
  const std::uint16_t tpdo_inhibit_100us[pdo_count] = {0, 0, 0, 100};
  constexpr std::uint16_t tpdo_event_timer_ms = 1000;
  const std::vector<std::uint32_t> tpdo_maps[pdo_count] = {
      {map_entry(0x6041, 0, 16)},
      {map_entry(0x6041, 0, 16), map_entry(0x6061, 0, 8)},
      {map_entry(0x6041, 0, 16), map_entry(0x6064, 0, 32)},
      {map_entry(0x6041, 0, 16), map_entry(0x606C, 0, 32)}};
  for (int n = 0; n < pdo_count; ++n) {
    const auto num = std::to_string(n + 1);
    const std::int64_t off = 0x100 * n;
    const std::int64_t invalid = rpdo_maps[n].empty() ? pdo_invalid : 0;
    t.push_back(group(
        static_cast<std::uint16_t>(0x1400 + n), "RPDO" + num + " communication parameter",
        object_code::record, optional,
        {var(0, "Highest sub-index supported", data_type::unsigned8, access::ro, 2),
         plus_node(var(1, "COB-ID used by RPDO", data_type::unsigned32, access::rw,
                       invalid + 0x200 + off)),
         var(2, "Transmission type", data_type::unsigned8, access::rw, transmission[n])}));
    t.push_back(pdo_mapping(static_cast<std::uint16_t>(0x1600 + n), "RPDO" + num + " mapping parameter",
                            rpdo_maps[n]));
  }
  for (int n = 0; n < pdo_count; ++n) {
    const auto num = std::to_string(n + 1);
    const std::int64_t off = 0x100 * n;
    const std::int64_t invalid = tpdo_maps[n].empty() ? pdo_invalid : 0;
    t.push_back(group(
        static_cast<std::uint16_t>(0x1800 + n), "TPDO" + num + " communication parameter",
        object_code::record, optional,
        {var(0, "Highest sub-index supported", data_type::unsigned8, access::ro, 5),
         plus_node(var(1, "COB-ID used by TPDO", data_type::unsigned32, access::rw,
                       invalid + 0x180 + off)),
         var(2, "Transmission type", data_type::unsigned8, access::rw, transmission[n]),
         var(3, "Inhibit time", data_type::unsigned16, access::rw, tpdo_inhibit_100us[n]),
         var(5, "Event timer", data_type::unsigned16, access::rw, tpdo_event_timer_ms)}));
    t.push_back(pdo_mapping(static_cast<std::uint16_t>(0x1A00 + n), "TPDO" + num + " mapping parameter",
                            tpdo_maps[n]));
  }

  t.push_back(single(device_label_index, manufacturer,
                     text(0, "Device label", access::rw, "", device_label_capacity)));
  t.push_back(single(fault_injection_index, manufacturer,
                     on_device(var(0, "Fault injection", data_type::unsigned16, access::wo))));

  // The drive profile's objects, from the one table the whole project reads (cia402/objects.hpp);
  // their values are the device's.
  // An entry with sub-indices (0x607D, 0x608F, 0x6099, 0x60C2) is an ARRAY when its entries share
  // one type, else a RECORD; its sub-index 0 is the table's own read-only count.
  for (std::size_t i = 0; i < drive_object_count(); ++i) {
    const object_description& d = drive_object(i);
    const access acc = d.access == cia402::object_access::read_only    ? access::ro
                       : d.access == cia402::object_access::write_only ? access::wo
                                                               : access::rw;
    sub_entry e = on_device(var(d.sub, d.name, static_cast<data_type>(d.type), acc, d.default_value));
    e.pdo_mappable = d.pdo_mappable;
    // The limits a write must keep, where they are narrower than the type (a ramp of 0 would never
    // end): the EDS says so as LowLimit / HighLimit.
    if (d.low != type_low(d.type) || d.high != type_high(d.type)) e = limited(std::move(e), d.low, d.high);
    const bool has_subs = i + 1 < drive_object_count() && drive_object(i + 1).index == d.index;
    if (d.sub != 0 || !has_subs) {
      if (d.sub != 0 && !t.empty() && t.back().index == d.index) {
        if (t.back().subs.size() > 1 && t.back().subs[1].type != e.type) t.back().code = object_code::record;
        t.back().subs.push_back(std::move(e));
        continue;
      }
      const bool mandatory_object = d.index == 0x6040 || d.index == 0x6041;
      t.push_back(single(d.index, mandatory_object ? mandatory : optional, std::move(e)));
      continue;
    }
    // Sub-index 0 of an array: a constant count, served by the dictionary itself.
    sub_entry count = var(0, "Highest sub-index supported", data_type::unsigned8, access::ro, d.default_value);
    t.push_back(group(d.index, d.name, object_code::array, optional, {std::move(count)}));
  }
  return t;
}

slave_config drive_node_config(std::uint8_t node_id, std::uint32_t sdo_timeout_us,
                               std::uint16_t heartbeat_ms) {
  slave_config c;
  c.node_id = node_id;
  c.sdo_timeout_us = sdo_timeout_us;
  c.heartbeat_ms = heartbeat_ms;
  c.objects = drive_objects();
  return c;
}

}  // namespace cia402::canopen
