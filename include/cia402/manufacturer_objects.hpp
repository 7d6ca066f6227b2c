// The manufacturer-specific objects (0x2000..0x5FFF, CiA 301 §7.4.1) of this project's virtual drive,
// and the device name (0x1008) a master knows it by. The drive (drive402) serves them on every
// fieldbus; a master (the CANopen drive master, the instrument page) uses them only on a device whose
// 0x1008 is `virtual_drive_device_name`.
#pragma once

#include <cstddef>
#include <cstdint>

namespace cia402 {

/// 0x1008 of every virtual drive.
inline constexpr const char* virtual_drive_device_name = "cia402 virtual drive";
/// 0x2000 device label: a VISIBLE_STRING a master may write (rw), up to 64 characters.
inline constexpr std::uint16_t device_label_index = 0x2000;
inline constexpr std::size_t device_label_capacity = 64;
/// 0x2001 fault injection: UNSIGNED16, write-only (a command, not a state). An error code raises a
/// fault cause in the virtual drive, 0 clears every cause.
inline constexpr std::uint16_t fault_injection_index = 0x2001;

}  // namespace cia402
