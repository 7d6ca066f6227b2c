// Real time for the page's backend: a thread that steps it once per cycle on the steady clock. The
// simulator and the CANopen stack never read a clock; the page layer does, here for the cycle and in
// server.cpp for the event stream's keep-alive.
#pragma once

#include <atomic>
#include <chrono>
#include <thread>

#include "cia402/page/backend.hpp"

namespace cia402::page {

class cycle_runner {
 public:
  /// The backend must outlive the runner.
  cycle_runner(backend& inst, std::chrono::microseconds cycle);
  ~cycle_runner();
  cycle_runner(const cycle_runner&) = delete;
  cycle_runner& operator=(const cycle_runner&) = delete;

  void start();
  /// Stops and joins the thread. Idempotent.
  void stop();
  /// Times the thread fell more than `max_lag` behind and skipped ahead instead of bursting.
  std::uint64_t skips() const noexcept { return skips_.load(); }

 private:
  void run();

  backend& inst_;
  std::chrono::microseconds cycle_;
  std::atomic<bool> stopping_{false};
  std::atomic<std::uint64_t> skips_{0};
  std::thread thread_;
};

}  // namespace cia402::page
