#include "cia402/apps/bus_host.hpp"

#include <algorithm>
#include <cerrno>

#include "cia402/apps/elapsed_clock.hpp"
#include "cia402/canopen/transport/candump_log.hpp"

namespace cia402::apps {

bus_host::~bus_host() {
  bus_.observe({});
  flush_log();
}

std::error_code bus_host::log_frames(const std::string& path, const std::string& interface) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) return {errno, std::generic_category()};
  flush_log();
  log_.reset(file);
  log_interface_ = interface;
  log_failure_.clear();
  bus_.observe([this](const canopen::frame& f) { log(f); });
  return {};
}

void bus_host::log(const canopen::frame& f) noexcept {
  if (!log_) return;
  // The clock is read per frame: the bus carries frames from the sockets and from the drives at
  // different moments of a pass, and the log is to show when.
  std::string line;
  try {
    line = canopen::candump::format_line(f, unix_time_us(), log_interface_);
  } catch (...) {
    return;  // no memory for one line: the log misses it, the bus does not
  }
  line += '\n';
  if (std::fwrite(line.data(), 1, line.size(), log_.get()) != line.size()) {
    log_failure_ = {errno != 0 ? errno : EIO, std::generic_category()};
    log_.reset();  // the observer stays (this runs inside it) and finds no file from now on
    return;
  }
  ++frames_logged_;
  log_unflushed_ = true;
}

void bus_host::flush_log() noexcept {
  if (!log_ || !log_unflushed_) return;
  log_unflushed_ = false;
  if (std::fflush(log_.get()) != 0) {
    log_failure_ = {errno != 0 ? errno : EIO, std::generic_category()};
    log_.reset();
  }
}

virtual_drive_node& bus_host::add_drive(const profile& p,
                                                 const canopen::slave_config& config) {
  drives_.push_back(std::make_unique<virtual_drive_node>(p, bus_.attach(), config));
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
  flush_log();
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
