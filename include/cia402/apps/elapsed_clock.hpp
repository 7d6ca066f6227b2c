// The wall clock as the layers below take time: microseconds passed since the last call, and the
// time of day a log line carries. The only clock the project's loops read (the page's cycle thread
// and HTTP keep-alive aside); everything below the apps layer is handed time and never reads it.
#pragma once

#include <chrono>
#include <cstdint>

namespace cia402::apps {

/// Microseconds since the Unix epoch (the system clock): the time stamped on a frame in a log.
inline std::uint64_t unix_time_us() {
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  return us < 0 ? 0 : static_cast<std::uint64_t>(us);
}

class elapsed_clock {
 public:
  elapsed_clock() : last_(clock::now()) {}

  /// Microseconds since the last take() (or construction), at most `cap_us`: a process that was
  /// stopped for a while goes on from where it was instead of replaying the gap.
  std::uint32_t take(std::uint32_t cap_us = 1000000) {
    const auto now = clock::now();
    const auto us = std::chrono::duration_cast<std::chrono::microseconds>(now - last_).count();
    const auto step = static_cast<std::uint32_t>(us < 0 ? 0 : (us > cap_us ? cap_us : us));
    last_ = us > cap_us ? now : last_ + std::chrono::microseconds(step);
    return step;
  }
  /// Nanoseconds since the last take_ns() (or construction), not capped: for a clock that keeps the
  /// host's time across a stall (an emulated controller's system time). One instance takes one or
  /// the other, never both.
  std::uint64_t take_ns() {
    const auto now = clock::now();
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now - last_).count();
    if (ns <= 0) return 0;
    last_ += std::chrono::nanoseconds(ns);
    return static_cast<std::uint64_t>(ns);
  }

 private:
  using clock = std::chrono::steady_clock;
  clock::time_point last_;
};

}  // namespace cia402::apps
