// The objects a CoE slave serves itself, beside the process data they configure, and the description
// (SII, ESI) of a slave read from its dictionary.
#include <algorithm>
#include <stdexcept>
#include <string>

#include "cia402/dictionary/error_history.hpp"
#include "cia402/dictionary/object_builders.hpp"
#include "cia402/ethercat/slave/coe_slave.hpp"
#include "cia402/hex_text.hpp"

namespace cia402::ethercat {
namespace {

using dictionary::access;
using cia402::data_type;
using dictionary::object_category;
using dictionary::object_code;
using dictionary::object_entry;
using dictionary::sub_entry;
using dictionary::variable;

object_entry pdo_assignment(std::uint16_t index, std::string name, std::uint16_t first_pdo, bool assigned) {
  return dictionary::group(
      index, std::move(name), object_code::array, object_category::optional,
      {dictionary::limited(variable(0, "Number of assigned PDOs", data_type::unsigned8, access::rw, assigned ? 1 : 0), 0, 2),
       variable(1, "PDO 1", data_type::unsigned16, access::rw, assigned ? first_pdo : 0),
       variable(2, "PDO 2", data_type::unsigned16, access::rw, 0)});
}

// 0x1C32 / 0x1C33 sync manager output / input parameter (ETG.1020 §5.3, ETG.6010): the sync mode a
// master chooses (written in PRE-OP; DC SYNC0 also taken from 0x0981 on the way to SAFE-OP), the
// cycle, the modes this slave offers (free run, SM-synchronous, DC SYNC0) and what SYNC0 ran.
object_entry sync_manager_parameter(std::uint16_t index, std::string name, std::uint32_t cycle_us) {
  return dictionary::group(
      index, std::move(name), object_code::record, object_category::optional,
      {variable(0, "Number of sub-indices", data_type::unsigned8, access::ro, sync_parameter::sync_error_count),
       variable(sync_parameter::mode, "Sync mode", data_type::unsigned16, access::rw, sync_mode::free_run),
       variable(sync_parameter::cycle_time, "Cycle time", data_type::unsigned32, access::rw, 0),
       variable(3, "Shift time", data_type::unsigned32, access::ro, 0),
       variable(sync_parameter::supported, "Sync modes supported", data_type::unsigned16, access::ro,
                sync_parameter::supported_modes),
       variable(sync_parameter::minimum_cycle_time, "Minimum cycle time", data_type::unsigned32, access::ro,
                std::int64_t{cycle_us} * 1000),
       variable(6, "Calc and copy time", data_type::unsigned32, access::ro, 0),
       // Subs 7 and 8 as ETG.1020 §5.3 and SOES have them, so a master that reads every sub up to
       // sub 0's count (SOEM's slaveinfo -sdo) finds no gap. The command (sub 8: measure the local
       // cycle, reset the error counters) is not offered: it reads 0 and a write is refused.
       variable(7, "Minimum delay time", data_type::unsigned32, access::ro, 0),
       variable(8, "Get cycle time", data_type::unsigned16, access::ro, 0),
       variable(9, "Delay time", data_type::unsigned32, access::ro, 0),
       variable(sync_parameter::sync0_cycle_time, "Sync0 cycle time", data_type::unsigned32, access::ro, 0),
       variable(sync_parameter::sync_error_count, "SM event missed", data_type::unsigned16, access::ro, 0)});
}

const object_entry* find(const std::vector<object_entry>& t, std::uint16_t index) {
  const auto it = std::find_if(t.begin(), t.end(), [&](const object_entry& o) { return o.index == index; });
  return it == t.end() ? nullptr : &*it;
}

const sub_entry* find(const std::vector<object_entry>& t, std::uint16_t index, std::uint8_t sub) {
  const object_entry* o = find(t, index);
  if (o == nullptr) return nullptr;
  const auto it = std::find_if(o->subs.begin(), o->subs.end(), [&](const sub_entry& e) { return e.sub == sub; });
  return it == o->subs.end() ? nullptr : &*it;
}

std::int64_t default_of(const std::vector<object_entry>& t, std::uint16_t index, std::uint8_t sub) {
  const sub_entry* e = find(t, index, sub);
  return e != nullptr ? e->default_value : 0;
}

// The PDO a mapping object's defaults describe, entry names and types from the dictionary.
pdo_description pdo_of(const std::vector<object_entry>& t, std::uint16_t index, std::uint8_t sm) {
  pdo_description p;
  p.index = index;
  p.sync_manager = sm;
  if (find(t, index) == nullptr) return p;
  p.name = (index < 0x1A00 ? "RxPDO " : "TxPDO ") + std::to_string((index & 0xFF) + 1);
  const auto n = default_of(t, index, 0);
  for (std::int64_t i = 1; i <= n; ++i) {
    const auto m = static_cast<std::uint32_t>(default_of(t, index, static_cast<std::uint8_t>(i)));
    pdo_entry e;
    e.index = static_cast<std::uint16_t>(m >> 16);
    e.sub = static_cast<std::uint8_t>(m >> 8);
    e.bits = static_cast<std::uint8_t>(m);
    if (is_pdo_padding(e.index, pdo_padding::dummies_and_gaps)) {
      // Padding: a dummy is of its data type (its index), a gap of none (the ESI gives it no type).
      if (e.index != 0) e.data_type = e.index;
    } else if (const sub_entry* s = find(t, e.index, e.sub)) {
      e.name = s->name;
      e.data_type = static_cast<std::uint16_t>(s->type);
    }
    p.entries.push_back(e);
  }
  return p;
}

}  // namespace

std::vector<object_entry> coe_communication_objects(const coe_slave_config& c) {
  std::vector<object_entry> t;
  // The emergencies' history (CiA 301 §7.5.2.5), as the CANopen node keeps it.
  t.push_back(dictionary::error_history_object());
  // EtherCAT has no heartbeat (the sync manager watchdog watches the master): 0x1017 is stored and
  // does nothing, so a master that sets it on every bus is not refused.
  t.push_back(dictionary::single(0x1017, object_category::optional,
                              variable(0, "Producer heartbeat time", data_type::unsigned16, access::rw)));
  t.push_back(dictionary::pdo_mapping(0x1600, "RxPDO 1 mapping", c.rx_pdo, max_pdo_entries));
  t.push_back(dictionary::pdo_mapping(0x1601, "RxPDO 2 mapping", pdo_map{}, max_pdo_entries));
  t.push_back(dictionary::pdo_mapping(0x1A00, "TxPDO 1 mapping", c.tx_pdo, max_pdo_entries));
  t.push_back(dictionary::pdo_mapping(0x1A01, "TxPDO 2 mapping", pdo_map{}, max_pdo_entries));
  t.push_back(dictionary::group(0x1C00, "Sync manager communication type", object_code::array, object_category::optional,
                             {variable(0, "Number of used sync managers", data_type::unsigned8, access::ro, 4),
                              variable(1, "SM0 (mailbox receive)", data_type::unsigned8, access::ro, 1),
                              variable(2, "SM1 (mailbox send)", data_type::unsigned8, access::ro, 2),
                              variable(3, "SM2 (outputs)", data_type::unsigned8, access::ro, 3),
                              variable(4, "SM3 (inputs)", data_type::unsigned8, access::ro, 4)}));
  t.push_back(pdo_assignment(0x1C12, "RxPDO assign", 0x1600, c.rx_pdo.count != 0));
  t.push_back(pdo_assignment(0x1C13, "TxPDO assign", 0x1A00, c.tx_pdo.count != 0));
  t.push_back(sync_manager_parameter(sync_parameter::outputs, "SM output parameter", c.application_cycle_us));
  t.push_back(sync_manager_parameter(sync_parameter::inputs, "SM input parameter", c.application_cycle_us));
  return t;
}

std::vector<object_entry> coe_objects(const coe_slave_config& c) {
  std::vector<object_entry> t = coe_communication_objects(c);
  for (const object_entry& o : c.objects) {
    if (find(t, o.index) != nullptr) {
      throw std::invalid_argument("the device's table has " + std::string(to_hex(o.index, 4).c_str()) +
                                  ", a communication object the CoE slave serves itself");
    }
  }
  t.insert(t.end(), c.objects.begin(), c.objects.end());
  std::sort(t.begin(), t.end(), [](const object_entry& a, const object_entry& b) { return a.index < b.index; });
  return t;
}

slave_description coe_slave_description(const coe_slave_config& c) {
  const std::vector<object_entry> t = coe_objects(c);
  slave_description d;
  d.vendor_id = static_cast<std::uint32_t>(default_of(t, 0x1018, 1));
  d.product_code = static_cast<std::uint32_t>(default_of(t, 0x1018, 2));
  d.revision = static_cast<std::uint32_t>(default_of(t, 0x1018, 3));
  d.serial = static_cast<std::uint32_t>(default_of(t, 0x1018, 4));  // a CoE dictionary has no node-ID to add
  d.vendor_name = c.vendor_name;
  if (const sub_entry* name = find(t, 0x1008, 0)) d.device_name = name->default_text;
  d.group_name = c.group_name;
  d.profile_number = static_cast<std::uint16_t>(default_of(t, 0x1000, 0) & 0xFFFF);
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
  d.dc_sync0 = true;  // the controller has the DC unit; the slave runs its outputs on SYNC0
  return d;
}

}  // namespace cia402::ethercat
