// CiA 306 electronic data sheet (EDS) of a node, printed from the node's own object dictionary table
// (its device's objects and its communication objects, slave.hpp), so the EDS and the node never
// disagree. Default values are the node's values
// at power-up, read from the live node: device-backed objects show the drive's defaults (e.g. 0x605A
// of the chosen profile), and objects the device does not have (0x06020000) are left out.
// Node-dependent defaults are written "$NODEID+0x180" as CiA 306 allows.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <map>
#include <utility>
#include <vector>
#include <string>

#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/canopen/301/slave.hpp"

namespace cia402::canopen {

struct eds_info {
  std::string file_name = "cia402-virtual-drive.eds";
  std::string description = "cia402 virtual drive (CiA 402 servo, profile velocity)";
  std::string created_by = "cia402 eds";
  std::string date = "01-01-2025";  ///< mm-dd-yyyy, as CiA 306 writes dates
  std::string time = "12:00PM";     ///< hh:mm(AM|PM)
  std::string vendor_name = "cia402 project";
  std::string product_name = "cia402 virtual drive";
  /// Non-zero: the node-ID the file is written for, in a [DeviceComissioning] section (CiA 306).
  std::uint8_t node_id = 0;
};

/// Writes the EDS of `node` (a freshly started node: its values are the defaults).
void write_eds(slave& node, const eds_info& info, std::ostream& out);

/// A DCF's present values (CiA 306 §4.6.4, ParameterValue), by index and sub-index, as the file
/// writes them (dcf_value_text for a number).
using dcf_values = std::map<std::pair<std::uint16_t, std::uint8_t>, std::string>;

/// A number as a DCF writes an entry of its type: decimal when signed, 0x-hexadecimal when not.
std::string dcf_value_text(const dictionary::sub_entry& e, std::int64_t value);

/// The entry's default value as write_dcf writes it (DefaultValue): a string's text, "$NODEID+X",
/// or dcf_value_text of the number. As a ParameterValue it reads back as the entry's value.
std::string dcf_entry_text(const dictionary::sub_entry& e);

/// Writes a device configuration file (CiA 306 DCF): `objects` as an EDS describes them, each entry
/// with a value in `values` with its ParameterValue too; read_eds (eds_reader.hpp) reads it back,
/// ParameterValue over DefaultValue. Objects without entries are left out.
void write_dcf(const std::vector<dictionary::object_entry>& objects, const dcf_values& values, const eds_info& info,
               std::ostream& out);

}  // namespace cia402::canopen
