// What an SDO server reads and writes, on either bus: the node's objects by index and sub-index, with
// SDO abort codes as results. The CANopen SDO server (canopen/301/sdo_server.hpp) and the CoE
// server (ethercat/slave/coe_server.hpp) speak their own framing over this one interface, which
// dictionary_access.hpp implements with the dictionary's rules.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "cia402/sdo_abort.hpp"

namespace cia402::dictionary {

/// Longest value a segmented download may carry, on CAN and on CoE alike.
inline constexpr std::size_t max_download = 1024;

class object_access {
 public:
  virtual ~object_access() = default;
  /// Whether a download of `size` bytes (if known) may start: existence, access, size.
  virtual sdo_abort check_download(std::uint16_t index, std::uint8_t sub, std::size_t size,
                                   bool size_known) noexcept = 0;
  /// The whole value. Without `size_indicated` (an expedited download that gave no size) the object
  /// takes as many bytes as its type needs.
  virtual sdo_abort download(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data,
                             bool size_indicated) noexcept = 0;
  virtual sdo_abort upload(std::uint16_t index, std::uint8_t sub,
                           std::vector<std::uint8_t>& data) noexcept = 0;
};

}  // namespace cia402::dictionary
