// `cia402 ecat-slave`: virtual CiA 402 drives as a chain of EtherCAT slaves on a network interface.
// A raw socket (AF_PACKET, EtherType 0x88A4) bound to the interface takes each frame a master
// sends, passes it through every drive's controller in order, and sends it back, as the last slave
// of a real line does. Between frames each drive's application runs once per cycle of wall time
// (AL state machine, mailboxes, process data, the simulator). Linux; needs CAP_NET_RAW (root).
#pragma once

#include <csignal>
#include <cstdint>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cia402/apps/raw_socket.hpp"
#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/profile.hpp"

namespace cia402::apps {

class ethercat_host {
 public:
  /// `nodes` drives of profile `p` (which must outlive the host), chained in order; each drive's
  /// serial number is its position + 1.
  ethercat_host(const profile& p, int nodes, std::uint32_t cycle_us = 1000);
  ~ethercat_host();
  ethercat_host(const ethercat_host&) = delete;
  ethercat_host& operator=(const ethercat_host&) = delete;

  /// Opens the raw socket on `interface`: the error (no such interface, no permission) if that fails.
  std::error_code open(const std::string& interface);
  /// Frames and cycles with the time that really passed until `stop`.
  void run(const volatile std::sig_atomic_t& stop);

  /// One frame from the wire: through every controller; false when it is not a sound EtherCAT
  /// frame (it is then not answered, as a line does not answer garbage).
  bool pass(std::vector<std::uint8_t>& frame);
  /// One application cycle of every drive.
  void cycle(std::uint32_t elapsed_us);

  std::vector<std::unique_ptr<virtual_drive_slave>>& drives() noexcept { return drives_; }
  std::uint64_t frames_answered() const noexcept { return wire_.frames(); }
  std::uint64_t frames_refused() const noexcept { return wire_.refused_frames(); }

 private:
  std::vector<std::unique_ptr<virtual_drive_slave>> drives_;
  ethercat::chain wire_;
  std::uint32_t cycle_us_;
  detail::raw_socket socket_;
};

}  // namespace cia402::apps
