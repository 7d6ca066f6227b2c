// What an EtherCAT slave tells a master about itself before any mailbox runs: identity, mailbox and
// sync-manager layout, FMMU use and the default process data objects. One description gives both
// forms a master reads: the SII EEPROM image (ETG.1000.6 / ETG.2010), which the ESC serves through its
// EEPROM registers, and the ESI XML file (ETG.2000) a configuration tool imports. The image can be
// parsed back, which is how our own master reads a slave it finds on the wire.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cia402::ethercat {

/// One entry of a PDO: an object (index, sub-index) of `bits` bits, or padding (index 0).
struct pdo_entry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;
  std::uint16_t data_type = 0;  ///< CiA 301 data type index (0x0006 UNSIGNED16, ...), 0 for padding
  std::string name;
};

/// A PDO as the SII's TXPDO / RXPDO category and the ESI's <RxPdo>/<TxPdo> describe it.
struct pdo_description {
  std::uint16_t index = 0;      ///< 0x1600.. (RxPDO, outputs) or 0x1A00.. (TxPDO, inputs)
  std::uint8_t sync_manager = 0;  ///< 2 for outputs, 3 for inputs
  bool fixed = false;           ///< the mapping cannot be changed
  bool mandatory = true;        ///< assigned by default
  std::string name;
  std::vector<pdo_entry> entries;
  unsigned bit_size() const noexcept;
};

/// Sync-manager types (SII category SyncM, byte 7).
enum class sm_type : std::uint8_t { unused = 0, mailbox_out = 1, mailbox_in = 2, outputs = 3, inputs = 4 };

struct sync_manager_description {
  std::uint16_t start = 0;    ///< physical start address in the ESC
  std::uint16_t length = 0;   ///< bytes (process data SMs: as the default PDOs need)
  std::uint8_t control = 0;   ///< register 0x0804 as the master is to write it
  std::uint8_t enable = 1;    ///< register 0x0806: bit 0 enable
  sm_type type = sm_type::unused;
};

/// FMMU use (SII category FMMU).
enum class fmmu_use : std::uint8_t { unused = 0, outputs = 1, inputs = 2, sm_status = 3 };

struct slave_description {
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  std::uint32_t revision = 0;
  std::uint32_t serial = 0;
  std::string vendor_name;
  std::string device_name;   ///< the order name / type a tool shows
  std::string group_name;
  std::uint16_t station_alias = 0;
  /// Standard mailbox: receive (master -> slave, SM0) and send (slave -> master, SM1).
  std::uint16_t mailbox_out_start = 0x1000;
  std::uint16_t mailbox_out_size = 128;
  std::uint16_t mailbox_in_start = 0x1080;
  std::uint16_t mailbox_in_size = 128;
  bool coe = true;             ///< mailbox protocol CoE (SII word 0x1C bit 2)
  std::uint8_t coe_details = 0;  ///< SII General: bit 0 SDO, 1 SDO info, 2 PDO assign, 3 PDO config, 5 complete access
  /// SII General, physical ports (ETG.2010): 4 bits a port, 0 unused, 1 MII, 3 EBUS. Ports 0 and 1 MII,
  /// as the ESC's port descriptor (0x0007) and the ESI's Physics="YY" say.
  std::uint16_t physical_ports = 0x0011;
  std::vector<sync_manager_description> sync_managers;  ///< SM0, SM1, ...
  std::vector<fmmu_use> fmmus;
  std::vector<pdo_description> rx_pdos;  ///< outputs
  std::vector<pdo_description> tx_pdos;  ///< inputs
  std::uint16_t profile_number = 402;    ///< CiA device profile (ESI <Profile><ProfileNo>)
  /// The ESI offers DC: operation modes SM-synchronous and DC SYNC0 (AssignActivate 0x0300).
  bool dc_sync0 = false;
};

/// The SII EEPROM image: ESC configuration area with its CRC, identity, the standard mailbox (no
/// bootstrap mailbox: BOOT is not offered), then the
/// categories strings, general, FMMU, SyncM, TXPDO, RXPDO and the end marker; padded to a whole
/// number of KiBit as word 0x3E says.
std::vector<std::uint8_t> sii_image(const slave_description& d);

/// CRC-8 of the ESC configuration area (words 0..6), polynomial 0x07, initial value 0xFF, as
/// ETG.1000.6 requires in the low byte of word 7.
std::uint8_t sii_checksum(const std::uint8_t* first14) noexcept;

/// Reads an image back: std::nullopt with `error` set when it is not a sound SII (too short, bad
/// checksum, a category running past the end, no end marker).
std::optional<slave_description> parse_sii(const std::vector<std::uint8_t>& image, std::string& error);

/// The ESI file (EtherCATInfo XML) of the same description.
std::string esi_xml(const slave_description& d);

}  // namespace cia402::ethercat
