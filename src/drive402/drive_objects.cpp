#include "cia402/drive402/drive_objects.hpp"

#include <string>

#include "cia402/dictionary/object_builders.hpp"
#include "cia402/objects.hpp"

namespace cia402::drive402 {

using namespace dictionary;

namespace {

// The drive profile's objects, from the one table the whole project reads (cia402/objects.hpp); their
// values are the device's. An entry with sub-indices (0x607D, 0x608F, 0x6099, 0x60C2) is an ARRAY when
// its entries share one type, else a RECORD; its sub-index 0 is the table's own read-only count.
void add_profile_objects(std::vector<object_entry>& t) {
  using enum object_category;
  for (std::size_t i = 0; i < drive_object_count(); ++i) {
    const object_description& d = drive_object(i);
    const access acc = d.access == cia402::object_access::read_only    ? access::ro
                       : d.access == cia402::object_access::write_only ? access::wo
                                                                       : access::rw;
    sub_entry e = on_device(variable(d.sub, d.name, d.type, acc, d.default_value));
    e.pdo_mappable = d.pdo_mappable;
    // The limits a write must keep, where they are narrower than the type (a ramp of 0 would never
    // end): the EDS says so as LowLimit / HighLimit.
    if (d.low != type_min(d.type) || d.high != type_max(d.type)) e = limited(std::move(e), d.low, d.high);
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
    sub_entry count = variable(0, "Highest sub-index supported", data_type::unsigned8, access::ro, d.default_value);
    t.push_back(group(d.index, d.name, object_code::array, optional, {std::move(count)}));
  }
}

}  // namespace

std::vector<object_entry> drive_objects(std::uint32_t serial) {
  using enum object_category;
  std::vector<object_entry> t;
  t.push_back(single(0x1000, mandatory, variable(0, "Device type", data_type::unsigned32, access::ro,
                                                 device_type)));
  // 0x1001 is the drive's register; the node adds bit 4 (communication) for its own errors.
  t.push_back(single(0x1001, mandatory,
                     mappable(on_device(variable(0, "Error register", data_type::unsigned8, access::ro)))));
  t.push_back(single(0x1008, optional, text(0, "Manufacturer device name", access::constant,
                                            virtual_drive_device_name, 0)));
  t.push_back(single(0x1009, optional, text(0, "Manufacturer hardware version", access::constant, hardware_version, 0)));
  t.push_back(single(0x100A, optional, text(0, "Manufacturer software version", access::constant, software_version, 0)));
  t.push_back(group(0x1018, "Identity object", object_code::record, mandatory,
                    {variable(0, "Highest sub-index supported", data_type::unsigned8, access::ro, 4),
                     variable(1, "Vendor-ID", data_type::unsigned32, access::ro, vendor_id),
                     variable(2, "Product code", data_type::unsigned32, access::ro, product_code),
                     variable(3, "Revision number", data_type::unsigned32, access::ro, revision_number),
                     plus_node_id(variable(4, "Serial number", data_type::unsigned32, access::ro, serial))}));
  t.push_back(single(device_label_index, manufacturer,
                     text(0, "Device label", access::rw, "", device_label_capacity)));
  t.push_back(single(fault_injection_index, manufacturer,
                     on_device(variable(0, "Fault injection", data_type::unsigned16, access::wo))));
  add_profile_objects(t);
  return t;
}

}  // namespace cia402::drive402
