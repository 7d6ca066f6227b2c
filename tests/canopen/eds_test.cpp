// The EDS (CiA 306) printed from the node's dictionary: sections, keys, the three object lists and
// their counts, and that it follows the profile (an option code the profile lacks is left out).
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>
#include <string>

#include <algorithm>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/306/eds.hpp"
#include "cia402/objects.hpp"
#include "cia402/drive402/drive_objects.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"

namespace cia402::canopen {
namespace {

using ini = std::map<std::string, std::map<std::string, std::string>>;

ini parse_ini(const std::string& text) {
  ini out;
  std::istringstream in(text);
  std::string line;
  std::string section;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == ';') continue;
    if (line.front() == '[') {
      section = line.substr(1, line.find(']') - 1);
      EXPECT_EQ(out.count(section), 0u) << "section [" << section << "] twice";
      out[section];
      continue;
    }
    const auto eq = line.find('=');
    EXPECT_NE(eq, std::string::npos) << line;
    out[section][line.substr(0, eq)] = line.substr(eq + 1);
  }
  return out;
}

std::string eds_of(const profile& p) {
  virtual_bus bus;
  auto ch = bus.attach();
  drive402::sim_device dev(p);
  slave node(dev, *ch, apps::drive_node_config(1));
  std::ostringstream out;
  write_eds(node, eds_info{}, out);
  return out.str();
}

unsigned number(const std::string& s) { return static_cast<unsigned>(std::stoul(s, nullptr, 0)); }

TEST(eds, object_lists_count_and_name_every_object_section) {
  const ini eds = parse_ini(eds_of(standard_profile()));
  std::set<std::string> listed;
  std::map<std::string, std::size_t> counts;
  for (const char* list : {"MandatoryObjects", "OptionalObjects", "ManufacturerObjects"}) {
    ASSERT_TRUE(eds.count(list)) << list;
    const auto& l = eds.at(list);
    const unsigned n = number(l.at("SupportedObjects"));
    EXPECT_EQ(l.size(), n + 1) << list;
    counts[list] = n;
    for (unsigned i = 1; i <= n; ++i) {
      char name[8];
      std::snprintf(name, sizeof name, "%04X", number(l.at(std::to_string(i))));
      EXPECT_TRUE(eds.count(name)) << name;
      EXPECT_TRUE(listed.insert(name).second) << name << " listed twice";
    }
  }
  EXPECT_EQ(counts["MandatoryObjects"], 3u);    // 1000, 1001, 1018 (CiA 306)
  EXPECT_EQ(counts["ManufacturerObjects"], 2u); // 2000, 2001
  for (const auto& [section, keys] : eds) {
    if (section.size() == 4 && section.find_first_not_of("0123456789ABCDEF") == std::string::npos) {
      EXPECT_TRUE(listed.count(section)) << section << " is in no list";
      for (const char* key : {"ParameterName", "ObjectType"}) EXPECT_TRUE(keys.count(key)) << section;
      const unsigned type = number(keys.at("ObjectType"));
      if (type == 7) {
        for (const char* key : {"DataType", "AccessType", "DefaultValue", "PDOMapping"}) {
          EXPECT_TRUE(keys.count(key)) << section << " " << key;
        }
      } else {
        std::size_t subs = 0;
        for (const auto& [other, k] : eds) subs += other.rfind(section + "sub", 0) == 0;
        EXPECT_EQ(subs, number(keys.at("SubNumber"))) << section;
      }
    }
  }
}

TEST(eds, entries_carry_type_access_default_and_mapping_of_the_dictionary) {
  const ini eds = parse_ini(eds_of(standard_profile()));
  // Section, key, value, and why where it is not plain.
  const struct {
    const char* section;
    const char* key;
    const char* value;
    const char* why;
  } entries[] = {
      {"1000", "DefaultValue", "0x00020192", ""},
      {"1000", "DataType", "0x0007", ""},
      {"6040", "AccessType", "rw", ""},
      {"6040", "DataType", "0x0006", ""},
      {"6040", "PDOMapping", "1", ""},
      {"6041", "AccessType", "ro", ""},
      {"605A", "DefaultValue", "2", "the profile's default (S5)"},
      {"605A", "DataType", "0x0003", ""},
      {"6083", "LowLimit", "0x1", ""},
      {"1008", "DefaultValue", "cia402 virtual drive", ""},
      {"1008", "AccessType", "const", ""},
      {"2001", "AccessType", "wo", ""},
      {"1018", "SubNumber", "0x5", ""},
      {"1018sub4", "DefaultValue", "$NODEID+0x0", ""},
      {"1A01sub2", "DefaultValue", "0x60610008", ""},
      {"1802sub1", "DefaultValue", "$NODEID+0x380", "TPDO3 carries the position"},
      {"1802sub2", "DefaultValue", "0x01", "on every SYNC"},
      {"1A02sub2", "DefaultValue", "0x60640020", ""},
      {"1800", "SubNumber", "0x5", "sub 4 is reserved"},
      {"FileInfo", "EDSVersion", "4.0", ""},
      // Spelled as CiA 306 spells them: parsers read the keys case-sensitively.
      {"DeviceInfo", "NrOfRXPDO", "4", ""},
      {"DeviceInfo", "NrOfTXPDO", "4", ""},
  };
  for (const auto& e : entries) {
    EXPECT_EQ(eds.at(e.section).at(e.key), e.value) << "[" << e.section << "] " << e.key << " " << e.why;
  }
  EXPECT_EQ(eds.at("DeviceInfo").count("NrOfRxPDO"), 0u) << "NrOfRXPDO, as CiA 306 spells it";
}

// CiA 306 keeps [MandatoryObjects] for CiA 301's 0x1000, 0x1001 and 0x1018; the drive's 0x6040 and
// 0x6041 are optional objects there, 0x2000..0x5FFF the manufacturer's.
TEST(eds, mandatory_objects_are_the_three_of_cia_301) {
  const ini eds = parse_ini(eds_of(standard_profile()));
  const auto& mandatory = eds.at("MandatoryObjects");
  EXPECT_EQ(mandatory.at("SupportedObjects"), "3");
  EXPECT_EQ(mandatory.at("1"), "0x1000");
  EXPECT_EQ(mandatory.at("2"), "0x1001");
  EXPECT_EQ(mandatory.at("3"), "0x1018");
  std::set<std::string> optional, manufacturer;
  for (const auto& [key, value] : eds.at("OptionalObjects")) optional.insert(value);
  for (const auto& [key, value] : eds.at("ManufacturerObjects")) manufacturer.insert(value);
  EXPECT_TRUE(optional.count("0x6040"));
  EXPECT_TRUE(optional.count("0x6041"));
  EXPECT_TRUE(manufacturer.count("0x2001"));
  EXPECT_FALSE(optional.count("0x1000"));
}

TEST(eds, option_code_the_profile_lacks_is_left_out) {
  const profile* p = find_builtin_profile("no-quick-stop");
  ASSERT_NE(p, nullptr);
  const ini eds = parse_ini(eds_of(*p));
  EXPECT_EQ(eds.count("605A"), 0u);
  EXPECT_EQ(eds.count("6040"), 1u);
}

}  // namespace
}  // namespace cia402::canopen

namespace {

// The CANopen dictionary takes the drive profile's objects from the one table: same type, access,
// PDO mapping and limits, and their values are the device's.
TEST(eds, the_dictionary_holds_every_object_of_the_one_table_as_it_describes_it) {
  const std::vector<cia402::dictionary::object_entry> od = cia402::drive402::drive_objects();
  for (std::size_t i = 0; i < cia402::drive_object_count(); ++i) {
    const cia402::object_description& d = cia402::drive_object(i);
    SCOPED_TRACE(d.name);
    const auto it = std::find_if(od.begin(), od.end(), [&](const auto& e) { return e.index == d.index; });
    ASSERT_NE(it, od.end());
    const auto sub = std::find_if(it->subs.begin(), it->subs.end(), [&](const auto& e) { return e.sub == d.sub; });
    ASSERT_NE(sub, it->subs.end());
    const cia402::dictionary::sub_entry& e = *sub;
    const bool has_subs = cia402::find_drive_object(d.index, 1) != nullptr;
    // An array or record: its count (sub-index 0) and the entries it counts.
    const std::size_t entries = has_subs ? static_cast<std::size_t>(cia402::find_drive_object(d.index, 0)->default_value) : 0;
    EXPECT_EQ(it->subs.size(), entries + 1);
    if (has_subs && d.sub == 0) {
      // An array's count is the dictionary's own constant.
      EXPECT_EQ(e.default_value, d.default_value);
      EXPECT_EQ(e.acc, cia402::dictionary::access::ro);
      continue;
    }
    EXPECT_EQ(static_cast<unsigned>(e.type), static_cast<unsigned>(d.type));
    EXPECT_EQ(e.name, d.name);
    EXPECT_EQ(e.pdo_mappable, d.pdo_mappable);
    EXPECT_EQ(e.acc == cia402::dictionary::access::ro, d.access == cia402::object_access::read_only);
    EXPECT_EQ(e.where, cia402::dictionary::backing::device);
    if (e.has_limits) {
      EXPECT_EQ(e.low, d.low);
      EXPECT_EQ(e.high, d.high);
    } else {
      EXPECT_EQ(d.low, cia402::type_min(d.type));
      EXPECT_EQ(d.high, cia402::type_max(d.type));
    }
  }
}

}  // namespace
