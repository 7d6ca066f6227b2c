// The SII EEPROM image and the ESI file of a slave description (ETG.1000.6, ETG.2010, ETG.2000):
// the image's fixed words are where a master reads them, its checksum is the one ETG.1000.6 gives,
// its categories parse back to the description, and a damaged image is refused with a reason.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "cia402/ethercat/sii/slave_information.hpp"

namespace cia402::ethercat {
namespace {

slave_description sample() {
  slave_description d;
  d.vendor_id = 0x12345678;
  d.product_code = 0x402;
  d.revision = 0x00010000;
  d.serial = 7;
  d.vendor_name = "cia402 & friends";
  d.device_name = "cia402 virtual drive";
  d.group_name = "Drives";
  d.station_alias = 0x0042;
  d.coe_details = 0x2F;
  d.sync_managers = {{0x1000, 128, 0x26, 1, sm_type::mailbox_out},
                     {0x1080, 128, 0x22, 1, sm_type::mailbox_in},
                     {0x1100, 6, 0x64, 1, sm_type::outputs},
                     {0x1180, 6, 0x20, 1, sm_type::inputs}};
  d.fmmus = {fmmu_use::outputs, fmmu_use::inputs, fmmu_use::sm_status};
  d.rx_pdos = {{0x1600, 2, false, true, "RxPDO 1",
                {{0x6040, 0, 16, 0x0006, "Controlword"}, {0x607A, 0, 32, 0x0004, "Target position"}}}};
  d.tx_pdos = {{0x1A00, 3, false, true, "TxPDO 1",
                {{0x6041, 0, 16, 0x0006, "Statusword"}, {0x6064, 0, 32, 0x0004, "Position actual value"}}}};
  return d;
}

std::uint16_t word(const std::vector<std::uint8_t>& image, std::size_t w) {
  return static_cast<std::uint16_t>(image[2 * w] | (image[2 * w + 1] << 8));
}

TEST(sii, fixed_words_hold_identity_mailbox_and_size) {
  const std::vector<std::uint8_t> image = sii_image(sample());
  EXPECT_EQ(image.size(), 2048u);
  EXPECT_EQ(word(image, 0x04), 0x0042) << "configured station alias";
  EXPECT_EQ(word(image, 0x08) | (word(image, 0x09) << 16), 0x12345678);
  EXPECT_EQ(word(image, 0x0A), 0x0402);
  EXPECT_EQ(word(image, 0x0D), 0x0001) << "revision 0x00010000, high word";
  EXPECT_EQ(word(image, 0x0E), 7) << "serial";
  EXPECT_EQ(word(image, 0x18), 0x1000) << "standard receive mailbox offset";
  EXPECT_EQ(word(image, 0x19), 128);
  EXPECT_EQ(word(image, 0x1A), 0x1080) << "standard send mailbox offset";
  EXPECT_EQ(word(image, 0x1C), 0x0004) << "mailbox protocols: CoE";
  EXPECT_EQ(word(image, 0x3E), 15) << "EEPROM size: 16 Kbit - 1";
  EXPECT_EQ(word(image, 0x3F), 1) << "version";
}

TEST(sii, checksum_is_crc8_of_the_configuration_area) {
  // ETG.1000.6's example: the configuration area of an ET1100 with PDI 0x0C08 ... gives 0x..;
  // here the polynomial is checked on a known input: CRC-8 (x^8+x^2+x+1, init 0xFF) of 14 zero bytes.
  const std::uint8_t zeros[14] = {};
  std::uint8_t crc = 0xFF;
  for (std::uint8_t b : zeros) {
    crc ^= b;
    for (int i = 0; i < 8; ++i) crc = static_cast<std::uint8_t>(crc & 0x80 ? (crc << 1) ^ 0x07 : crc << 1);
  }
  EXPECT_EQ(sii_checksum(zeros), crc);
  const std::vector<std::uint8_t> image = sii_image(sample());
  EXPECT_EQ(image[14], sii_checksum(image.data()));
  // A different alias gives a different checksum: the CRC covers word 4.
  slave_description other = sample();
  other.station_alias = 0x0043;
  EXPECT_NE(sii_image(other)[14], image[14]);
}

TEST(sii, the_image_parses_back_to_its_description) {
  const slave_description d = sample();
  std::string error;
  const auto back = parse_sii(sii_image(d), error);
  ASSERT_TRUE(back.has_value()) << error;
  EXPECT_EQ(back->vendor_id, d.vendor_id);
  EXPECT_EQ(back->product_code, d.product_code);
  EXPECT_EQ(back->revision, d.revision);
  EXPECT_EQ(back->serial, d.serial);
  EXPECT_EQ(back->device_name, d.device_name);
  EXPECT_EQ(back->group_name, d.group_name);
  EXPECT_EQ(back->coe_details, d.coe_details);
  EXPECT_TRUE(back->coe);
  ASSERT_EQ(back->sync_managers.size(), 4u);
  EXPECT_EQ(back->sync_managers[2].start, 0x1100);
  EXPECT_EQ(back->sync_managers[2].control, 0x64);
  EXPECT_EQ(back->sync_managers[3].type, sm_type::inputs);
  ASSERT_EQ(back->fmmus.size(), 3u);
  EXPECT_EQ(back->fmmus[2], fmmu_use::sm_status);
  ASSERT_EQ(back->rx_pdos.size(), 1u);
  ASSERT_EQ(back->tx_pdos.size(), 1u);
  EXPECT_EQ(back->rx_pdos[0].index, 0x1600);
  EXPECT_EQ(back->rx_pdos[0].sync_manager, 2);
  EXPECT_EQ(back->rx_pdos[0].bit_size(), 48u);
  ASSERT_EQ(back->tx_pdos[0].entries.size(), 2u);
  EXPECT_EQ(back->tx_pdos[0].entries[1].index, 0x6064);
  EXPECT_EQ(back->tx_pdos[0].entries[1].name, "Position actual value");
  EXPECT_EQ(back->tx_pdos[0].entries[1].data_type, 0x0004);
}

TEST(sii, a_damaged_image_is_refused_with_a_reason) {
  const std::vector<std::uint8_t> good = sii_image(sample());
  std::string error;
  EXPECT_FALSE(parse_sii(std::vector<std::uint8_t>(good.begin(), good.begin() + 100), error));
  EXPECT_NE(error.find("shorter"), std::string::npos);

  std::vector<std::uint8_t> bad_crc = good;
  bad_crc[8] ^= 1;  // word 4, covered by the checksum
  EXPECT_FALSE(parse_sii(bad_crc, error));
  EXPECT_NE(error.find("checksum"), std::string::npos);

  std::vector<std::uint8_t> runs_past = good;
  runs_past[0x80 + 2] = 0xFF;  // the first category claims 0xFFxx words
  runs_past[0x80 + 3] = 0x7F;
  EXPECT_FALSE(parse_sii(runs_past, error));
  EXPECT_NE(error.find("past the end"), std::string::npos);

  // Every truncation before the end marker is refused, none crashes.
  std::size_t end = 0x80;
  while (word(good, end / 2) != 0xFFFF) end += 4 + 2 * std::size_t{word(good, end / 2 + 1)};
  EXPECT_GT(end, 0x80u + 100) << "the sample's categories";
  for (std::size_t n = 130; n < end + 2; ++n) {
    std::vector<std::uint8_t> cut(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_FALSE(parse_sii(cut, error)) << n;
  }
}

TEST(esi, names_identity_sync_managers_and_pdos_as_the_image_does) {
  const std::string x = esi_xml(sample());
  EXPECT_EQ(x.rfind("<?xml", 0), 0u);
  EXPECT_NE(x.find("<Id>#x12345678</Id>"), std::string::npos);
  EXPECT_NE(x.find("cia402 &amp; friends"), std::string::npos) << "escaped";
  EXPECT_NE(x.find("ProductCode=\"#x00000402\" RevisionNo=\"#x00010000\""), std::string::npos);
  EXPECT_NE(x.find("<Sm DefaultSize=\"128\" StartAddress=\"#x1000\" ControlByte=\"#x26\" Enable=\"1\">MBoxOut</Sm>"),
            std::string::npos);
  EXPECT_NE(x.find("<RxPdo Sm=\"2\""), std::string::npos);
  EXPECT_NE(x.find("<Index>#x607A</Index>"), std::string::npos);
  EXPECT_NE(x.find("<DataType>DINT</DataType>"), std::string::npos);
  EXPECT_NE(x.find("<CoE SdoInfo=\"true\" PdoAssign=\"true\" PdoConfig=\"true\" CompleteAccess=\"true\"/>"),
            std::string::npos);
  EXPECT_NE(x.find("<ProfileNo>402</ProfileNo>"), std::string::npos);
}

}  // namespace
}  // namespace cia402::ethercat

namespace cia402::ethercat {
namespace {

TEST(sii, the_first_string_is_the_device_name_as_masters_that_show_string_1_expect) {
  const std::vector<std::uint8_t> image = sii_image(sample());
  // Categories from word 0x40: type, size in words, data. The strings category (10) starts with
  // the count, then each string as a length byte and its characters.
  for (std::size_t at = 0x80; at + 4 <= image.size();) {
    const std::uint16_t type = static_cast<std::uint16_t>(image[at] | (image[at + 1] << 8));
    const std::uint16_t size = static_cast<std::uint16_t>(image[at + 2] | (image[at + 3] << 8));
    ASSERT_NE(type, 0xFFFF) << "no strings category";
    if (type == 10) {
      const std::size_t length = image[at + 5];
      EXPECT_EQ(std::string(image.begin() + static_cast<long>(at) + 6, image.begin() + static_cast<long>(at + 6 + length)),
                "cia402 virtual drive");
      return;
    }
    at += 4 + 2u * size;
  }
  FAIL() << "no end marker";
}

}  // namespace
}  // namespace cia402::ethercat
