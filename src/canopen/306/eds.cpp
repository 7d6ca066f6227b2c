#include "cia402/canopen/306/eds.hpp"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <ostream>
#include <vector>

#include "cia402/support/text.hpp"

namespace cia402::canopen {
namespace {

using support::hex;

// CiA 306 lists objects by what CiA 301 says of them, not by the device profile: 0x1000, 0x1001
// and 0x1018 are mandatory, 0x2000..0x5FFF are the manufacturer's, the rest optional (a CiA 402
// drive's 0x6040 and 0x6041 included).
int eds_list_of(std::uint16_t index) {
  if (index == 0x1000 || index == 0x1001 || index == 0x1018) return 0;
  if (index >= 0x2000 && index <= 0x5FFF) return 2;
  return 1;
}

std::string section_name(std::uint16_t index) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04X", index);
  return buf;
}

std::string number_text(data_type type, std::int64_t v);

// "$NODEID+X" with X as number_text writes it, so a signed type's negative X reads back (its hex
// two's complement, 0xFFFFFFFFFFFFFFFB, is no INTEGER the reader takes).
std::string node_text(const dictionary::sub_entry& e) {
  return "$NODEID+" + (type_is_signed(e.type) ? std::to_string(e.default_value)
                                               : hex(static_cast<std::uint64_t>(e.default_value), 0));
}

// The value at power-up as the EDS writes it; false if the device lacks the object.
bool default_text(slave& node, const dictionary::object_entry& o, const dictionary::sub_entry& e, std::string& out) {
  if (e.type == data_type::visible_string) {
    std::vector<std::uint8_t> bytes;
    if (dictionary::readable(e.acc)) (void)node.read_bytes(o.index, e.sub, bytes);
    out.assign(bytes.begin(), bytes.end());
    return true;
  }
  if (e.plus_node_id) {
    out = node_text(e);
    return true;
  }
  std::int64_t v = e.default_value;
  if (e.where == dictionary::backing::device) {
    const sdo_abort a = node.read(o.index, e.sub, v);
    if (a == sdo_abort::object_does_not_exist) return false;
    if (a != sdo_abort::none) v = 0;
  }
  out = number_text(e.type, v);
  return true;
}

// One entry's section; `parameter` (a DCF's) is the value the node has now (CiA 306 §4.6.4).
void write_sub(std::ostream& out, const std::string& section, const dictionary::object_entry& o, const dictionary::sub_entry& e,
               const std::string& value, const std::string* parameter = nullptr) {
  out << "[" << section << "]\n"
      << "ParameterName=" << (o.subs.size() == 1 && o.code == dictionary::object_code::var ? o.name : e.name) << "\n"
      << "ObjectType=0x7\n"
      << "DataType=" << hex(static_cast<std::uint16_t>(e.type), 4) << "\n"
      << "AccessType=" << dictionary::access_name(e.acc) << "\n"
      << "DefaultValue=" << value << "\n";
  if (parameter != nullptr) out << "ParameterValue=" << *parameter << "\n";
  if (e.has_limits) {
    const bool sign = type_is_signed(e.type);
    out << "LowLimit=" << (sign ? std::to_string(e.low) : hex(static_cast<std::uint64_t>(e.low), 0)) << "\n"
        << "HighLimit=" << (sign ? std::to_string(e.high) : hex(static_cast<std::uint64_t>(e.high), 0))
        << "\n";
  }
  out << "PDOMapping=" << (e.pdo_mappable ? 1 : 0) << "\n\n";
}

void write_file_info(std::ostream& out, const eds_info& info) {
  out << "[FileInfo]\n"
      << "FileName=" << info.file_name << "\n"
      << "FileVersion=1\nFileRevision=0\nEDSVersion=4.0\n"
      << "Description=" << info.description << "\n"
      << "CreationTime=" << info.time << "\nCreationDate=" << info.date << "\n"
      << "CreatedBy=" << info.created_by << "\n"
      << "ModificationTime=" << info.time << "\nModificationDate=" << info.date << "\n"
      << "ModifiedBy=" << info.created_by << "\n\n";
}

void write_commissioning(std::ostream& out, const eds_info& info) {
  if (info.node_id == 0) return;
  // CiA 306's commissioning section (as a DCF has it): the node this file was written for.
  out << "[DeviceComissioning]\nNodeID=" << int{info.node_id} << "\nNodeName=" << info.product_name
      << " " << int{info.node_id} << "\nBaudrate=1000\n\n";
}

// The three object lists (CiA 306 §4.6.2) and each object's sections; `value_of` gives an entry's
// DefaultValue text, `parameter_of` its ParameterValue (nullptr: none).
void write_objects(std::ostream& out, const std::vector<const dictionary::object_entry*>& present,
                   const std::function<std::string(const dictionary::object_entry&, const dictionary::sub_entry&)>& value_of,
                   const std::function<const std::string*(const dictionary::object_entry&, const dictionary::sub_entry&)>& parameter_of) {
  const char* list_names[3] = {"MandatoryObjects", "OptionalObjects", "ManufacturerObjects"};
  for (int c = 0; c < 3; ++c) {
    std::vector<const dictionary::object_entry*> in;
    for (const dictionary::object_entry* o : present) {
      if (eds_list_of(o->index) == c) in.push_back(o);
    }
    out << "[" << list_names[c] << "]\nSupportedObjects=" << in.size() << "\n";
    for (std::size_t i = 0; i < in.size(); ++i) out << i + 1 << "=" << hex(in[i]->index, 4) << "\n";
    out << "\n";
    for (const dictionary::object_entry* o : in) {
      const std::string name = section_name(o->index);
      if (o->code == dictionary::object_code::var) {
        const dictionary::sub_entry& e = o->subs.front();
        write_sub(out, name, *o, e, value_of(*o, e), parameter_of(*o, e));
        continue;
      }
      out << "[" << name << "]\n"
          << "ParameterName=" << o->name << "\n"
          << "ObjectType=" << hex(static_cast<unsigned>(o->code), 0) << "\n"
          << "SubNumber=" << hex(o->subs.size(), 0) << "\n\n";
      for (const dictionary::sub_entry& e : o->subs) {
        write_sub(out, name + "sub" + hex(e.sub, 0).substr(2), *o, e, value_of(*o, e), parameter_of(*o, e));
      }
    }
  }
}

// An entry's value as CiA 306 writes it: decimal when signed, hexadecimal when not.
std::string number_text(data_type type, std::int64_t v) {
  if (type_is_signed(type)) return std::to_string(v);
  return hex(static_cast<std::uint64_t>(v), static_cast<int>(type_size(type) * 2));
}

}  // namespace

void write_eds(slave& node, const eds_info& info, std::ostream& out) {
  // Which objects the node really has (a profile may lack an option-code object).
  std::vector<const dictionary::object_entry*> present;
  for (const dictionary::object_entry& o : node.dictionary().table()) {
    std::string ignored;
    if (default_text(node, o, o.subs.front(), ignored)) present.push_back(&o);
  }

  // The PDOs the node has: its communication parameter objects (RPDO 0x1400.., TPDO 0x1800..).
  int rpdos = 0, tpdos = 0;
  for (const dictionary::object_entry& o : node.dictionary().table()) {
    if (o.index >= 0x1400 && o.index <= 0x15FF) ++rpdos;
    if (o.index >= 0x1800 && o.index <= 0x19FF) ++tpdos;
  }

  std::int64_t vendor = 0, product = 0, revision = 0;
  (void)node.read(0x1018, 1, vendor);
  (void)node.read(0x1018, 2, product);
  (void)node.read(0x1018, 3, revision);

  write_file_info(out, info);
  out << "[DeviceInfo]\n"
      << "VendorName=" << info.vendor_name << "\n"
      << "VendorNumber=" << hex(static_cast<std::uint64_t>(vendor), 8) << "\n"
      << "ProductName=" << info.product_name << "\n"
      << "ProductNumber=" << hex(static_cast<std::uint64_t>(product), 8) << "\n"
      << "RevisionNumber=" << hex(static_cast<std::uint64_t>(revision), 8) << "\n"
      << "OrderCode=\n";
  for (int rate : {10, 20, 50, 125, 250, 500, 800, 1000}) out << "BaudRate_" << rate << "=1\n";
  // Granularity 1: entries follow each other at any bit offset (after a BOOLEAN dummy's one bit);
  // an object is still mapped whole.
  out << "SimpleBootUpMaster=0\nSimpleBootUpSlave=1\nGranularity=1\nDynamicChannelsSupported=0\n"
      << "GroupMessaging=0\nNrOfRXPDO=" << rpdos << "\nNrOfTXPDO=" << tpdos
      << "\nLSS_Supported=0\n\n";
  out << "[DummyUsage]\n";
  // The node maps every CiA 301 dummy entry (pdo_maps.hpp, pdo_padding).
  for (int i = 1; i <= 7; ++i) out << "Dummy000" << i << "=1\n";
  out << "\n[Comments]\nLines=1\nLine1=Generated from the node's object dictionary (cia402 eds).\n\n";
  write_commissioning(out, info);
  write_objects(
      out, present,
      [&node](const dictionary::object_entry& o, const dictionary::sub_entry& e) {
        std::string value;
        default_text(node, o, e, value);
        return value;
      },
      [](const dictionary::object_entry&, const dictionary::sub_entry&) -> const std::string* { return nullptr; });
}

std::string dcf_value_text(const dictionary::sub_entry& e, std::int64_t value) { return number_text(e.type, value); }

std::string dcf_entry_text(const dictionary::sub_entry& e) {
  if (e.type == data_type::visible_string) return e.default_text;
  if (e.plus_node_id) return node_text(e);
  return number_text(e.type, e.default_value);
}

void write_dcf(const std::vector<dictionary::object_entry>& objects, const dcf_values& values, const eds_info& info,
               std::ostream& out) {
  write_file_info(out, info);
  out << "[DeviceInfo]\nVendorName=" << info.vendor_name << "\nProductName=" << info.product_name << "\n\n";
  write_commissioning(out, info);
  std::vector<const dictionary::object_entry*> present;
  for (const dictionary::object_entry& o : objects) {
    if (!o.subs.empty()) present.push_back(&o);
  }
  std::sort(present.begin(), present.end(),
            [](const dictionary::object_entry* a, const dictionary::object_entry* b) { return a->index < b->index; });
  write_objects(
      out, present,
      [](const dictionary::object_entry&, const dictionary::sub_entry& e) { return dcf_entry_text(e); },
      [&values](const dictionary::object_entry& o, const dictionary::sub_entry& e) -> const std::string* {
        const auto it = values.find({o.index, e.sub});
        return it == values.end() ? nullptr : &it->second;
      });
}

}  // namespace cia402::canopen
