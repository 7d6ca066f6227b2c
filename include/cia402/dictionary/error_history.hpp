// The pre-defined error field 0x1003 (CiA 301 §7.5.2.5), the history of the errors a device
// signalled by emergency: newest first at sub-index 1, sub-index 0 the number of errors held.
// Writing 0 to sub-index 0 empties it; any other value is refused with 0x06090030; sub-indices
// 1..depth are read-only UNSIGNED32, the error code in bits 0..15 and the manufacturer's additional
// information in bits 16..31 (CiA 301). Empty entries read 0. It lives with the EMCY service: the
// CANopen node (slave.hpp) records the device's error codes and its own (0x8130, 0x8210), the CoE
// slave (ethercat/slave) its emergencies; both keep the values in their dictionary, so SDO, CoE
// and the EDS see one object.
#pragma once

#include <cstdint>

#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402::dictionary {

inline constexpr std::uint16_t error_history_index = 0x1003;
/// Errors held (CiA 301 allows 1..254): 8, as many as an EMCY consumer usually shows.
inline constexpr std::uint8_t error_history_depth = 8;

/// The object: an ARRAY, sub-index 0 rw UNSIGNED8, 1..depth ro UNSIGNED32, all 0. A dictionary
/// that keeps the list itself uses the default depth (record_error and write_error_history assume
/// it); one whose device keeps the list (a local plant) asks for the device's depth.
object_entry error_history_object(std::uint8_t depth = error_history_depth);

/// Records an error at sub-index 1; the others move down one, the oldest beyond the depth is
/// dropped. `info` goes into bits 16..31. Code 0 (the "error reset" EMCY) records nothing.
void record_error(object_dictionary& od, std::uint16_t code, std::uint16_t info) noexcept;

/// A write of `v` to 0x1003 sub-index `sub` that passed the dictionary's rules (so sub-index 0):
/// 0 empties the field, any other value is 0x06090030 and changes nothing.
sdo_abort write_error_history(object_dictionary& od, std::uint8_t sub, std::int64_t v) noexcept;

}  // namespace cia402::dictionary
