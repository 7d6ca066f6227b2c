// 0x1021 store EDS and 0x1022 storage format: a master builds the node's
// dictionary from the node itself (python-canopen's import_from_node reads 0x1021). Over the
// in-process bus with our SDO client, by block transfer; the file read back by the EDS reader.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <variant>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/301/sdo_client.hpp"
#include "cia402/canopen/306/eds.hpp"
#include "cia402/canopen/306/eds_reader.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/profile.hpp"

namespace cia402::canopen {
namespace {

struct bench {
  explicit bench(const profile& p, slave_config c = apps::drive_node_config(3)) : node(p, bus.attach(), c) {
    node.poll(1000);
  }
  // One transfer of the client to its end.
  sdo_client& run() {
    for (int i = 0; i < 100000 && !client.finished(); ++i) {
      node.poll(0);
      frame f;
      while (client_side->receive(f)) client.on_frame(f);
    }
    return client;
  }
  virtual_bus bus;
  apps::virtual_drive_node node;
  std::unique_ptr<virtual_channel> client_side = bus.attach();
  sdo_client client{*client_side, 3};
};

TEST(stored_eds, the_node_gives_its_eds_in_0x1021_as_cia402_eds_writes_it_and_the_file_reads_back) {
  const profile* found = find_builtin_profile("lexium32");
  ASSERT_NE(found, nullptr);
  const profile& p = *found;
  bench b(p);
  // What a master changed does not change the file: it gives the values at power-up.
  ASSERT_TRUE(b.client.start_download(0x1017, 0, std::int64_t{250}, 2));
  ASSERT_EQ(b.run().state(), sdo_client::status::done);
  b.client.clear();
  ASSERT_TRUE(b.client.start_upload(0x1022, 0));
  ASSERT_EQ(b.run().state(), sdo_client::status::done);
  EXPECT_EQ(b.client.value(), 0) << "0x1022: ASCII";
  b.client.clear();
  ASSERT_TRUE(b.client.start_block_upload(0x1021, 0));
  ASSERT_EQ(b.run().state(), sdo_client::status::done) << std::hex << static_cast<std::uint32_t>(b.client.abort_code());
  const std::string file(b.client.data().begin(), b.client.data().end());
  // What `cia402 eds --profile lexium32 --node 3` writes, from a node of its own that nothing wrote
  // to (the file's date aside, which the command takes from the clock).
  {
    virtual_bus other;
    auto ch = other.attach();
    drive402::sim_device dev(p);
    slave fresh(dev, *ch, apps::drive_node_config(3));
    eds_info info;
    info.description += ", profile lexium32";
    info.node_id = 3;
    std::ostringstream expected;
    write_eds(fresh, info, expected);
    EXPECT_EQ(file, expected.str());
  }
  EXPECT_NE(file.find("profile lexium32"), std::string::npos);
  const auto read = read_eds(file);
  ASSERT_TRUE(std::holds_alternative<eds_contents>(read)) << std::get<eds_error>(read).reason;
  const std::vector<dictionary::object_entry>& objects = std::get<eds_contents>(read).objects;
  // The node's objects that its device has (a profile lacks some option codes: 0x06020000).
  std::vector<dictionary::object_entry> own;
  for (const dictionary::object_entry& o : b.node.node().dictionary().table()) {
    std::vector<std::uint8_t> ignored;
    if (b.node.node().read_bytes(o.index, o.subs.front().sub, ignored) != sdo_abort::object_does_not_exist) own.push_back(o);
  }
  ASSERT_LT(own.size(), b.node.node().dictionary().table().size()) << "lexium32 lacks an option code object";
  ASSERT_EQ(objects.size(), own.size()) << "every object of the node, no other";
  for (std::size_t i = 0; i < own.size(); ++i) {
    EXPECT_EQ(objects[i].index, own[i].index);
    EXPECT_EQ(objects[i].subs.size(), own[i].subs.size()) << own[i].index;
  }
  for (const dictionary::object_entry& o : objects) {
    if (o.index == 0x1017) EXPECT_EQ(o.subs[0].default_value, 0) << "the power-up value, not the 250 written";
  }
}

TEST(stored_eds, a_node_configured_without_it_has_no_0x1021) {
  slave_config c = apps::drive_node_config(3);
  c.store_eds = false;
  bench b(standard_profile(), c);
  ASSERT_TRUE(b.client.start_upload(0x1021, 0));
  ASSERT_EQ(b.run().state(), sdo_client::status::aborted);
  EXPECT_EQ(static_cast<std::uint32_t>(b.client.abort_code()), 0x06020000u);
}

}  // namespace
}  // namespace cia402::canopen
