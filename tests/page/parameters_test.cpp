// The page's parameter list and parameter files over HTTP (docs/instrument-page.md, "Parameter list
// and parameter files"): the drive in this process behind the page, with the DCF files `cia402 serve`
// gives it (canopen/306). Expected names, units, limits and defaults are the CiA 402 object table's
// (objects.hpp), abort codes CiA 301's.
#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <regex>
#include <string>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/301/slave.hpp"
#include "cia402/objects.hpp"
#include "cia402/page/server.hpp"
#include "cli/parameter_file.hpp"
#include "virtual_axis_page.hpp"

namespace cia402::page::testing {
namespace {

using json = nlohmann::json;

axis_page_config with_files() {
  axis_page_config c;
  c.parameter_file = cli::dcf_parameter_file();
  return c;
}

class parameters : public ::testing::Test {
 protected:
  void SetUp() override {
    server_options o;
    o.port = 0;
    http = std::make_unique<server>(inst, o);
    ASSERT_TRUE(http->bind()) << http->error();
    http->start();
    client = std::make_unique<httplib::Client>("127.0.0.1", http->bound_port());
    client->set_read_timeout(5, 0);
    for (int i = 0; i < 10; ++i) inst.step();
  }
  void TearDown() override { http->stop(); }

  json list() {
    auto r = client->Get("/api/parameters");
    EXPECT_TRUE(r);
    EXPECT_EQ(r->status, 200) << r->body;
    return json::parse(r->body);
  }
  json entry(const std::string& key) {
    const json l = list();
    for (const json& e : l["entries"]) {
      if (e["key"] == key) return e;
    }
    ADD_FAILURE() << key << " is not listed";
    return {};
  }
  static std::string hex_key(std::uint16_t index) {
    char b[16];
    std::snprintf(b, sizeof b, "0x%04X:0", index);
    return b;
  }
  httplib::Result write(const std::string& key, const json& value) {
    return client->Post("/api/object", json{{"index", key}, {"value", value}}.dump(), "application/json");
  }
  httplib::Result load(const std::string& file) {
    return client->Post("/api/parameters.dcf", json{{"file", file}}.dump(), "application/json");
  }
  std::string saved() {
    auto r = client->Get("/api/parameters.dcf");
    EXPECT_TRUE(r);
    EXPECT_EQ(r->status, 200) << r->body;
    return r->body;
  }

  virtual_axis_page inst{cia402::standard_profile(), with_files()};
  std::unique_ptr<server> http;
  std::unique_ptr<httplib::Client> client;
};

// A DCF's entry section with its ParameterValue set to `value`.
std::string with_value(const std::string& file, const std::string& section, const std::string& value) {
  const std::regex at("(\\[" + section + "\\]\\n(?:[^\\[]*\\n)*?)ParameterValue=[^\\n]*");
  return std::regex_replace(file, at, "$1ParameterValue=" + value, std::regex_constants::format_first_only);
}

TEST_F(parameters, every_entry_of_the_object_table_the_drive_has_is_listed_with_its_description) {
  const json l = list();
  std::size_t listed = 0;
  for (std::size_t i = 0; i < drive_object_count(); ++i) {
    const object_description& o = drive_object(i);
    char key[16];
    std::snprintf(key, sizeof key, "0x%04X:%u", o.index, static_cast<unsigned>(o.sub));
    for (const json& e : l["entries"]) {
      if (e["key"] != key) continue;
      ++listed;
      EXPECT_EQ(e["name"], o.name) << key;
      EXPECT_EQ(e["unit"], o.unit) << key;
      EXPECT_EQ(e["low"], o.low) << key;
      EXPECT_EQ(e["high"], o.high) << key;
      EXPECT_EQ(e["default"], o.default_value) << key;
      EXPECT_EQ(e["writable"], o.access != object_access::read_only) << key;
      EXPECT_FALSE(e.contains("error")) << key << ": " << e;
    }
  }
  EXPECT_EQ(listed, l["entries"].size());
  EXPECT_GT(listed, 40u);
  const json speed = entry("0x6099:1");
  EXPECT_EQ(speed["type"], "unsigned32");
  EXPECT_EQ(speed["unit"], "rpm");
  EXPECT_EQ(speed["value"], speed["default"]);
  EXPECT_EQ(speed["differs"], false);
}

// Where a write is a choice, the list gives the values the drive takes, not its type's range: each
// option code's as the profile allows them, the modes 0x6502 announces, the homing methods.
TEST_F(parameters, a_choice_lists_the_values_the_drive_takes) {
  const profile& p = cia402::standard_profile();
  for (int k = 0; k < option_count; ++k) {
    const auto o = static_cast<option>(k);
    if (!p.spec(o).exists()) continue;
    std::vector<std::int64_t> allowed;
    for (int v = -32768; v <= 32767; ++v) {
      if (p.spec(o).allows(v)) allowed.push_back(v);
    }
    const json e = entry(hex_key(option_index(o)));
    ASSERT_TRUE(e.contains("values")) << e.dump();
    EXPECT_EQ(e["values"].get<std::vector<std::int64_t>>(), allowed) << e.dump();
  }
  const json modes = entry("0x6060:0");
  ASSERT_TRUE(modes.contains("values"));
  const auto supported = static_cast<std::uint32_t>(find_drive_object(object_index::supported_drive_modes)->default_value);
  for (const std::int64_t m : modes["values"].get<std::vector<std::int64_t>>()) {
    EXPECT_NE(supported & (1u << (m - 1)), 0u) << "mode " << m << " is announced in 0x6502";
  }
  EXPECT_FALSE(entry("0x6099:1").contains("values")) << "a speed is a range";
}

TEST_F(parameters, a_write_by_index_and_sub_index_changes_the_value_and_marks_it_as_differing) {
  auto r = write("0x6099:1", 500);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200) << r->body;
  const json speed = entry("0x6099:1");
  EXPECT_EQ(speed["value"], 500);
  EXPECT_EQ(speed["differs"], true);
  r = write("0x6099:2", "0x30");  // a number's text
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(entry("0x6099:2")["value"], 0x30);
}

TEST_F(parameters, a_write_the_drive_refuses_answers_422_with_the_abort_code_and_its_text) {
  for (const auto& [key, value, abort] : {std::tuple{"0x605A:0", 100, "0x06090030"},
                                          std::tuple{"0x6041:0", 5, "0x06010002"},
                                          std::tuple{"0x607D:0", 3, "0x06010002"}}) {
    const json before = entry(key)["value"];
    auto r = write(key, value);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 422) << key << ": " << r->body;
    const json b = json::parse(r->body);
    EXPECT_EQ(b["abort"], abort) << key;
    EXPECT_EQ(b["abort_text"], sdo_abort_text(static_cast<sdo_abort>(std::stoul(abort, nullptr, 16)))) << key;
    EXPECT_EQ(entry(key)["value"], before) << key;
  }
  auto r = write("0x6099:1", "fast");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400) << r->body;
  r = write("0x6099:256", 5);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400) << r->body;
}

TEST_F(parameters, a_saved_set_loaded_back_restores_its_values_and_lists_the_refused_with_their_abort_text) {
  const std::string file = saved();
  EXPECT_NE(file.find("[6099sub1]"), std::string::npos);
  EXPECT_NE(file.find("ParameterValue="), std::string::npos);
  const json original = entry("0x6099:1")["value"];
  ASSERT_EQ(write("0x6099:1", 900)->status, 200);
  ASSERT_EQ(write("0x6083:0", 1234)->status, 200);
  ASSERT_EQ(entry("0x6099:1")["value"], 900);

  auto r = load(with_value(file, "605A", "100"));  // an option code the profile does not have
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json result = json::parse(r->body);
  EXPECT_EQ(entry("0x6099:1")["value"], original);
  EXPECT_EQ(entry("0x6083:0")["value"], entry("0x6083:0")["default"]);
  ASSERT_EQ(result["refused"].size(), 1u) << result["refused"];
  EXPECT_EQ(result["refused"][0]["key"], "0x605A:0");
  EXPECT_EQ(result["refused"][0]["abort"], "0x06090030");
  EXPECT_EQ(result["refused"][0]["abort_text"], "invalid value for parameter");
  bool status_word_skipped = false;
  for (const json& s : result["skipped"]) status_word_skipped |= s["key"] == "0x6041:0" && s["reason"] == "read-only";
  EXPECT_TRUE(status_word_skipped) << result["skipped"];
  bool speed_written = false;
  for (const json& w : result["written"]) speed_written |= w["key"] == "0x6099:1";
  EXPECT_TRUE(speed_written);
}

TEST_F(parameters, a_file_that_does_not_parse_changes_nothing_and_names_its_line) {
  ASSERT_EQ(write("0x6099:1", 900)->status, 200);
  const std::string file = with_value(saved(), "6099sub1", "0x10");
  for (const std::string& bad : {file + "[6083]\nDataType=0x0007\nParameterValue=fast\n",
                                 file + "this is no key\n",
                                 with_value(file, "6083", "0x1FFFFFFFF")}) {
    auto r = load(bad);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << r->body;
    const json b = json::parse(r->body);
    EXPECT_GT(b["line"].get<int>(), 0) << r->body;
    EXPECT_EQ(entry("0x6099:1")["value"], 900);
  }
  auto r = load(file);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(entry("0x6099:1")["value"], 0x10);
}

TEST_F(parameters, a_file_bigger_than_a_command_body_is_taken) {
  const std::string file = saved();
  ASSERT_GT(file.size(), server_options{}.max_body);
  auto r = load(file);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200) << r->body;
}

// The entries `serve --can` gives the page beyond the table: a node's dictionary, each sub-index
// with its type, access and its node-dependent default resolved ($NODEID+0x180 for node 5).
TEST(parameter_entries, a_nodes_dictionary_gives_its_communication_objects_with_resolved_defaults) {
  const auto entries = cli::parameter_entries(canopen::node_objects(apps::drive_node_config(5)), 5);
  const auto find = [&](std::uint16_t index, std::uint8_t sub) -> const parameter_entry* {
    for (const parameter_entry& e : entries) {
      if (e.index == index && e.sub == sub) return &e;
    }
    return nullptr;
  };
  const parameter_entry* device_type = find(0x1000, 0);
  ASSERT_NE(device_type, nullptr);
  EXPECT_EQ(device_type->data_type, 0x0007);
  EXPECT_EQ(device_type->access, "ro");
  const parameter_entry* name = find(0x1008, 0);
  ASSERT_NE(name, nullptr);
  EXPECT_EQ(name->data_type, 0x0009);
  const parameter_entry* tpdo1 = find(0x1800, 1);
  ASSERT_NE(tpdo1, nullptr);
  EXPECT_EQ(tpdo1->default_number.value_or(0) & 0x7FF, 0x180 + 5);
  EXPECT_NE(find(0x1022, 0), nullptr);
  EXPECT_EQ(find(0x1021, 0), nullptr) << "the stored EDS is a file of its own, not a parameter to read into the list";
}

// A drive's text is a peer's: a line break in it stays inside its value in the file and cannot add
// an entry of its own.
TEST(dcf_parameter_file, a_text_with_line_breaks_cannot_add_an_entry_to_the_file) {
  parameter_entry name;
  name.index = 0x1008;
  name.name = "Manufacturer device name";
  name.data_type = 0x0009;
  name.access = "const";
  parameter_entry accel;
  accel.index = 0x6083;
  accel.name = "Profile acceleration";
  accel.data_type = 0x0007;
  const auto format = cli::dcf_parameter_file();
  const std::string file =
      format.write({name, accel}, {std::string("drive\n[6083]\nParameterValue=1"), std::nullopt}, 1);
  auto read = format.read(file);
  ASSERT_TRUE(std::holds_alternative<std::vector<parameter_value>>(read)) << file;
  const auto& values = std::get<std::vector<parameter_value>>(read);
  ASSERT_EQ(values.size(), 1u) << file;
  EXPECT_EQ(values[0].index, 0x1008);
  EXPECT_EQ(values[0].value, "drive [6083] ParameterValue=1");
}

}  // namespace
}  // namespace cia402::page::testing
