// The object dictionary of a CiA 402 drive node: the communication objects of CiA 301 and the drive
// objects of CiA 402 that the virtual drive has. The slave serves this table and `cia402 eds` prints
// it; nothing else lists objects.
//
// Choices, with the reason:
// - 0x1000 device type = 0x00020192: the low word is the device profile number, 402 = 0x0192; bits
//   16..23 are CiA 402's "type" field, 0x02 = servo drive; bits 24..31 are 0.
// - 0x1018 identity: vendor-ID 0 (no CiA-assigned ID), product code 0x00000402, revision 0x00010000,
//   serial number = node-ID, so each virtual drive on a bus differs.
// - 0x1008 device name "cia402 virtual drive" and 0x2000 (device label, rw, up to 64 characters) are
//   VISIBLE_STRINGs longer than 4 bytes: they travel by segmented SDO transfer.
// - 0x2001 "fault injection" (wo, UNSIGNED16): writing an error code raises a fault cause in the
//   virtual drive, 0 clears every cause. Write-only because it is a command, not a state.
// - PDO defaults are the CiA 402 predefined set (as drive manuals restate it, e.g. Kollmorgen S300
//   CANopen manual §5.3.1.3): RPDO1 = 0x6040; RPDO2 = 0x6040 + 0x6060; RPDO3 = 0x6040 + 0x607A
//   (target position); RPDO4 = 0x6040 + 0x60FF. TPDO1 = 0x6041; TPDO2 = 0x6041 + 0x6061; TPDO3 =
//   0x6041 + 0x6064 (position actual value); TPDO4 = 0x6041 + 0x606C. PDO 3 is what a cyclic
//   synchronous position master needs, so it is synchronous (transmission type 1: RPDO3 takes effect
//   at the next SYNC, TPDO3 goes out on every SYNC); the others are event-driven (255). Every
//   event-driven TPDO has an event timer of 1000 ms (a master can rely on hearing each one every
//   second) and TPDO4, which carries the velocity, an inhibit time of 10 ms (at most 100 frames/s
//   while the drive ramps, where it sent about 850).
// - 0x1016 has 4 consumer entries; 0x1017 defaults to 0 (no heartbeat) as CiA 301 does.
#pragma once

#include <cstdint>
#include <vector>

#include "cia402/canopen/301/object_dictionary.hpp"
#include "cia402/canopen/301/slave.hpp"

namespace cia402::canopen {

inline constexpr std::uint32_t device_type_cia402_servo = 0x00020192;
/// 0x1008 of every virtual drive: how a master tells a `cia402 bus` node (and its 0x2001) apart.
inline constexpr const char* virtual_drive_device_name = "cia402 virtual drive";
inline constexpr std::uint16_t fault_injection_index = 0x2001;
inline constexpr std::uint16_t device_label_index = 0x2000;
inline constexpr std::size_t device_label_capacity = 64;

/// The table; 0x6xxx objects and 0x2001 are backed by the device.
std::vector<object_entry> drive_objects();

/// A node configuration that serves the drive's table: what a CiA 402 node is built with.
slave_config drive_node_config(std::uint8_t node_id, std::uint32_t sdo_timeout_us = 1000000,
                               std::uint16_t heartbeat_ms = 0);

}  // namespace cia402::canopen
