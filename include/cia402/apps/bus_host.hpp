// `cia402 bus`: an in-process CAN bus with virtual CiA 402 drives on it, served to other processes
// over socketcand. One pass of its loop: the sockets (frames clients send go onto the bus at once),
// the time that passed for the server and every node, then the bus's frames out to the clients.
// `cycle()` takes the time from the caller (tests run it in virtual time); `run()` is the real-time
// loop that reads the clock.
#pragma once

#include <csignal>
#include <cstdint>
#include <memory>
#include <system_error>
#include <vector>

#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/402/virtual_drive_node.hpp"
#include "cia402/canopen/transport/socketcand.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/profile.hpp"

namespace cia402::apps {

class bus_host {
 public:
  explicit bus_host(const canopen::socketcand::server_config& config)
      : server_(std::make_unique<canopen::socketcand::server>(bus_, config)) {}

  /// A virtual drive as a node of the bus. The profile must outlive the host.
  canopen::virtual_drive_node& add_drive(const profile& p, const canopen::slave_config& config);
  /// Binds and listens: the socket error (e.g. address in use) if that fails.
  std::error_code open() { return server_->open(); }
  /// Replaces the server (closing its connections) with one of another configuration; the bus and
  /// its nodes stay. Call open() again.
  void restart_server(const canopen::socketcand::server_config& config);

  /// One pass: waits up to `wait_ms` for the sockets, then `elapsed_us` of time for the server and
  /// the nodes, then output. Returns the microseconds until a node next wants to run.
  std::uint32_t cycle(std::uint32_t elapsed_us, int wait_ms = 0);
  /// Passes with the time that really passed (waking at least every millisecond) until `stop`.
  void run(const volatile std::sig_atomic_t& stop);

  canopen::socketcand::server& server() noexcept { return *server_; }
  canopen::virtual_bus& bus() noexcept { return bus_; }
  std::vector<std::unique_ptr<canopen::virtual_drive_node>>& drives() noexcept { return drives_; }

 private:
  std::uint32_t advance(std::uint32_t elapsed_us);

  canopen::virtual_bus bus_;
  std::vector<std::unique_ptr<canopen::virtual_drive_node>> drives_;
  std::unique_ptr<canopen::socketcand::server> server_;
};

}  // namespace cia402::apps
