// The virtual CiA 402 drive's part of a dictionary, the same on every fieldbus: what it says it is
// (0x1000 device type, 0x1008..0x100A names, 0x1018 identity), its error register 0x1001, its
// manufacturer objects (0x2000 device label, 0x2001 fault injection: cia402/manufacturer_objects.hpp)
// and the drive objects of CiA 402 it has, from the core's one object table (cia402/objects.hpp).
// A fieldbus adds the communication objects it serves itself: the CANopen node 0x1005..0x1BFF
// (canopen/301/slave.hpp) and the CoE slave 0x1600.., 0x1A00.., 0x1C00, 0x1C12, 0x1C13
// (ethercat/slave/coe_slave.hpp).
//
// Choices, with the reason:
// - 0x1000 device type = 0x00020192: the low word is the device profile number, 402 = 0x0192; bits
//   16..23 are CiA 402's "type" field, 0x02 = servo drive; bits 24..31 are 0.
// - 0x1018 identity: vendor-ID 0 (no CiA-assigned ID), product code 0x00000402, revision 0x00010000,
//   serial number = the given serial + node-ID, so each virtual drive on a CAN bus differs (a CoE
//   dictionary has no node-ID: the serial alone, the slave's position + 1).
// - 0x1008 device name "cia402 virtual drive" and 0x2000 (device label, rw, up to 64 characters) are
//   VISIBLE_STRINGs longer than 4 bytes: they travel by segmented SDO transfer.
// - 0x2001 "fault injection" (wo, UNSIGNED16): writing an error code raises a fault cause in the
//   virtual drive, 0 clears every cause. Write-only because it is a command, not a state.
#pragma once

#include <cstdint>
#include <vector>

#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/manufacturer_objects.hpp"

namespace cia402::drive402 {

/// 0x1000: CiA 402 (0x0192), servo drive (0x02).
inline constexpr std::uint32_t device_type = 0x00020192;
/// 0x1018 sub 1..3.
inline constexpr std::uint32_t vendor_id = 0;
inline constexpr std::uint32_t product_code = 0x402;
inline constexpr std::uint32_t revision_number = 0x00010000;
/// 0x1009, 0x100A.
inline constexpr const char* hardware_version = "virtual";
inline constexpr const char* software_version = "0.1.0";

/// The drive's objects: 0x1000, 0x1001, 0x1008..0x100A, 0x1018 (sub 4 = `serial` + node-ID), 0x2000,
/// 0x2001 and the 0x6xxx objects; 0x1001, 0x2001 and the 0x6xxx objects are backed by the device
/// (sim_device), the rest stored.
std::vector<dictionary::object_entry> drive_objects(std::uint32_t serial = 0);

}  // namespace cia402::drive402
