// CiA 306 electronic data sheet (EDS) of a node, printed from the node's own object dictionary table
// (its device's objects and its communication objects, slave.hpp), so the EDS and the node never
// disagree. Default values are the node's values
// at power-up, read from the live node: device-backed objects show the drive's defaults (e.g. 0x605A
// of the chosen profile), and objects the device does not have (0x06020000) are left out.
// Node-dependent defaults are written "$NODEID+0x180" as CiA 306 allows.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

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

}  // namespace cia402::canopen
