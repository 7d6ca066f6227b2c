// `cia402 ecat-slave`: virtual CiA 402 drives as a chain of EtherCAT slaves on a network interface.
// A raw socket (AF_PACKET, EtherType 0x88A4) bound to the interface takes each frame a master
// sends, passes it through every drive's controller in order, and sends it back, as the last slave
// of a real line does. Between frames each drive's application runs once per cycle of wall time
// (AL state machine, mailboxes, process data, the simulator), one drive at a time with the socket
// looked at between any two: a frame waits at most one drive's step, never a whole cycle of every
// drive or a catch-up after a stall, so its answer time depends on the frame alone. The
// controllers' clocks (DC system time, SYNC0, watchdogs) run on the host's clock to the nanosecond,
// brought up to it before every frame, not in the drives' 1 ms steps: a master reading 0x0910 sees
// it move between cycles, every controller of the line reads the same time, and a stalled host's
// time is not lost. Linux; needs CAP_NET_RAW (root).
#pragma once

#include <csignal>
#include <cstdint>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cia402/apps/elapsed_clock.hpp"
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
  /// One application cycle of every drive, with `elapsed_us` of their clocks.
  void cycle(std::uint32_t elapsed_us);
  /// `ns` more of every controller's clock (DC system time, SYNC0, watchdogs), no application step.
  void advance_clocks(std::uint64_t ns);
  /// `elapsed_us` more wall time, then at most one drive's application cycle of those it made due
  /// (at most 10 cycles are owed after a stall): true while drives' steps are still owed, so the
  /// caller answers frames between any two steps. The clocks are advance_clocks()'.
  bool step_one_drive(std::uint32_t elapsed_us);

  std::vector<std::unique_ptr<virtual_drive_slave>>& drives() noexcept { return drives_; }
  std::uint64_t frames_answered() const noexcept { return wire_.frames(); }
  std::uint64_t frames_refused() const noexcept { return wire_.refused_frames(); }

 private:
  void answer_waiting_frames(std::vector<std::uint8_t>& frame, elapsed_clock& controllers_clock);

  std::vector<std::unique_ptr<virtual_drive_slave>> drives_;
  ethercat::chain wire_;
  std::uint32_t cycle_us_;
  std::uint32_t owed_us_ = 0;   // wall time not yet given to the drives, at most 10 cycles
  std::size_t next_drive_ = 0;  // the next drive to step in the cycle under way; size(): none under way
  detail::raw_socket socket_;
};

}  // namespace cia402::apps
