// Reading an EDS (306/eds_reader.hpp): the drive's own EDS reads back as the table it was written
// from; CiA 306's notations (compact subs, $NODEID, octal, DCF values) read as the standard says;
// a file that does not parse is refused with its line and gives nothing.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <variant>

#include "cia402/canopen/306/eds.hpp"
#include "cia402/canopen/306/eds_reader.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"

namespace cia402::canopen {
namespace {

std::string drive_eds(std::uint8_t node_id = 0) {
  virtual_bus bus;
  auto ch = bus.attach();
  drive402::sim_device dev(standard_profile());
  slave node(dev, *ch, apps::drive_node_config(1));
  eds_info info;
  info.node_id = node_id;
  std::ostringstream out;
  write_eds(node, info, out);
  return out.str();
}

const object_entry* find(const std::vector<object_entry>& t, std::uint16_t index) {
  for (const object_entry& o : t) {
    if (o.index == index) return &o;
  }
  return nullptr;
}

eds_contents read_ok(const std::string& text) {
  auto r = read_eds(text);
  if (const auto* e = std::get_if<eds_error>(&r)) {
    ADD_FAILURE() << "line " << e->line << ": " << e->reason;
    return {};
  }
  return std::get<eds_contents>(std::move(r));
}

TEST(eds_reader, the_drives_eds_reads_back_as_the_table_it_was_written_from) {
  const eds_contents eds = read_ok(drive_eds());
  EXPECT_EQ(eds.node_id, 0);
  std::size_t compared = 0;
  for (const object_entry& o : node_objects(apps::drive_node_config(1))) {
    const object_entry* r = find(eds.objects, o.index);
    if (r == nullptr) continue;  // an object the device lacks is not in the EDS
    ++compared;
    EXPECT_EQ(r->name, o.name) << std::hex << o.index;
    EXPECT_EQ(r->code, o.code) << std::hex << o.index;
    ASSERT_EQ(r->subs.size(), o.subs.size()) << std::hex << o.index;
    for (std::size_t i = 0; i < o.subs.size(); ++i) {
      const sub_entry& want = o.subs[i];
      const sub_entry& got = r->subs[i];
      SCOPED_TRACE(testing::Message() << std::hex << o.index << "sub" << int{want.sub});
      EXPECT_EQ(got.sub, want.sub);
      EXPECT_EQ(got.name, o.code == object_code::var ? o.name : want.name);
      EXPECT_EQ(got.type, want.type);
      EXPECT_EQ(got.acc, want.acc);
      EXPECT_EQ(got.pdo_mappable, want.pdo_mappable);
      EXPECT_EQ(got.plus_node_id, want.plus_node_id);
      if (want.where == backing::stored && want.type != data_type::visible_string) {
        EXPECT_EQ(got.default_value, want.default_value);
      }
    }
  }
  EXPECT_GT(compared, 40u);
  // The PDO set at power-up, as a monitor needs it: TPDO1 = 0x180 + node-ID, mapping 0x6041.
  const object_entry* tpdo1 = find(eds.objects, 0x1800);
  ASSERT_NE(tpdo1, nullptr);
  EXPECT_TRUE(tpdo1->subs[1].plus_node_id);
  EXPECT_EQ(tpdo1->subs[1].default_value, 0x180);
  const object_entry* map1 = find(eds.objects, 0x1A00);
  ASSERT_NE(map1, nullptr);
  EXPECT_EQ(map1->subs[0].default_value, 1);
  EXPECT_EQ(map1->subs[1].default_value, 0x60410010);
}

TEST(eds_reader, a_commissioned_file_names_its_node) {
  EXPECT_EQ(read_ok(drive_eds(5)).node_id, 5);
}

TEST(eds_reader, cia_306_notations_read_as_the_standard_says) {
  const eds_contents eds = read_ok(
      "; a comment\n"
      "[FileInfo]\nFileName=x.eds\n\n"
      "[1800sub1]\nParameterName=COB-ID\nDataType=0x0007\nAccessType=rw\nDefaultValue=0x180+$NodeID\n"
      "[1800]\nParameterName=TPDO1 communication parameter\nObjectType=0x9\nSubNumber=2\n"
      "[1800sub0]\nParameterName=Highest\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n"
      "[2100]\nParameterName=Gains\nObjectType=0x8\nDataType=0x0003\nAccessType=rww\nCompactSubObj=3\n"
      "PDOMapping=1\nDefaultValue=-5\n"
      "[2200]\nParameterName=Octal\nDataType=0x0006\nAccessType=ro\nDefaultValue=017\n"
      "[2300]\nParameterName=Configured\nDataType=0x0006\nAccessType=rw\nDefaultValue=1\nParameterValue=0x10\n"
      "[2400]\nParameterName=A float\nDataType=0x0008\nAccessType=rw\n"
      "[2500]\nParameterName=A domain\nObjectType=0x2\n"
      "[2600]\nParameterName=Label\nDataType=0x0009\nAccessType=rw\nDefaultValue=hello world\n");
  ASSERT_EQ(eds.objects.size(), 5u);  // 0x2400 (REAL32) and 0x2500 (DOMAIN) are left out
  const object_entry* tpdo = find(eds.objects, 0x1800);
  ASSERT_NE(tpdo, nullptr);
  ASSERT_EQ(tpdo->subs.size(), 2u);
  EXPECT_EQ(tpdo->subs[0].sub, 0);
  EXPECT_TRUE(tpdo->subs[1].plus_node_id);
  EXPECT_EQ(tpdo->subs[1].default_value, 0x180);
  const object_entry* gains = find(eds.objects, 0x2100);
  ASSERT_NE(gains, nullptr);
  ASSERT_EQ(gains->subs.size(), 4u);
  EXPECT_EQ(gains->subs[0].default_value, 3);
  EXPECT_EQ(gains->subs[3].type, data_type::integer16);
  EXPECT_EQ(gains->subs[3].acc, access::rw);
  EXPECT_TRUE(gains->subs[3].pdo_mappable);
  EXPECT_EQ(gains->subs[3].default_value, -5);
  EXPECT_EQ(find(eds.objects, 0x2200)->subs[0].default_value, 15);
  EXPECT_EQ(find(eds.objects, 0x2300)->subs[0].default_value, 0x10);
  EXPECT_EQ(find(eds.objects, 0x2600)->subs[0].default_text, "hello world");
}

TEST(eds_reader, a_file_that_does_not_parse_is_refused_with_its_line) {
  const struct {
    const char* text;
    std::size_t line;
    const char* reason;
  } bad[] = {
      {"[1000]\nDataType=0x0007\nnonsense\n", 3, "expected [SECTION] or KEY=VALUE"},
      {"DataType=0x0007\n", 1, "before the first section"},
      {"[1000\n", 1, "[ and ]"},
      {"[1000]\nDataType=0x0007\n[1000]\n", 3, "appears twice"},
      {"[1000]\nDataType=0x0007\nDataType=0x0006\n", 3, "appears twice"},
      {"[1000]\nParameterName=x\n", 1, "no DataType"},
      {"[1000]\nDataType=seven\n", 2, "DataType 'seven' is not a number"},
      {"[1000]\nDataType=0x0005\nDefaultValue=256\n", 3, "outside its data type"},
      {"[1000]\nDataType=0x0002\nDefaultValue=0x\n", 3, "not a number"},
      {"[1000]\nDataType=0x0007\nDefaultValue=99999999999999999999999\n", 3, "not a number"},
      {"[1000]\nDataType=0x0007\nDefaultValue=$NODEID*2\n", 3, "$NODEID+X"},
      {"[1000]\nDataType=0x0007\nAccessType=rx\n", 3, "AccessType 'rx'"},
      {"[2000]\nObjectType=0x8\nDataType=0x0005\nCompactSubObj=300\n", 1, "CompactSubObj above 254"},
      {"[DeviceComissioning]\nNodeID=128\n", 2, "NodeID '128' is not 1..127"},
      {"[1A00sub1]\nDataType=0x0007\n", 1, "[1A00sub1] has no object section [1A00]"},
  };
  for (const auto& b : bad) {
    const auto r = read_eds(b.text);
    ASSERT_TRUE(std::holds_alternative<eds_error>(r)) << b.text;
    const eds_error& e = std::get<eds_error>(r);
    EXPECT_EQ(e.line, b.line) << b.text;
    EXPECT_NE(e.reason.find(b.reason), std::string::npos) << b.text << " -> " << e.reason;
  }
}

// A DCF (write_dcf): each entry given a value carries it as ParameterValue beside its DefaultValue,
// and reads back with it; an entry without one reads back as its default.
TEST(eds_reader, a_dcf_written_from_entries_reads_back_with_its_parameter_values) {
  std::vector<object_entry> objects = node_objects(apps::drive_node_config(1));
  dcf_values values;
  const object_entry* accel = find(objects, 0x6083);
  const object_entry* speeds = find(objects, 0x6099);
  ASSERT_NE(accel, nullptr);
  ASSERT_NE(speeds, nullptr);
  ASSERT_GE(speeds->subs.size(), 3u);
  values[{0x6083, 0}] = dcf_value_text(accel->subs.front(), 4321);
  values[{0x6099, 1}] = dcf_value_text(speeds->subs[1], 777);
  eds_info info;
  info.node_id = 5;
  std::ostringstream out;
  write_dcf(objects, values, info, out);
  EXPECT_NE(out.str().find("ParameterValue=0x000010E1"), std::string::npos) << out.str();
  const eds_contents dcf = read_ok(out.str());
  EXPECT_EQ(dcf.node_id, 5);
  const object_entry* a = find(dcf.objects, 0x6083);
  const object_entry* s = find(dcf.objects, 0x6099);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(a->subs.front().default_value, 4321);
  EXPECT_EQ(s->subs[1].default_value, 777);
  EXPECT_TRUE(a->subs.front().parameter_value);
  EXPECT_EQ(s->subs[2].default_value, speeds->subs[2].default_value);  // no ParameterValue: the default
  EXPECT_FALSE(s->subs[2].parameter_value);
  EXPECT_EQ(dcf.objects.size(), objects.size());
}

}  // namespace
}  // namespace cia402::canopen
