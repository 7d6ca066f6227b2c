#include "cia402/page/runner.hpp"

namespace cia402::page {

cycle_runner::cycle_runner(backend& inst, std::chrono::microseconds cycle)
    : inst_(inst), cycle_(cycle.count() > 0 ? cycle : std::chrono::microseconds(1000)) {}

cycle_runner::~cycle_runner() { stop(); }

void cycle_runner::start() {
  if (thread_.joinable()) return;
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void cycle_runner::stop() {
  stopping_ = true;
  if (thread_.joinable()) thread_.join();
}

void cycle_runner::run() {
  using clock = std::chrono::steady_clock;
  // Falling this far behind (a stopped process, a loaded machine) skips the lost cycles rather
  // than running them in a burst: virtual time then lags wall time, the plot stays smooth.
  const auto max_lag = cycle_ * 100;
  auto next = clock::now();
  while (!stopping_.load(std::memory_order_relaxed)) {
    inst_.step();
    next += cycle_;
    const auto now = clock::now();
    if (now - next > max_lag) {
      next = now;
      skips_.fetch_add(1);
    }
    std::this_thread::sleep_until(next);
  }
}

}  // namespace cia402::page
