// The homing mode (CiA 402-2, mode 6) on virtual time: a homing run finds the machine's home
// position with the methods a simulated axis can offer, and then redefines the position so that home
// reads as the home offset 0x607C. Integers only, no heap, bounded work per cycle.
//
// Methods (0x6098):
//   3  the home switch on the positive side, the index pulse left of its edge: search the switch in
//      the positive direction at 0x6099 sub 1 (if it is not already active), leave it in the
//      negative direction at sub 2, and home at the first index pulse after it went inactive;
//   33 / 34 the first index pulse in the negative / positive direction, at 0x6099 sub 2;
//   35 / 37 the current position is home (35 is the older number of 37); no motion.
// Every velocity change is at the homing acceleration 0x609A. A search stops past the pulse it found
// and then goes back to stand exactly at home.
#pragma once

#include <cstdint>

#include "cia402/motion/trajectory.hpp"

namespace cia402::motion {

struct homing_parameters {
  std::int8_t method = 35;                   ///< 0x6098
  std::uint32_t switch_speed_rpm = 500;      ///< 0x6099 sub 1: searching the switch
  std::uint32_t zero_speed_rpm = 50;         ///< 0x6099 sub 2: searching the index pulse
  std::uint32_t acceleration_rpm_s = 1000;   ///< 0x609A, at least 1
  std::int64_t home_offset = 0;              ///< 0x607C: what home reads as afterwards
  std::uint32_t increments_per_rev = 10000;  ///< 0x608F
  /// The machine: the home switch is active at positions >= home_switch_at; an index pulse comes
  /// at index_at and every revolution from there.
  std::int64_t home_switch_at = 50000;
  std::int64_t index_at = 0;
};

/// Status bits of the homing mode: 12 homing attained, 10 target reached, 13 homing error. Together
/// (CiA 402-2): 0/0/0 in progress, 0/0/1 interrupted or not started, 1/0/0 attained but still
/// stopping, 1/0/1 done, error with 10 = the shaft has stopped.
struct homing_status {
  bool attained = false;
  bool target_reached = false;
  bool error = false;
};

class homing {
 public:
  /// The methods step() runs.
  static bool supports(std::int64_t method) noexcept {
    return method == 3 || method == 33 || method == 34 || method == 35 || method == 37;
  }
  /// How far a search may travel before it is given up (homing error): no switch or index found.
  static constexpr std::int64_t max_search_revolutions = 1000;

  /// Not started, at whatever the shaft does (as when the mode is entered).
  void reset() noexcept { *this = homing{}; }
  /// One cycle: `start` is control-word bit 4 (its rising edge starts a run, its fall interrupts
  /// one); moves `s` and, when home is found, redefines its position.
  homing_status step(bool start, const homing_parameters& par, shaft& s, std::uint32_t dt_us) noexcept;
  /// A stop from outside (halt, a quick stop) ends a running search: interrupted.
  void interrupt() noexcept;
  bool running() const noexcept { return phase_ != phase::idle && phase_ != phase::done && phase_ != phase::failed; }

 private:
  enum class phase : std::uint8_t { idle, search_switch, leave_switch, search_index, stopping, returning, done, failed };
  phase phase_ = phase::idle;
  bool last_start_ = false;
  std::int64_t home_at_ = 0;      // the index pulse found: in the old coordinates until at rest
  std::int64_t travelled_ = 0;    // increments since the run started, for the search limit
};

}  // namespace cia402::motion
