// The virtual CiA 402 drive as an EtherCAT CoE slave: its object dictionary and what its SII and
// ESI say about it. The drive objects and the identity are the CANopen node's (canopen/402
// drive_objects(), itself built from the one CiA 402 object table); CoE replaces the CAN-only
// communication objects (SYNC, EMCY and PDO COB-IDs, heartbeat, SDO server channel) by the sync
// manager objects of ETG.1000.6: 0x1C00 communication types, 0x1C12 / 0x1C13 PDO assignment.
//
// Default process data, enough for a cyclic synchronous position master and every other mode:
//   RxPDO 0x1600 (SM2, outputs, 13 bytes): 0x6040 controlword, 0x607A target position, 0x60FF target
//     velocity, 0x6071 target torque, 0x6060 modes of operation;
//   TxPDO 0x1A00 (SM3, inputs, 19 bytes): 0x6041 statusword, 0x6064 position actual value, 0x606C
//     velocity actual value, 0x6077 torque actual value, 0x6061 modes of operation display, 0x603F
//     error code, 0x60F4 following error actual value (a master sees a following error growing).
// Both mappings and both assignments are writable in PRE-OP (a master may map what it wants); a
// second pair 0x1601 / 0x1A01 starts empty and unassigned.
//
// Memory: SM0 (mailbox out) 0x1000, 128 bytes; SM1 (mailbox in) 0x1080, 128 bytes; SM2 (outputs)
// 0x1100; SM3 (inputs) 0x1180; each process data SM as long as its assigned PDOs.
#pragma once

#include <cstdint>
#include <vector>

#include "cia402/canopen/301/object_dictionary.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"

namespace cia402::ethercat {

inline constexpr std::uint16_t mailbox_out_start = 0x1000;
inline constexpr std::uint16_t mailbox_in_start = 0x1080;
inline constexpr std::uint16_t mailbox_size = 128;
inline constexpr std::uint16_t outputs_start = 0x1100;
inline constexpr std::uint16_t inputs_start = 0x1180;
/// Most bytes a process data SM may take (the room between SM2 and SM3, and after SM3).
inline constexpr std::uint16_t max_process_data = 0x80;
/// Entries a PDO mapping object holds.
inline constexpr int max_pdo_entries = 12;

/// The CoE dictionary of the virtual drive, sorted by index.
std::vector<canopen::object_entry> coe_drive_objects();

/// SII / ESI description of the virtual drive whose dictionary is `objects` (its identity 0x1018,
/// names 0x1008, the PDOs its 0x1C12 / 0x1C13 assign as their defaults say).
slave_description drive_slave_description(const std::vector<canopen::object_entry>& objects,
                                          std::uint32_t serial = 0);

}  // namespace cia402::ethercat
