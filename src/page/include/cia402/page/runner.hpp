// Real time for the instrument: a thread that steps it once per cycle on the steady clock. The
// simulator never reads a clock; this is the one place that does.
#pragma once

#include <atomic>
#include <chrono>
#include <thread>

#include "cia402/page/instrument.hpp"

namespace cia402::page {

class cycle_runner {
 public:
  /// The instrument must outlive the runner.
  cycle_runner(instrument& inst, std::chrono::microseconds cycle);
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

  instrument& inst_;
  std::chrono::microseconds cycle_;
  std::atomic<bool> stopping_{false};
  std::atomic<std::uint64_t> skips_{0};
  std::thread thread_;
};

}  // namespace cia402::page
