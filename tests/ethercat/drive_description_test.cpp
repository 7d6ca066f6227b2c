// The virtual drive's CoE dictionary and what its SII says: the CiA 402 objects of the one table,
// the CANopen identity, CoE's own communication objects and none of CAN's, and default PDOs a csp
// master can run.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/objects.hpp"

namespace cia402::ethercat {
namespace {

const dictionary::object_entry* find(const std::vector<dictionary::object_entry>& t, std::uint16_t index) {
  const auto it = std::find_if(t.begin(), t.end(), [&](const auto& o) { return o.index == index; });
  return it == t.end() ? nullptr : &*it;
}

TEST(coe_dictionary, holds_every_drive_object_and_no_can_only_object) {
  const auto t = coe_objects(apps::drive_slave_config());
  for (std::size_t i = 0; i < drive_object_count(); ++i) {
    EXPECT_NE(find(t, drive_object(i).index), nullptr) << std::hex << drive_object(i).index;
  }
  for (std::uint16_t can_only : {0x1005, 0x1014, 0x1016, 0x1200, 0x1400, 0x1800}) {
    EXPECT_EQ(find(t, can_only), nullptr) << std::hex << can_only;
  }
  // 0x1017 is CoE's too: stored, acting on nothing (a master sets it on every bus).
  for (std::uint16_t coe : {0x1000, 0x1017, 0x1018, 0x1600, 0x1A00, 0x1C00, 0x1C12, 0x1C13}) {
    EXPECT_NE(find(t, coe), nullptr) << std::hex << coe;
  }
  EXPECT_TRUE(std::is_sorted(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.index < b.index; }));
}

TEST(coe_dictionary, default_pdos_carry_a_csp_masters_objects) {
  const slave_description d = coe_slave_description(apps::drive_slave_config(3));
  ASSERT_EQ(d.rx_pdos.size(), 1u);
  ASSERT_EQ(d.tx_pdos.size(), 1u);
  const auto has = [](const pdo_description& p, std::uint16_t index) {
    return std::any_of(p.entries.begin(), p.entries.end(), [&](const pdo_entry& e) { return e.index == index; });
  };
  EXPECT_TRUE(has(d.rx_pdos[0], 0x6040));
  EXPECT_TRUE(has(d.rx_pdos[0], 0x607A));
  EXPECT_TRUE(has(d.rx_pdos[0], 0x6060));
  EXPECT_TRUE(has(d.tx_pdos[0], 0x6041));
  EXPECT_TRUE(has(d.tx_pdos[0], 0x6064));
  EXPECT_TRUE(has(d.tx_pdos[0], 0x6061));
  // Every entry names an object of the dictionary with its own size.
  for (const auto* pdos : {&d.rx_pdos, &d.tx_pdos}) {
    for (const pdo_entry& e : (*pdos)[0].entries) {
      const object_description* o = find_drive_object(e.index, e.sub);
      ASSERT_NE(o, nullptr) << std::hex << e.index;
      EXPECT_EQ(e.bits, type_size(o->type) * 8) << std::hex << e.index;
      EXPECT_EQ(e.name, o->name);
    }
  }
  ASSERT_EQ(d.sync_managers.size(), 4u);
  EXPECT_EQ(d.sync_managers[2].length, (d.rx_pdos[0].bit_size() + 7) / 8);
  EXPECT_EQ(d.sync_managers[3].length, (d.tx_pdos[0].bit_size() + 7) / 8);
  EXPECT_EQ(d.product_code, 0x402u) << "the CANopen identity 0x1018";
  EXPECT_EQ(d.serial, 3u);
  std::string error;
  const auto back = parse_sii(sii_image(d), error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(back->tx_pdos[0].bit_size(), d.tx_pdos[0].bit_size());
}

}  // namespace
}  // namespace cia402::ethercat
