// The one table of default PDOs (pdo_maps.hpp) against the one object table: every entry an object a
// PDO may carry that way, of its full length, and CANopen's maps within a frame's 8 bytes.
#include <gtest/gtest.h>

#include "cia402/objects.hpp"
#include "cia402/pdo_maps.hpp"

namespace cia402 {
namespace {

TEST(pdo_maps, every_default_map_keeps_the_object_tables_rules) {
  for (std::size_t n = 0; n < 4; ++n) {
    EXPECT_EQ(check_pdo_map(pdo_maps::can_rpdo[n], true), sdo_abort::none) << "RPDO" << n + 1;
    EXPECT_EQ(check_pdo_map(pdo_maps::can_tpdo[n], false), sdo_abort::none) << "TPDO" << n + 1;
    EXPECT_LE(pdo_maps::can_rpdo[n].bits(), 64u) << "RPDO" << n + 1;
    EXPECT_LE(pdo_maps::can_tpdo[n].bits(), 64u) << "TPDO" << n + 1;
  }
  EXPECT_EQ(check_pdo_map(pdo_maps::ecat_rxpdo, true), sdo_abort::none);
  EXPECT_EQ(check_pdo_map(pdo_maps::ecat_txpdo, false), sdo_abort::none);
  EXPECT_EQ(pdo_maps::ecat_rxpdo.bits(), 13u * 8);
  EXPECT_EQ(pdo_maps::ecat_txpdo.bits(), 19u * 8);
}

TEST(pdo_maps, the_control_and_status_words_come_first_in_every_map) {
  for (std::size_t n = 0; n < 4; ++n) {
    EXPECT_EQ(pdo_maps::can_rpdo[n].entries[0].word(), 0x60400010u) << n;
    EXPECT_EQ(pdo_maps::can_tpdo[n].entries[0].word(), 0x60410010u) << n;
    // PDO 3 is the cyclic synchronous position pair: at the next SYNC, on every SYNC.
    const std::uint8_t type = n == 2 ? pdo_maps::every_sync : pdo_maps::on_change;
    EXPECT_EQ(pdo_maps::can_rpdo[n].transmission_type, type) << n;
    EXPECT_EQ(pdo_maps::can_tpdo[n].transmission_type, type) << n;
  }
  EXPECT_EQ(pdo_maps::can_rpdo[2].entries[1].word(), 0x607A0020u);
  EXPECT_EQ(pdo_maps::can_tpdo[2].entries[1].word(), 0x60640020u);
  EXPECT_EQ(pdo_maps::ecat_rxpdo.entries[0].word(), 0x60400010u);
  EXPECT_EQ(pdo_maps::ecat_txpdo.entries[0].word(), 0x60410010u);
}

TEST(pdo_maps, a_map_that_breaks_the_object_table_is_named_with_the_dictionarys_code) {
  const auto one = [](pdo_mapping_entry e) { return detail::make_pdo_map({e}, pdo_maps::on_change); };
  EXPECT_EQ(check_pdo_map(one({0x6042, 0, 16}), true), sdo_abort::object_does_not_exist);
  EXPECT_EQ(check_pdo_map(one({0x6040, 1, 16}), true), sdo_abort::sub_index_does_not_exist);
  EXPECT_EQ(check_pdo_map(one({0x6041, 0, 16}), true), sdo_abort::cannot_map_to_pdo) << "read-only, received";
  EXPECT_EQ(check_pdo_map(one({0x6041, 0, 16}), false), sdo_abort::none);
  EXPECT_EQ(check_pdo_map(one({0x6040, 0, 8}), true), sdo_abort::cannot_map_to_pdo) << "not its full length";
  EXPECT_EQ(check_pdo_map(one({0x605A, 0, 16}), true), sdo_abort::cannot_map_to_pdo) << "not mappable";
}

}  // namespace
}  // namespace cia402
