// Linux SocketCAN: a raw CAN socket on an interface (can0, vcan0, ...), non-blocking.
#pragma once

#include <memory>
#include <string>
#include <system_error>

#include "cia402/canopen/can/channel.hpp"

namespace cia402::canopen {

class socketcan_channel final : public channel {
 public:
  /// Opens a raw CAN socket bound to `interface`. Fails with the OS error: e.g. the kernel has no
  /// CAN support (address family not supported) or the interface does not exist (no such device).
  static std::unique_ptr<socketcan_channel> open(const std::string& interface, std::error_code& ec);
  ~socketcan_channel() override;

  std::error_code send(const frame& f) noexcept override;
  bool receive(frame& f) noexcept override;
  int native_handle() const noexcept override { return fd_; }
  std::error_code failure() const noexcept override { return failure_; }

 private:
  explicit socketcan_channel(int fd) : fd_(fd) {}
  int fd_;
  std::error_code failure_;
};

}  // namespace cia402::canopen
