#include "cia402/ethercat/sii/slave_information.hpp"

#include "cia402/support/text.hpp"

#include <cstdio>

namespace cia402::ethercat {
namespace {

// SII word addresses (ETG.1000.6 table 2) and category types (table 19).
constexpr std::size_t word_alias = 0x04;
constexpr std::size_t word_checksum = 0x07;
constexpr std::size_t word_vendor = 0x08;
constexpr std::size_t word_product = 0x0A;
constexpr std::size_t word_revision = 0x0C;
constexpr std::size_t word_serial = 0x0E;
constexpr std::size_t word_bootstrap_mailbox = 0x14;
constexpr std::size_t word_standard_mailbox = 0x18;
constexpr std::size_t word_mailbox_protocol = 0x1C;
constexpr std::size_t word_size = 0x3E;
constexpr std::size_t word_version = 0x3F;
constexpr std::size_t first_category = 0x40;

constexpr std::uint16_t category_strings = 10;
constexpr std::uint16_t category_general = 30;
constexpr std::uint16_t category_fmmu = 40;
constexpr std::uint16_t category_syncm = 41;
constexpr std::uint16_t category_txpdo = 50;
constexpr std::uint16_t category_rxpdo = 51;
constexpr std::uint16_t category_end = 0xFFFF;

constexpr std::uint16_t mailbox_coe = 0x0004;
// General category (ETG.2010): byte offset of the physical ports word.
constexpr std::size_t general_physical_port = 0x10;
constexpr std::uint16_t pdo_flag_mandatory = 0x0001;
constexpr std::uint16_t pdo_flag_default = 0x0002;
constexpr std::uint16_t pdo_flag_fixed = 0x0010;

// The EEPROM a generated image claims: 2 KiB (16 Kbit), the smallest that holds a drive's PDOs.
constexpr std::size_t image_bytes = 2048;

void put16(std::vector<std::uint8_t>& b, std::size_t at, std::uint16_t v) {
  if (b.size() < at + 2) b.resize(at + 2, 0);
  b[at] = static_cast<std::uint8_t>(v);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
void put32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  put16(b, at, static_cast<std::uint16_t>(v));
  put16(b, at + 2, static_cast<std::uint16_t>(v >> 16));
}
std::uint16_t get16(const std::vector<std::uint8_t>& b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}
std::uint32_t get32(const std::vector<std::uint8_t>& b, std::size_t at) {
  return get16(b, at) | (static_cast<std::uint32_t>(get16(b, at + 2)) << 16);
}

// The string table of the Strings category: index 0 means "no string", so the first is 1.
class string_table {
 public:
  std::uint8_t add(const std::string& s) {
    if (s.empty()) return 0;
    for (std::size_t i = 0; i < strings_.size(); ++i) {
      if (strings_[i] == s) return static_cast<std::uint8_t>(i + 1);
    }
    if (strings_.size() >= 255) return 0;
    strings_.push_back(s.size() > 255 ? s.substr(0, 255) : s);
    return static_cast<std::uint8_t>(strings_.size());
  }
  std::vector<std::uint8_t> bytes() const {
    std::vector<std::uint8_t> b{static_cast<std::uint8_t>(strings_.size())};
    for (const std::string& s : strings_) {
      b.push_back(static_cast<std::uint8_t>(s.size()));
      b.insert(b.end(), s.begin(), s.end());
    }
    return b;
  }

 private:
  std::vector<std::string> strings_;
};

void add_category(std::vector<std::uint8_t>& image, std::uint16_t type, std::vector<std::uint8_t> data) {
  if (data.size() % 2) data.push_back(0);
  const std::size_t at = image.size();
  put16(image, at, type);
  put16(image, at + 2, static_cast<std::uint16_t>(data.size() / 2));
  image.insert(image.end(), data.begin(), data.end());
}

std::vector<std::uint8_t> pdo_category(const std::vector<pdo_description>& pdos, string_table& strings) {
  std::vector<std::uint8_t> b;
  for (const pdo_description& p : pdos) {
    const std::size_t at = b.size();
    put16(b, at, p.index);
    b.push_back(static_cast<std::uint8_t>(p.entries.size()));
    b.push_back(p.sync_manager);
    b.push_back(0);  // synchronization: none
    b.push_back(strings.add(p.name));
    put16(b, at + 6, static_cast<std::uint16_t>((p.mandatory ? pdo_flag_mandatory : 0) | pdo_flag_default |
                                                (p.fixed ? pdo_flag_fixed : 0)));
    for (const pdo_entry& e : p.entries) {
      const std::size_t e_at = b.size();
      put16(b, e_at, e.index);
      b.push_back(e.sub);
      b.push_back(strings.add(e.name));
      b.push_back(static_cast<std::uint8_t>(e.data_type));
      b.push_back(e.bits);
      put16(b, e_at + 6, 0);
    }
  }
  return b;
}

// ESI numbers are written "#x0001" (ETG.2000).
std::string hex(std::uint32_t v, int digits) { return support::hex(v, digits, "#x"); }

// ESI data type names (ETG.2000) of the CiA 301 data type indices.
const char* esi_type(std::uint16_t t) {
  switch (t) {
    case 0x0001: return "BOOL";
    case 0x0002: return "SINT";
    case 0x0003: return "INT";
    case 0x0004: return "DINT";
    case 0x0005: return "USINT";
    case 0x0006: return "UINT";
    case 0x0007: return "UDINT";
    case 0x0015: return "LINT";
    case 0x001B: return "ULINT";
    default: return "";
  }
}

// The ESI's Physics letters of the SII's physical ports (ETG.2000): Y MII, K EBUS, H fast hot connect.
std::string physics(std::uint16_t ports) {
  std::string letters;
  for (int port = 0; port < 4; ++port) {
    const unsigned kind = (ports >> (4 * port)) & 0xFu;
    if (kind == 0) break;
    letters += kind == 1 ? 'Y' : kind == 3 ? 'K' : kind == 4 ? 'H' : ' ';
  }
  return letters;
}

const char* sm_name(sm_type t) {
  switch (t) {
    case sm_type::mailbox_out: return "MBoxOut";
    case sm_type::mailbox_in: return "MBoxIn";
    case sm_type::outputs: return "Outputs";
    case sm_type::inputs: return "Inputs";
    case sm_type::unused: break;
  }
  return "";
}

const char* fmmu_name(fmmu_use u) {
  switch (u) {
    case fmmu_use::outputs: return "Outputs";
    case fmmu_use::inputs: return "Inputs";
    case fmmu_use::sm_status: return "MBoxState";
    case fmmu_use::unused: break;
  }
  return "";
}

void pdos_xml(std::string& x, const std::vector<pdo_description>& pdos, const char* tag) {
  for (const pdo_description& p : pdos) {
    x += "        <" + std::string(tag) + " Sm=\"" + std::to_string(p.sync_manager) + "\" Fixed=\"" +
         (p.fixed ? "1" : "0") + "\" Mandatory=\"" + (p.mandatory ? "1" : "0") + "\">\n";
    x += "          <Index>" + hex(p.index, 4) + "</Index>\n";
    x += "          <Name>" + support::xml_escaped(p.name) + "</Name>\n";
    for (const pdo_entry& e : p.entries) {
      x += "          <Entry>\n";
      x += "            <Index>" + hex(e.index, 4) + "</Index>\n";
      if (e.index != 0) x += "            <SubIndex>" + std::to_string(e.sub) + "</SubIndex>\n";
      x += "            <BitLen>" + std::to_string(e.bits) + "</BitLen>\n";
      if (e.index != 0) {
        x += "            <Name>" + support::xml_escaped(e.name) + "</Name>\n";
        x += "            <DataType>" + std::string(esi_type(e.data_type)) + "</DataType>\n";
      }
      x += "          </Entry>\n";
    }
    x += "        </" + std::string(tag) + ">\n";
  }
}

}  // namespace

unsigned pdo_description::bit_size() const noexcept {
  unsigned bits = 0;
  for (const pdo_entry& e : entries) bits += e.bits;
  return bits;
}

std::uint8_t sii_checksum(const std::uint8_t* first14) noexcept {
  std::uint8_t crc = 0xFF;
  for (int i = 0; i < 14; ++i) {
    crc ^= first14[i];
    for (int bit = 0; bit < 8; ++bit) {
      crc = static_cast<std::uint8_t>((crc & 0x80) ? (crc << 1) ^ 0x07 : crc << 1);
    }
  }
  return crc;
}

std::vector<std::uint8_t> sii_image(const slave_description& d) {
  std::vector<std::uint8_t> image(first_category * 2, 0);
  put16(image, word_alias * 2, d.station_alias);
  image[word_checksum * 2] = sii_checksum(image.data());
  put32(image, word_vendor * 2, d.vendor_id);
  put32(image, word_product * 2, d.product_code);
  put32(image, word_revision * 2, d.revision);
  put32(image, word_serial * 2, d.serial);
  // Only the standard mailbox: the bootstrap mailbox words (0x14..0x17) stay 0, since no slave
  // described here has a BOOT state (its AL state machine refuses it with 0x0013).
  put16(image, word_standard_mailbox * 2, d.mailbox_out_start);
  put16(image, word_standard_mailbox * 2 + 2, d.mailbox_out_size);
  put16(image, word_standard_mailbox * 2 + 4, d.mailbox_in_start);
  put16(image, word_standard_mailbox * 2 + 6, d.mailbox_in_size);
  put16(image, word_mailbox_protocol * 2, d.coe ? mailbox_coe : 0);
  put16(image, word_size * 2, static_cast<std::uint16_t>(image_bytes * 8 / 1024 - 1));
  put16(image, word_version * 2, 1);

  string_table strings;
  std::vector<std::uint8_t> general(32, 0);
  // The device name is string 1: masters that show a slave's name without reading the general
  // category (SOEM's slaveinfo, for one) take the first string.
  general[2] = strings.add(d.device_name);  // order number
  general[3] = strings.add(d.device_name);
  general[0] = strings.add(d.group_name);
  general[5] = d.coe ? d.coe_details : 0;
  general[9] = d.profile_number == 402 ? 1 : 0;  // CiA 402 channels
  general[14] = general[0];
  put16(general, general_physical_port, d.physical_ports);
  std::vector<std::uint8_t> fmmu;
  for (fmmu_use u : d.fmmus) fmmu.push_back(static_cast<std::uint8_t>(u));
  std::vector<std::uint8_t> syncm;
  for (const sync_manager_description& sm : d.sync_managers) {
    const std::size_t at = syncm.size();
    put16(syncm, at, sm.start);
    put16(syncm, at + 2, sm.length);
    syncm.push_back(sm.control);
    syncm.push_back(0);
    syncm.push_back(sm.enable);
    syncm.push_back(static_cast<std::uint8_t>(sm.type));
  }
  const std::vector<std::uint8_t> tx = pdo_category(d.tx_pdos, strings);
  const std::vector<std::uint8_t> rx = pdo_category(d.rx_pdos, strings);
  strings.add(d.vendor_name);

  add_category(image, category_strings, strings.bytes());
  add_category(image, category_general, general);
  add_category(image, category_fmmu, fmmu);
  add_category(image, category_syncm, syncm);
  if (!tx.empty()) add_category(image, category_txpdo, tx);
  if (!rx.empty()) add_category(image, category_rxpdo, rx);
  put16(image, image.size(), category_end);
  // The rest of the EEPROM reads as erased.
  if (image.size() < image_bytes) image.resize(image_bytes, 0xFF);
  return image;
}

std::optional<slave_description> parse_sii(const std::vector<std::uint8_t>& image, std::string& error) {
  if (image.size() < first_category * 2 + 2) {
    error = "SII image shorter than its fixed header (130 bytes)";
    return std::nullopt;
  }
  if (sii_checksum(image.data()) != image[word_checksum * 2]) {
    error = "SII checksum (word 7) does not match the configuration area";
    return std::nullopt;
  }
  slave_description d;
  d.station_alias = get16(image, word_alias * 2);
  d.vendor_id = get32(image, word_vendor * 2);
  d.product_code = get32(image, word_product * 2);
  d.revision = get32(image, word_revision * 2);
  d.serial = get32(image, word_serial * 2);
  d.mailbox_out_start = get16(image, word_standard_mailbox * 2);
  d.mailbox_out_size = get16(image, word_standard_mailbox * 2 + 2);
  d.mailbox_in_start = get16(image, word_standard_mailbox * 2 + 4);
  d.mailbox_in_size = get16(image, word_standard_mailbox * 2 + 6);
  d.coe = (get16(image, word_mailbox_protocol * 2) & mailbox_coe) != 0;

  std::vector<std::string> strings;
  const auto string_at = [&](std::uint8_t i) { return i >= 1 && i <= strings.size() ? strings[i - 1] : std::string(); };
  std::size_t at = first_category * 2;
  bool ended = false;
  // Bounded: every category moves `at` forward by at least 4 bytes.
  while (at + 4 <= image.size()) {
    const std::uint16_t type = get16(image, at);
    if (type == category_end) {
      ended = true;
      break;
    }
    const std::size_t size = std::size_t{get16(image, at + 2)} * 2;
    const std::size_t data = at + 4;
    if (data + size > image.size()) {
      error = "SII category " + std::to_string(type) + " runs past the end of the image";
      return std::nullopt;
    }
    const auto byte = [&](std::size_t i) -> std::uint8_t { return i < size ? image[data + i] : 0; };
    switch (type) {
      case category_strings: {
        const std::size_t n = byte(0);
        std::size_t p = 1;
        for (std::size_t i = 0; i < n && p < size; ++i) {
          const std::size_t len = byte(p);
          if (p + 1 + len > size) {
            error = "SII string " + std::to_string(i + 1) + " runs past its category";
            return std::nullopt;
          }
          strings.emplace_back(image.begin() + static_cast<std::ptrdiff_t>(data + p + 1),
                               image.begin() + static_cast<std::ptrdiff_t>(data + p + 1 + len));
          p += 1 + len;
        }
        break;
      }
      case category_general:
        d.group_name = string_at(byte(0));
        d.device_name = string_at(byte(3));
        d.coe_details = byte(5);
        d.physical_ports = static_cast<std::uint16_t>(byte(general_physical_port) | (byte(general_physical_port + 1) << 8));
        break;
      case category_fmmu:
        for (std::size_t i = 0; i < size; ++i) {
          if (byte(i) >= 1 && byte(i) <= 3) d.fmmus.push_back(static_cast<fmmu_use>(byte(i)));
        }
        break;
      case category_syncm:
        for (std::size_t i = 0; i + 8 <= size; i += 8) {
          sync_manager_description sm;
          sm.start = static_cast<std::uint16_t>(byte(i) | (byte(i + 1) << 8));
          sm.length = static_cast<std::uint16_t>(byte(i + 2) | (byte(i + 3) << 8));
          sm.control = byte(i + 4);
          sm.enable = byte(i + 6);
          sm.type = byte(i + 7) <= 4 ? static_cast<sm_type>(byte(i + 7)) : sm_type::unused;
          d.sync_managers.push_back(sm);
        }
        break;
      case category_txpdo:
      case category_rxpdo: {
        std::vector<pdo_description>& into = type == category_txpdo ? d.tx_pdos : d.rx_pdos;
        std::size_t p = 0;
        while (p + 8 <= size) {
          pdo_description pdo;
          pdo.index = static_cast<std::uint16_t>(byte(p) | (byte(p + 1) << 8));
          const std::size_t n = byte(p + 2);
          pdo.sync_manager = byte(p + 3);
          pdo.name = string_at(byte(p + 5));
          const unsigned flags = byte(p + 6) | (byte(p + 7) << 8);
          pdo.mandatory = (flags & pdo_flag_mandatory) != 0;
          pdo.fixed = (flags & pdo_flag_fixed) != 0;
          p += 8;
          if (p + 8 * n > size) {
            error = "SII PDO " + hex(pdo.index, 4) + " has more entries than its category holds";
            return std::nullopt;
          }
          for (std::size_t e = 0; e < n; ++e, p += 8) {
            pdo_entry entry;
            entry.index = static_cast<std::uint16_t>(byte(p) | (byte(p + 1) << 8));
            entry.sub = byte(p + 2);
            entry.name = string_at(byte(p + 3));
            entry.data_type = byte(p + 4);
            entry.bits = byte(p + 5);
            pdo.entries.push_back(entry);
          }
          into.push_back(pdo);
        }
        break;
      }
      default: break;  // categories a master may skip
    }
    at = data + size;
  }
  if (!ended) {
    error = "SII image has no end category (0xFFFF)";
    return std::nullopt;
  }
  // The vendor's name is the last string the generator adds; a foreign image may not name it.
  return d;
}

std::string esi_xml(const slave_description& d) {
  std::string x;
  x += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<EtherCATInfo xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" Version=\"1.6\">\n";
  x += "  <Vendor>\n    <Id>" + hex(d.vendor_id, 8) + "</Id>\n    <Name>" + support::xml_escaped(d.vendor_name) +
       "</Name>\n  </Vendor>\n";
  x += "  <Descriptions>\n    <Groups>\n      <Group>\n        <Type>" + support::xml_escaped(d.group_name) +
       "</Type>\n        <Name>" + support::xml_escaped(d.group_name) + "</Name>\n      </Group>\n    </Groups>\n";
  x += "    <Devices>\n      <Device Physics=\"" + physics(d.physical_ports) + "\">\n";
  x += "        <Type ProductCode=\"" + hex(d.product_code, 8) + "\" RevisionNo=\"" + hex(d.revision, 8) +
       "\">" + support::xml_escaped(d.device_name) + "</Type>\n";
  x += "        <Name>" + support::xml_escaped(d.device_name) + "</Name>\n";
  x += "        <GroupType>" + support::xml_escaped(d.group_name) + "</GroupType>\n";
  x += "        <Profile>\n          <ProfileNo>" + std::to_string(d.profile_number) +
       "</ProfileNo>\n          <AddInfo>0</AddInfo>\n        </Profile>\n";
  for (fmmu_use u : d.fmmus) x += "        <Fmmu>" + std::string(fmmu_name(u)) + "</Fmmu>\n";
  for (const sync_manager_description& sm : d.sync_managers) {
    x += "        <Sm DefaultSize=\"" + std::to_string(sm.length) + "\" StartAddress=\"" + hex(sm.start, 4) +
         "\" ControlByte=\"" + hex(sm.control, 2) + "\" Enable=\"" + std::to_string(sm.enable & 1) + "\">" +
         sm_name(sm.type) + "</Sm>\n";
  }
  pdos_xml(x, d.rx_pdos, "RxPdo");
  pdos_xml(x, d.tx_pdos, "TxPdo");
  if (d.coe) {
    const auto flag = [&](unsigned bit) { return (d.coe_details >> bit) & 1u ? "true" : "false"; };
    x += "        <Mailbox DataLinkLayer=\"true\">\n";
    x += std::string("          <CoE SdoInfo=\"") + flag(1) + "\" PdoAssign=\"" + flag(2) + "\" PdoConfig=\"" +
         flag(3) + "\" CompleteAccess=\"" + flag(5) + "\"/>\n";
    x += "        </Mailbox>\n";
  }
  if (d.dc_sync0) {
    // ETG.2000 <Dc>: the operation modes a configuration tool offers, with the 0x0980..0x0981 value
    // each writes (0x0300: cyclic unit and SYNC0 activated).
    x += "        <Dc>\n";
    x += "          <OpMode>\n            <Name>SM</Name>\n            <Desc>SM-synchronous</Desc>\n"
         "            <AssignActivate>#x0000</AssignActivate>\n          </OpMode>\n";
    x += "          <OpMode>\n            <Name>DC</Name>\n            <Desc>DC SYNC0</Desc>\n"
         "            <AssignActivate>#x0300</AssignActivate>\n"
         "            <CycleTimeSync0 Factor=\"1\">0</CycleTimeSync0>\n"
         "            <ShiftTimeSync0>0</ShiftTimeSync0>\n          </OpMode>\n";
    x += "        </Dc>\n";
  }
  const std::vector<std::uint8_t> image = sii_image(d);
  x += "        <Eeprom>\n          <ByteSize>" + std::to_string(image.size()) + "</ByteSize>\n          <ConfigData>";
  char byte[3];
  for (std::size_t i = 0; i < 16; ++i) {
    std::snprintf(byte, sizeof byte, "%02X", image[i]);
    x += byte;
  }
  x += "</ConfigData>\n        </Eeprom>\n";
  x += "      </Device>\n    </Devices>\n  </Descriptions>\n</EtherCATInfo>\n";
  return x;
}

}  // namespace cia402::ethercat
