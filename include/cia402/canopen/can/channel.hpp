// The one interface between the CANopen stack and a CAN network (lely-core's shape): send a frame,
// take the next received frame. Implementations: the in-process virtual bus (virtual_bus.hpp),
// socketcand over TCP (socketcand.hpp) and Linux SocketCAN (socketcan.hpp). Neither call blocks.
#pragma once

#include <string>
#include <system_error>

#include "cia402/canopen/can/frame.hpp"

namespace cia402::canopen {

class channel {
 public:
  virtual ~channel() = default;
  /// Queues one frame for the bus. An error says why it was not sent (e.g. the connection is gone,
  /// the queue is full); the frame is then dropped, as a CAN controller drops it on bus-off.
  virtual std::error_code send(const frame& f) noexcept = 0;
  /// Takes the next received frame; false when there is none now.
  virtual bool receive(frame& f) noexcept = 0;
  /// A file descriptor to poll() for input, or -1 (the in-process bus).
  virtual int native_handle() const noexcept { return -1; }
  /// Set once the channel can no longer send or receive (peer closed, interface down), with why.
  virtual std::error_code failure() const noexcept { return {}; }
};

}  // namespace cia402::canopen
