// Time in the stack is passed in, never read (CANopenNode's shape): every periodic function takes the
// microseconds elapsed since its last call and returns how long until it next wants to run.
#pragma once

#include <algorithm>
#include <cstdint>

namespace cia402::canopen {

/// "Nothing due": the value a periodic function returns when only a frame can wake it.
inline constexpr std::uint32_t no_deadline = 0xFFFFFFFFu;

/// The earlier of two deadlines.
constexpr std::uint32_t earliest(std::uint32_t a, std::uint32_t b) noexcept { return std::min(a, b); }

/// A countdown timer for one periodic duty. `period` 0 = off.
class interval_timer {
 public:
  void start(std::uint32_t period_us) noexcept { period_ = period_us; left_ = period_us; }
  void stop() noexcept { period_ = 0; left_ = 0; }
  bool running() const noexcept { return period_ != 0; }
  std::uint32_t period() const noexcept { return period_; }
  /// Advances by `elapsed`; true when the period has run out (then it starts again; a long gap
  /// fires once, not once per missed period).
  bool expired(std::uint32_t elapsed_us) noexcept {
    if (period_ == 0) return false;
    if (elapsed_us < left_) {
      left_ -= elapsed_us;
      return false;
    }
    left_ = period_;
    return true;
  }
  std::uint32_t left() const noexcept { return period_ == 0 ? no_deadline : left_; }

 private:
  std::uint32_t period_ = 0;
  std::uint32_t left_ = 0;
};

}  // namespace cia402::canopen
