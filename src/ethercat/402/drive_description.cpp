#include "cia402/ethercat/402/drive_description.hpp"

#include <algorithm>
#include <string>

#include "cia402/drive402/drive_objects.hpp"
#include "cia402/pdo_maps.hpp"

namespace cia402::ethercat {
namespace {

using canopen::access;
using canopen::data_type;
using canopen::object_category;
using canopen::object_code;
using canopen::object_entry;
using canopen::sub_entry;

sub_entry var(std::uint8_t sub, std::string name, data_type t, access a, std::int64_t def = 0) {
  sub_entry e;
  e.sub = sub;
  e.name = std::move(name);
  e.type = t;
  e.acc = a;
  e.default_value = def;
  return e;
}

sub_entry limited(sub_entry e, std::int64_t low, std::int64_t high) {
  e.has_limits = true;
  e.low = low;
  e.high = high;
  return e;
}

object_entry group(std::uint16_t index, std::string name, object_code code, std::vector<sub_entry> subs) {
  object_entry o;
  o.index = index;
  o.name = std::move(name);
  o.code = code;
  o.category = object_category::optional;
  o.subs = std::move(subs);
  return o;
}

object_entry pdo_mapping(std::uint16_t index, std::string name, const std::vector<std::uint32_t>& defaults) {
  std::vector<sub_entry> subs;
  subs.push_back(limited(var(0, "Number of mapped objects", data_type::unsigned8, access::rw,
                             static_cast<std::int64_t>(defaults.size())),
                         0, max_pdo_entries));
  for (int i = 1; i <= max_pdo_entries; ++i) {
    const std::uint32_t def = i <= static_cast<int>(defaults.size()) ? defaults[static_cast<std::size_t>(i - 1)] : 0;
    subs.push_back(var(static_cast<std::uint8_t>(i), "Mapped object " + std::to_string(i), data_type::unsigned32,
                       access::rw, def));
  }
  return group(index, std::move(name), object_code::record, std::move(subs));
}

object_entry pdo_assignment(std::uint16_t index, std::string name, std::uint16_t first_pdo, bool assigned) {
  return group(index, std::move(name), object_code::array,
               {limited(var(0, "Number of assigned PDOs", data_type::unsigned8, access::rw, assigned ? 1 : 0), 0, 2),
                var(1, "PDO 1", data_type::unsigned16, access::rw, assigned ? first_pdo : 0),
                var(2, "PDO 2", data_type::unsigned16, access::rw, 0)});
}

const object_entry* find(const std::vector<object_entry>& t, std::uint16_t index) {
  const auto it = std::find_if(t.begin(), t.end(), [&](const object_entry& o) { return o.index == index; });
  return it == t.end() ? nullptr : &*it;
}

std::int64_t default_of(const std::vector<object_entry>& t, std::uint16_t index, std::uint8_t sub) {
  const object_entry* o = find(t, index);
  if (o == nullptr) return 0;
  for (const sub_entry& e : o->subs) {
    if (e.sub == sub) return e.default_value;
  }
  return 0;
}

// The PDO a mapping object's defaults describe, entry names and types from the dictionary.
pdo_description pdo_of(const std::vector<object_entry>& t, std::uint16_t index, std::uint8_t sm) {
  pdo_description p;
  p.index = index;
  p.sync_manager = sm;
  const object_entry* mapping = find(t, index);
  if (mapping == nullptr) return p;
  p.name = (index < 0x1A00 ? "RxPDO " : "TxPDO ") + std::to_string((index & 0xFF) + 1);
  const auto n = default_of(t, index, 0);
  for (std::int64_t i = 1; i <= n; ++i) {
    const auto m = static_cast<std::uint32_t>(default_of(t, index, static_cast<std::uint8_t>(i)));
    pdo_entry e;
    e.index = static_cast<std::uint16_t>(m >> 16);
    e.sub = static_cast<std::uint8_t>(m >> 8);
    e.bits = static_cast<std::uint8_t>(m);
    if (const object_entry* o = find(t, e.index)) {
      for (const sub_entry& s : o->subs) {
        if (s.sub == e.sub) {
          e.name = s.name;
          e.data_type = static_cast<std::uint16_t>(s.type);
        }
      }
    }
    p.entries.push_back(e);
  }
  return p;
}

}  // namespace

std::vector<object_entry> coe_drive_objects() {
  std::vector<object_entry> t = drive402::drive_objects();
  // Sub 4 of the identity is the serial number; on CAN it adds the node-ID, here the slave's
  // position (set per slave by drive_slave_description's caller through its serial).
  for (object_entry& o : t) {
    for (sub_entry& e : o.subs) e.plus_node_id = false;
  }
  const auto words = [](const pdo_map& m) {
    std::vector<std::uint32_t> w;
    for (std::size_t i = 0; i < m.count; ++i) w.push_back(m.entries[i].word());
    return w;
  };
  t.push_back(pdo_mapping(0x1600, "RxPDO 1 mapping", words(pdo_maps::ecat_rxpdo)));
  t.push_back(pdo_mapping(0x1601, "RxPDO 2 mapping", {}));
  t.push_back(pdo_mapping(0x1A00, "TxPDO 1 mapping", words(pdo_maps::ecat_txpdo)));
  t.push_back(pdo_mapping(0x1A01, "TxPDO 2 mapping", {}));
  t.push_back(group(0x1C00, "Sync manager communication type", object_code::array,
                    {var(0, "Number of used sync managers", data_type::unsigned8, access::ro, 4),
                     var(1, "SM0 (mailbox receive)", data_type::unsigned8, access::ro, 1),
                     var(2, "SM1 (mailbox send)", data_type::unsigned8, access::ro, 2),
                     var(3, "SM2 (outputs)", data_type::unsigned8, access::ro, 3),
                     var(4, "SM3 (inputs)", data_type::unsigned8, access::ro, 4)}));
  t.push_back(pdo_assignment(0x1C12, "RxPDO assign", 0x1600, true));
  t.push_back(pdo_assignment(0x1C13, "TxPDO assign", 0x1A00, true));
  std::sort(t.begin(), t.end(), [](const object_entry& a, const object_entry& b) { return a.index < b.index; });
  return t;
}

slave_description drive_slave_description(const std::vector<object_entry>& t, std::uint32_t serial) {
  slave_description d;
  d.vendor_id = static_cast<std::uint32_t>(default_of(t, 0x1018, 1));
  d.product_code = static_cast<std::uint32_t>(default_of(t, 0x1018, 2));
  d.revision = static_cast<std::uint32_t>(default_of(t, 0x1018, 3));
  d.serial = serial;
  d.vendor_name = "cia402 project";
  d.device_name = virtual_drive_device_name;
  d.group_name = "Drives";
  d.mailbox_out_start = mailbox_out_start;
  d.mailbox_out_size = mailbox_size;
  d.mailbox_in_start = mailbox_in_start;
  d.mailbox_in_size = mailbox_size;
  d.coe = true;
  d.coe_details = 0x01 | 0x02 | 0x04 | 0x08 | 0x20;  // SDO, SDO info, PDO assign, PDO config, complete access
  d.rx_pdos.push_back(pdo_of(t, static_cast<std::uint16_t>(default_of(t, 0x1C12, 1)), 2));
  d.tx_pdos.push_back(pdo_of(t, static_cast<std::uint16_t>(default_of(t, 0x1C13, 1)), 3));
  const auto bytes = [](const pdo_description& p) { return static_cast<std::uint16_t>((p.bit_size() + 7) / 8); };
  // Control bytes (register 0x0804): mailbox mode with ECAT write (0x26) / read (0x22) and PDI
  // interrupt; buffered (three-buffer) mode for process data, outputs with watchdog trigger (0x64).
  d.sync_managers = {{mailbox_out_start, mailbox_size, 0x26, 1, sm_type::mailbox_out},
                     {mailbox_in_start, mailbox_size, 0x22, 1, sm_type::mailbox_in},
                     {outputs_start, bytes(d.rx_pdos[0]), 0x64, 1, sm_type::outputs},
                     {inputs_start, bytes(d.tx_pdos[0]), 0x20, 1, sm_type::inputs}};
  d.fmmus = {fmmu_use::outputs, fmmu_use::inputs, fmmu_use::sm_status};
  return d;
}

}  // namespace cia402::ethercat
