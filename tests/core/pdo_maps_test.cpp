// The one table of default PDOs (pdo_maps.hpp) against the one object table: every entry an object a
// PDO may carry that way, of its full length, and CANopen's maps within a frame's 8 bytes.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

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

TEST(pdo_padding, dummies_on_both_buses_and_index_0_gaps_on_ethercat_of_their_one_length) {
  using enum_p = pdo_padding;
  // CiA 301 dummies: BOOLEAN 1 bit, INTEGER8..UNSIGNED32 their size; sub-index 0 only.
  const std::uint32_t dummies[][2] = {{0x00010001, 1},  {0x00020008, 8},  {0x00030010, 16}, {0x00040020, 32},
                                      {0x00050008, 8},  {0x00060010, 16}, {0x00070020, 32}};
  for (const auto& d : dummies) {
    const pdo_mapping_entry e = pdo_mapping_entry::of_word(d[0]);
    EXPECT_EQ(e.word(), d[0]);
    EXPECT_EQ(pdo_padding_bits(e, enum_p::dummies), d[1]) << std::hex << d[0];
    EXPECT_EQ(pdo_padding_bits(e, enum_p::dummies_and_gaps), d[1]) << std::hex << d[0];
  }
  for (const std::uint32_t wrong : {0x00010008u, 0x00050010u, 0x00070008u, 0x00050108u, 0x00030000u}) {
    EXPECT_TRUE(is_pdo_padding(static_cast<std::uint16_t>(wrong >> 16), enum_p::dummies));
    EXPECT_EQ(pdo_padding_bits(pdo_mapping_entry::of_word(wrong), enum_p::dummies_and_gaps), 0u) << std::hex << wrong;
  }
  // Index 0: a gap of any length 1..64 on EtherCAT; nothing on CANopen.
  EXPECT_EQ(pdo_padding_bits(pdo_mapping_entry::of_word(0x00000008), enum_p::dummies_and_gaps), 8u);
  EXPECT_EQ(pdo_padding_bits(pdo_mapping_entry::of_word(0x00000003), enum_p::dummies_and_gaps), 3u);
  EXPECT_EQ(pdo_padding_bits(pdo_mapping_entry::of_word(0x00000040), enum_p::dummies_and_gaps), 64u);
  EXPECT_EQ(pdo_padding_bits(pdo_mapping_entry::of_word(0x00000041), enum_p::dummies_and_gaps), 0u);
  EXPECT_EQ(pdo_padding_bits(pdo_mapping_entry::of_word(0x00000000), enum_p::dummies_and_gaps), 0u);
  EXPECT_EQ(pdo_padding_bits(pdo_mapping_entry::of_word(0x00000108), enum_p::dummies_and_gaps), 0u);
  EXPECT_FALSE(is_pdo_padding(0, enum_p::dummies));
  EXPECT_EQ(pdo_padding_bits(pdo_mapping_entry::of_word(0x00000008), enum_p::dummies), 0u);
  EXPECT_FALSE(is_pdo_padding(0x0008, enum_p::dummies_and_gaps));
  EXPECT_FALSE(is_pdo_padding(0x6040, enum_p::dummies_and_gaps));
}

TEST(pdo_padding, a_default_map_may_hold_padding_between_objects) {
  const pdo_map m = detail::make_pdo_map({{0x6040, 0, 16}, {0x0005, 0, 8}, {0x0000, 0, 8}, {0x607A, 0, 32}},
                                         pdo_maps::on_change);
  EXPECT_EQ(check_pdo_map(m, true), sdo_abort::object_does_not_exist) << "a gap is EtherCAT's";
  EXPECT_EQ(check_pdo_map(m, true, pdo_padding::dummies_and_gaps), sdo_abort::none);
  EXPECT_EQ(m.bits(), 64u);
  const pdo_map wrong = detail::make_pdo_map({{0x6041, 0, 16}, {0x0006, 0, 8}}, pdo_maps::on_change);
  EXPECT_EQ(check_pdo_map(wrong, false), sdo_abort::cannot_map_to_pdo) << "UNSIGNED16 is 16 bits";
}

TEST(pdo_bits, entries_at_any_bit_offset_read_and_written_little_endian) {
  std::array<std::uint8_t, 4> b{0xFF, 0xFF, 0xFF, 0xFF};
  // 16 bits from bit 1, beside a BOOLEAN dummy: the bits around it are kept.
  pdo_put_bits(b.data(), b.size(), 1, 16, 0x1234);
  EXPECT_EQ(b[0], static_cast<std::uint8_t>((0x34 << 1) | 1));
  EXPECT_EQ(b[1], static_cast<std::uint8_t>((0x1234 >> 7) & 0xFF));
  EXPECT_EQ(b[2], static_cast<std::uint8_t>(0xFE | ((0x1234 >> 15) & 1)));
  EXPECT_EQ(pdo_get_bits(b.data(), b.size(), 1, 16), 0x1234u);
  EXPECT_EQ(pdo_get_bits(b.data(), b.size(), 0, 1), 1u);
  std::array<std::uint8_t, 8> w{};
  pdo_put_bits(w.data(), w.size(), 0, 64, 0x8877665544332211ull);
  EXPECT_EQ(pdo_get_bits(w.data(), w.size(), 0, 64), 0x8877665544332211ull);
  EXPECT_EQ(w[0], 0x11);
  EXPECT_EQ(w[7], 0x88);
  // Past the buffer: read as 0, dropped when written.
  EXPECT_EQ(pdo_get_bits(w.data(), 2, 8, 16), 0x22u);
  pdo_put_bits(w.data(), 2, 8, 16, 0xFFFF);
  EXPECT_EQ(w[1], 0xFF);
  EXPECT_EQ(w[2], 0x33);
  EXPECT_EQ(pdo_sign_extended(0x8000, 16), -32768);
  EXPECT_EQ(pdo_sign_extended(0x7FFF, 16), 32767);
  EXPECT_EQ(pdo_sign_extended(0x8000000000000000ull, 64), INT64_MIN);
}

}  // namespace
}  // namespace cia402
