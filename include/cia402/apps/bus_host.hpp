// `cia402 bus`: an in-process CAN bus with virtual CiA 402 drives on it, served to other processes
// over socketcand. One pass of its loop: the sockets (frames clients send go onto the bus at once),
// the time that passed for the server and every node, then the bus's frames out to the clients.
// `cycle()` takes the time from the caller (tests run it in virtual time); `run()` is the real-time
// loop that reads the clock. With a log (`cia402 bus --log FILE`) every frame the bus carries, from a
// client or from a drive, is written in candump's log format, stamped with the wall clock.
#pragma once

#include <csignal>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cia402/canopen/301/slave.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/transport/socketcand.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/profile.hpp"

namespace cia402::apps {

class bus_host {
 public:
  explicit bus_host(const canopen::socketcand::server_config& config)
      : server_(std::make_unique<canopen::socketcand::server>(bus_, config)) {}
  ~bus_host();
  bus_host(const bus_host&) = delete;
  bus_host& operator=(const bus_host&) = delete;

  /// A virtual drive as a node of the bus. The profile must outlive the host.
  virtual_drive_node& add_drive(const profile& p, const canopen::slave_config& config);
  /// Binds and listens: the socket error (e.g. address in use) if that fails.
  std::error_code open() { return server_->open(); }
  /// From now on writes every frame the bus carries to `path` (created, or emptied) in candump's log
  /// format (`canopen/transport/candump_log.hpp`) as interface `interface`, stamped with the wall
  /// clock as the bus carries it, and flushed after each pass that wrote, so a reader sees frames
  /// within a millisecond or so. The error if the file cannot be opened; nothing changes then.
  std::error_code log_frames(const std::string& path, const std::string& interface);
  /// Why the log stopped (a write failed, e.g. the disk is full): the bus goes on without it.
  std::error_code log_failure() const noexcept { return log_failure_; }
  /// Frames written to the log so far.
  std::uint64_t frames_logged() const noexcept { return frames_logged_; }
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
  std::vector<std::unique_ptr<virtual_drive_node>>& drives() noexcept { return drives_; }

 private:
  std::uint32_t advance(std::uint32_t elapsed_us);
  void log(const canopen::frame& f) noexcept;
  void flush_log() noexcept;

  struct file_closer {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
  };

  canopen::virtual_bus bus_;
  std::vector<std::unique_ptr<virtual_drive_node>> drives_;
  std::unique_ptr<canopen::socketcand::server> server_;
  std::unique_ptr<std::FILE, file_closer> log_;
  std::string log_interface_;
  bool log_unflushed_ = false;
  std::uint64_t frames_logged_ = 0;
  std::error_code log_failure_;
};

}  // namespace cia402::apps
