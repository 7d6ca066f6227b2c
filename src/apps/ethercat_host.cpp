#include "cia402/apps/ethercat_host.hpp"

#include <linux/if_packet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <ctime>

#include "cia402/apps/elapsed_clock.hpp"
#include "raw_ethercat_socket.hpp"

namespace cia402::apps {

ethercat_host::ethercat_host(const profile& p, int nodes, std::uint32_t cycle_us) : cycle_us_(cycle_us) {
  for (int i = 0; i < nodes; ++i) {
    drives_.push_back(std::make_unique<virtual_drive_slave>(p, static_cast<std::uint32_t>(i + 1), sim::plant_config{}, cycle_us));
    wire_.add(drives_.back()->controller());
    drives_.back()->slave().keep_clock_outside();
  }
  next_drive_ = drives_.size();  // no cycle under way until one is due
}

ethercat_host::~ethercat_host() {
  if (socket_.fd >= 0) ::close(socket_.fd);
}

std::error_code ethercat_host::open(const std::string& interface) {
  return detail::open_raw_ethercat_socket(interface, socket_);
}

bool ethercat_host::pass(std::vector<std::uint8_t>& frame) {
  if (wire_.pass(frame) != ethercat::frame_error::none) return false;
  // As an ESC's port 0 does on the way back: the source address marked locally administered, so a
  // master tells its own outgoing frame from the answer.
  frame[6] |= 0x02;
  return true;
}

void ethercat_host::cycle(std::uint32_t elapsed_us) {
  advance_clocks(std::uint64_t{elapsed_us} * 1000);
  for (auto& d : drives_) d->step(elapsed_us);
}

void ethercat_host::advance_clocks(std::uint64_t ns) {
  for (auto& d : drives_) d->controller().advance(ns);
}

bool ethercat_host::step_one_drive(std::uint32_t elapsed_us) {
  // Catch up at most a few cycles: a stalled host does not replay a second of drive time at once.
  const std::uint32_t most_owed = cycle_us_ * 10;
  owed_us_ = elapsed_us >= most_owed - owed_us_ ? most_owed : owed_us_ + elapsed_us;
  if (next_drive_ >= drives_.size()) {
    if (owed_us_ < cycle_us_) return false;
    owed_us_ -= cycle_us_;
    next_drive_ = 0;
  }
  if (next_drive_ < drives_.size()) drives_[next_drive_++]->step(cycle_us_);
  return next_drive_ < drives_.size() || owed_us_ >= cycle_us_;
}

void ethercat_host::answer_waiting_frames(std::vector<std::uint8_t>& frame, elapsed_clock& controllers_clock) {
  // Every frame waiting, answered at once: a master's cycle is a frame and its answer.
  for (int burst = 0; burst < 64 && socket_.fd >= 0; ++burst) {
    sockaddr_ll from{};
    socklen_t from_len = sizeof from;
    frame.resize(ethercat::maximum_frame_size + 4);
    const ssize_t n = ::recvfrom(socket_.fd, frame.data(), frame.size(), MSG_DONTWAIT,
                                 reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n <= 0) break;
    if (from.sll_pkttype == PACKET_OUTGOING) continue;  // our own answer, seen going out
    frame.resize(static_cast<std::size_t>(n));
    advance_clocks(controllers_clock.take_ns());  // the frame finds the time it arrives at
    if (!pass(frame)) continue;
    (void)detail::send_raw_frame(socket_, frame);
  }
}

void ethercat_host::run(const volatile std::sig_atomic_t& stop) {
  elapsed_clock clock;
  elapsed_clock controllers_clock;  // to the nanosecond, not capped
  std::vector<std::uint8_t> frame(ethercat::maximum_frame_size + 4);
  bool steps_owed = false;
  while (stop == 0) {
    if (!steps_owed) {
      // Sleep until a frame comes or the next cycle is due, to the microsecond: no busy loop.
      pollfd p{socket_.fd, POLLIN, 0};
      const std::uint32_t wait_us = cycle_us_ > owed_us_ ? cycle_us_ - owed_us_ : 0;
      const timespec wait{0, static_cast<long>(wait_us) * 1000};
      (void)::ppoll(&p, 1, &wait, nullptr);
    }
    advance_clocks(controllers_clock.take_ns());  // a SYNC0 pulse or a watchdog the step takes
    answer_waiting_frames(frame, controllers_clock);
    steps_owed = step_one_drive(clock.take());
  }
}

}  // namespace cia402::apps
