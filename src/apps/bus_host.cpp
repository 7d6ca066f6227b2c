#include "cia402/apps/bus_host.hpp"

#include <algorithm>

#include "cia402/apps/elapsed_clock.hpp"

namespace cia402::apps {

canopen::virtual_drive_node& bus_host::add_drive(const profile& p,
                                                 const canopen::slave_config& config) {
  drives_.push_back(std::make_unique<canopen::virtual_drive_node>(p, bus_.attach(), config));
  return *drives_.back();
}

void bus_host::restart_server(const canopen::socketcand::server_config& config) {
  server_.reset();
  server_ = std::make_unique<canopen::socketcand::server>(bus_, config);
}

std::uint32_t bus_host::cycle(std::uint32_t elapsed_us, int wait_ms) {
  server_->poll_sockets(wait_ms);
  return advance(elapsed_us);
}

std::uint32_t bus_host::advance(std::uint32_t elapsed_us) {
  server_->advance(elapsed_us);
  // The time first, then the frames: they came in at some moment of the interval, and taking them
  // at its end means that a host held up (a loaded machine) steps its drives through the time that
  // passed before it answers the SYNCs queued meanwhile, so TPDOs show where the drives now are.
  for (auto& d : drives_) (void)d->node().process(elapsed_us);
  std::uint32_t next_us = canopen::no_deadline;
  for (auto& d : drives_) next_us = std::min(next_us, d->poll(0));
  server_->flush();
  return next_us;
}

void bus_host::run(const volatile std::sig_atomic_t& stop) {
  // Each pass hands the nodes the time that really passed; the drives step their plants in 1 ms
  // cycles of it.
  elapsed_clock clock;
  std::uint32_t next_us = 1000;
  while (stop == 0) {
    server_->poll_sockets(next_us == 0 ? 0 : 1);  // wake at least every millisecond
    next_us = advance(clock.take());
  }
}

}  // namespace cia402::apps
