// What a CANopen node sits on: the application behind the object dictionary. A device answers reads
// and writes of its objects by index and sub-index (the results are SDO abort codes), runs when the
// node gives it time, and hears about the fieldbus connection. The node learns of faults by reading
// 0x603F / 0x1001 after each step, so a device needs no callback into the node.
//
// Implementations: sim_device (sim_device.hpp) over the simulator's virtual drive, and test doubles.
#pragma once

#include <cstdint>

#include "cia402/sdo_abort.hpp"

namespace cia402::canopen {

class device {
 public:
  virtual ~device() = default;
  /// Reads an object. Signed values come sign-extended.
  virtual sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& value) noexcept = 0;
  /// Writes an object; a refused write changes nothing.
  virtual sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t value) noexcept = 0;
  /// Gives the device `elapsed_us` of time; returns how long until it next wants to run.
  virtual std::uint32_t step(std::uint32_t elapsed_us) noexcept = 0;
  /// The fieldbus connection was lost (heartbeat consumer timeout) or is back: 0x6007 applies (S10).
  virtual void set_connection_lost(bool lost) noexcept = 0;
  /// Reset application (NMT reset node): the device starts again as at power-on.
  virtual void reset() noexcept = 0;
};

}  // namespace cia402::canopen
