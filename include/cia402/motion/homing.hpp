// The homing mode (CiA 402-2, mode 6) on virtual time: a homing run finds the machine's home
// position by the method 0x6098 names, then sets the offset between the shaft and the position the
// drive reports so that home reads as the home offset 0x607C. Integers only, no heap, bounded work
// per cycle.
//
// The switches and index pulses are places on the shaft (homing_machine, in the shaft's own
// increments): a run moves the shaft and changes the offset, never where they are, so the same
// run from the same place finds the same home every time.
//
// Methods (CiA 402-2, figures of methods 1..35, 37):
//   1 / 2    the negative / positive limit switch, then the first index pulse beyond its edge;
//   3 .. 6   a home switch on the positive (3, 4) or negative (5, 6) side, the index pulse left (3, 6)
//            or right (4, 5) of its edge; the first move depends on whether the switch is active;
//   7 .. 14  a home switch with an edge on each side: 7..10 start in the positive direction and
//            reverse at the positive limit switch, 11..14 the mirror image; home at the index pulse
//            left / right of the lower edge (7, 8 / 14, 13) or the upper edge (9, 10 / 12, 11);
//   17 .. 30 as 1 .. 14, without the index pulse: home is the edge itself;
//   33 / 34  the first index pulse in the negative / positive direction that the shaft reaches.
// An index pulse is latched on its edge as the shaft moves across it, as an encoder latch does: a
// run of 33 / 34 started standing exactly on a pulse does not take that one, it searches on to the
// next, a revolution on. (1..14 search their pulse only after an edge, moving.)
//   35 / 37  the present position is home (35 is the older number of 37); no motion.
// A method's first move (and its first move after a reversal at a limit switch) runs at 0x6099
// sub 1; the moves after it, which find the edge home is measured from, and the search for the
// index pulse at sub 2; every velocity change at 0x609A. A limit switch met where the method does
// not expect one, or a search that travels max_search_revolutions without finding its switch or
// pulse, ends the run with a homing error. Once home is found the drive stops past it, sets the
// offset and goes back to stand exactly at home.
#pragma once

#include <cstdint>

#include "cia402/motion/trajectory.hpp"

namespace cia402::motion {

/// The objects of a homing run (0x6098, 0x6099, 0x609A, 0x607C, 0x608F).
struct homing_parameters {
  std::int8_t method = 35;                   ///< 0x6098
  std::uint32_t switch_speed_rpm = 1000;     ///< 0x6099 sub 1: searching a switch
  std::uint32_t zero_speed_rpm = 100;        ///< 0x6099 sub 2: the edge and the index pulse
  std::uint32_t acceleration_rpm_s = 10000;  ///< 0x609A, at least 1
  std::int64_t home_offset = 0;              ///< 0x607C: what home reads as afterwards
  std::uint32_t increments_per_rev = 10000;  ///< 0x608F
};

/// The machine's switches and index pulses, in the shaft's own increments: fixed places that a
/// homing run never moves. A switch is active over a range of positions; its edge is the first
/// position of the other state.
struct homing_machine {
  static constexpr std::int64_t none_below = INT64_MIN;
  static constexpr std::int64_t none_above = INT64_MAX;
  /// The negative limit switch is active below this position (none_below: not fitted).
  std::int64_t negative_limit = none_below;
  /// The positive limit switch is active above this position (none_above: not fitted).
  std::int64_t positive_limit = none_above;
  /// The home switch is active from home_switch_low to home_switch_high, both included (none_below
  /// / none_above: from / to the end of travel; low > high: no home switch).
  std::int64_t home_switch_low = 50000;
  std::int64_t home_switch_high = none_above;
  /// An index pulse at index_at and every revolution (0x608F increments) from there.
  std::int64_t index_at = 0;

  bool negative_limit_active(std::int64_t at) const noexcept { return at < negative_limit; }
  bool positive_limit_active(std::int64_t at) const noexcept { return at > positive_limit; }
  bool home_switch_active(std::int64_t at) const noexcept {
    return at >= home_switch_low && at <= home_switch_high;
  }
  /// A shaft that moved from `from` to `to` reached an index pulse: one lies in (from, to] going up,
  /// [to, from) going down, or at `from` when it stands still.
  bool index_pulse_between(std::int64_t from, std::int64_t to, std::uint32_t increments_per_rev) const noexcept;
};

/// Status bits of the homing mode: 12 homing attained, 10 target reached, 13 homing error. Together
/// (CiA 402-2): 0/0/0 in progress, 0/0/1 interrupted or not started, 1/0/0 attained but still
/// stopping, 1/0/1 done, error with 10 = the shaft has stopped.
struct homing_status {
  bool attained = false;
  bool target_reached = false;
  bool error = false;
  /// The speed 0x6099 asks for was cut to the speed limit (status bit 11).
  bool limited = false;
};

/// What a homing run is doing, for a display: homing_phase_name() says it in words.
enum class homing_phase : std::uint8_t {
  not_started,
  searching_home_switch,
  searching_limit_switch,
  searching_index_pulse,
  stopping_past_home,
  moving_to_zero,
  attained,
  interrupted,
  error,
};

/// "not started", "searching home switch", "searching limit switch", "searching index pulse",
/// "stopping past home", "moving to zero", "homing attained", "interrupted", "homing error".
const char* homing_phase_name(homing_phase p) noexcept;

class homing {
 public:
  /// The methods step() runs; 0x60E3 lists the same.
  static bool supports(std::int64_t method) noexcept {
    return (method >= 1 && method <= 14) || (method >= 17 && method <= 30) || method == 33 ||
           method == 34 || method == 35 || method == 37;
  }
  /// How far a search may travel before it is given up (homing error): no switch or index found.
  static constexpr std::int64_t max_search_revolutions = 1000;

  /// Not started, at whatever the shaft does (as when the mode is entered). `start_now` is control
  /// bit 4 as it is now: it counts as the previous value, so entering the mode with bit 4 already 1
  /// starts nothing; only a 0->1 edge after it does.
  void reset(bool start_now = false) noexcept {
    *this = homing{};
    last_start_ = start_now;
  }
  /// A cycle in which the mode does not move the shaft (the drive not enabled, the brake still
  /// releasing, a stop or a halt running): a running search is interrupted. Bit 4 held 1 through
  /// such cycles is no new edge; once it falls, its next rise starts a run, at the first cycle the
  /// mode moves again.
  void stand_by(bool start_bit) noexcept {
    interrupt();
    last_start_ = last_start_ && start_bit;
  }
  /// One cycle: `start` is control-word bit 4 (its rising edge starts a run, its fall interrupts
  /// one). `s` is the shaft in its own increments, which the run moves; `offset` is what the drive
  /// adds to s.position to report its position (0x6064), which the run sets once home is found.
  /// The speeds are cut to `speed_limit_rpm` (0x607F / 0x6080).
  homing_status step(bool start, const homing_parameters& par, const homing_machine& m, shaft& s,
                     std::int64_t& offset, std::uint32_t dt_us,
                     std::uint32_t speed_limit_rpm = UINT32_MAX) noexcept;
  /// A stop from outside (halt, a quick stop) ends a running search: interrupted.
  void interrupt() noexcept;
  bool running() const noexcept {
    return stage_ != stage::idle && stage_ != stage::done && stage_ != stage::failed;
  }
  homing_phase phase() const noexcept;

 private:
  enum class stage : std::uint8_t { idle, searching, index, stopping, returning, done, failed };

  void start(const homing_parameters& par, const homing_machine& m, shaft& s, std::int64_t& offset) noexcept;
  void follow_plan(std::int8_t method, const homing_machine& m, std::int64_t here, bool after_limit) noexcept;
  void edge_found(const homing_machine& m, std::int64_t resolution, std::int64_t here) noexcept;
  std::int64_t first_pulse_ahead(const homing_machine& m, std::int64_t resolution, const shaft& s) const noexcept;
  void search(const homing_parameters& par, const homing_machine& m, const shaft& s) noexcept;

  stage stage_ = stage::idle;
  bool last_start_ = false;
  bool interrupted_ = false;
  bool index_after_edge_ = false;  // the method homes on the index pulse after its edge
  std::int8_t method_ = 0;         // the method running (0x6098 at its start)
  std::uint8_t plan_ = 0;          // which of the method's moves it makes (homing.cpp)
  std::uint8_t leg_at_ = 0;        // the move it is at
  std::int8_t final_direction_ = 0;
  std::int64_t home_at_ = 0;     // where home is on the shaft, once found
  std::int64_t travelled_ = 0;   // increments since the run started, for the search limit
};

}  // namespace cia402::motion
