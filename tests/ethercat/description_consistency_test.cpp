// What the virtual drive says about itself agrees with what it does (issue 34): the SII read through
// the EEPROM registers declares the physical ports the controller's port descriptor shows (ETG.2010
// General category) and no bootstrap mailbox, since BOOT is refused; SDO information gives every
// RECORD of its dictionary the data type of its structure (ETG.1000.6), never 0.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "cia402/ethercat/sii/slave_information.hpp"
#include "drive_bench.hpp"

namespace cia402::ethercat {
namespace {

using testing::bench;

// The whole SII image as a master reads it: 8 bytes at a time through 0x0502..0x050F.
std::vector<std::uint8_t> read_sii(bench& b, std::size_t bytes) {
  std::vector<std::uint8_t> image;
  for (std::uint32_t w = 0; w * 2 < bytes; w += 4) {
    b.send(command::apwr, static_cast<std::uint32_t>(reg::eeprom_address) << 16,
           {static_cast<std::uint8_t>(w), static_cast<std::uint8_t>(w >> 8), 0, 0});
    b.send(command::apwr, static_cast<std::uint32_t>(reg::eeprom_control) << 16, {0x00, 0x01});
    const auto a = b.send(command::aprd, static_cast<std::uint32_t>(reg::eeprom_data) << 16, std::vector<std::uint8_t>(8, 0));
    image.insert(image.end(), a.data.begin(), a.data.end());
  }
  return image;
}

// The data of an SII category, empty when the image has none.
std::vector<std::uint8_t> category(const std::vector<std::uint8_t>& image, std::uint16_t wanted) {
  for (std::size_t at = 0x80; at + 4 <= image.size();) {
    const auto type = static_cast<std::uint16_t>(image[at] | (image[at + 1] << 8));
    const std::size_t size = 2u * static_cast<std::uint16_t>(image[at + 2] | (image[at + 3] << 8));
    if (type == 0xFFFF || at + 4 + size > image.size()) break;
    if (type == wanted) return {image.begin() + static_cast<long>(at + 4), image.begin() + static_cast<long>(at + 4 + size)};
    at += 4 + size;
  }
  return {};
}

TEST(drive_description, the_sii_declares_the_physical_ports_the_controller_has) {
  bench b;
  const std::vector<std::uint8_t> image = read_sii(b, 2048);
  const std::vector<std::uint8_t> general = category(image, 30);
  ASSERT_GE(general.size(), 18u) << "General category";
  const unsigned ports = general[0x10] | (general[0x11] << 8);
  const std::uint8_t descriptor = b.send(command::aprd, static_cast<std::uint32_t>(reg::port_descriptor) << 16, {0}).data[0];
  for (int port = 0; port < 4; ++port) {
    const unsigned esc_kind = (descriptor >> (2 * port)) & 3u;  // 0 not implemented, 2 EBUS, 3 MII
    const unsigned sii_kind = (ports >> (4 * port)) & 0xFu;      // 0 not used, 1 MII, 3 EBUS
    const unsigned expected = esc_kind == 3 ? 1 : esc_kind == 2 ? 3 : 0;
    EXPECT_EQ(sii_kind, expected) << "port " << port;
  }
  EXPECT_NE(ports, 0u) << "a slave with no port is not on any line";
  EXPECT_NE(esi_xml(b.slave.description()).find("Physics=\"YY\""), std::string::npos) << "the ESI says the same";
}

TEST(drive_description, no_bootstrap_mailbox_is_declared_since_boot_is_refused) {
  bench b;
  const std::vector<std::uint8_t> image = read_sii(b, 0x80);
  for (std::size_t w = 0x14; w < 0x18; ++w) {
    EXPECT_EQ(image[2 * w] | (image[2 * w + 1] << 8), 0) << "bootstrap mailbox word " << w;
  }
  EXPECT_EQ(image[2 * 0x18] | (image[2 * 0x18 + 1] << 8), mailbox_out_start) << "the standard mailbox stays";
  b.to_pre_op();
  EXPECT_EQ(b.request(3), 0x12) << "BOOT refused";
  EXPECT_EQ(b.read16(reg::al_status_code), 0x0013);
}

// The object description (SDO information opcode 3) of an object, its data type.
std::uint16_t described_type(bench& b, std::uint16_t index) {
  std::vector<std::uint8_t> m(mailbox_size, 0);
  mailbox_header h;
  h.length = 8;
  h.type = mailbox_type::coe;
  h.counter = static_cast<std::uint8_t>(++b.counter % 7 + 1);
  write_mailbox_header(h, m.data());
  m[7] = 0x80;  // SDO information
  m[8] = 3;     // get object description request
  m[12] = static_cast<std::uint8_t>(index);
  m[13] = static_cast<std::uint8_t>(index >> 8);
  EXPECT_EQ(b.send(command::fpwr, b.fp(mailbox_out_start), m).wkc, 1);
  b.run(1);
  const bench::answer a = b.send(command::fprd, b.fp(mailbox_in_start), std::vector<std::uint8_t>(mailbox_size, 0));
  EXPECT_EQ(a.wkc, 1);
  EXPECT_EQ(a.data[8] & 0x7F, 4) << "object description response for " << std::hex << index;
  EXPECT_EQ(a.data[12] | (a.data[13] << 8), index);
  EXPECT_EQ(a.data[17], 9) << "RECORD";
  return static_cast<std::uint16_t>(a.data[14] | (a.data[15] << 8));
}

TEST(drive_description, sdo_information_gives_each_record_the_type_of_its_structure) {
  bench b;
  b.to_pre_op();
  b.drain_mailbox();
  EXPECT_EQ(described_type(b, 0x1018), 0x0023) << "identity";
  EXPECT_EQ(described_type(b, 0x1600), 0x0021) << "PDO mapping";
  EXPECT_EQ(described_type(b, 0x1A00), 0x0021) << "PDO mapping";
  EXPECT_EQ(described_type(b, 0x60C2), 0x002A) << "a record of the profile";
  // Every record of the dictionary: a type, never 0.
  for (const dictionary::object_entry& o : b.slave.slave().dictionary().table()) {
    if (o.code != dictionary::object_code::record) continue;
    EXPECT_NE(described_type(b, o.index), 0) << std::hex << o.index;
  }
}

}  // namespace
}  // namespace cia402::ethercat
