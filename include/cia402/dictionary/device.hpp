// What a CANopen node sits on: the application behind the object dictionary. A device answers reads
// and writes of its objects by index and sub-index (the results are SDO abort codes), runs when the
// node gives it time, and hears about the fieldbus connection.
//
// The device tells its node what changed, as CANopenNode's application requests a TPDO
// (OD_requestTPDO) and reports an error (CO_errorReport): the node does not poll. Each object whose
// value the device changes by itself (in step(), reset() or as a side effect of a write to another
// object) is reported with changed(); a change of the device's error with error_changed(). The node
// samples an event-driven TPDO only when an object it maps was reported (or written by the node),
// and sends EMCY on the reported error.
//
// Implementations: drive402::sim_device (cia402/drive402/sim_device.hpp) over the simulator's virtual
// drive, and test doubles. A device is fieldbus-neutral: the CANopen node (slave.hpp) and the CoE slave
// (ethercat/slave) mount the same one.
#pragma once

#include <array>
#include <cstdint>

#include "cia402/sdo_abort.hpp"

namespace cia402::dictionary {

/// The node's side of a device's reports.
class device_events {
 public:
  virtual void object_changed(std::uint16_t index, std::uint8_t sub) noexcept = 0;
  /// The device's error code (0 = none) changed.
  virtual void error_changed(std::uint16_t code) noexcept = 0;

 protected:
  ~device_events() = default;
};

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
  /// Bytes 3..7 of an EMCY (the manufacturer-specific error field) at this moment. A CiA 402 drive
  /// puts its status word in the first two.
  virtual std::array<std::uint8_t, 5> manufacturer_error_field() const noexcept { return {}; }

  /// Where the device reports its changes: the node attaches itself (nullptr detaches).
  void attach(device_events* events) noexcept { events_ = events; }

 protected:
  void changed(std::uint16_t index, std::uint8_t sub) noexcept {
    if (events_ != nullptr) events_->object_changed(index, sub);
  }
  void error_changed(std::uint16_t code) noexcept {
    if (events_ != nullptr) events_->error_changed(code);
  }

 private:
  device_events* events_ = nullptr;
};

}  // namespace cia402::dictionary
