// What the homing tests share (homing_test.cpp, start_test.cpp): the cycle and the revolution,
// the machines the figures are checked on, and one homing run from a shaft at rest, watched cycle
// by cycle.
#pragma once

#include <cstdint>

#include "cia402/motion/homing.hpp"

namespace cia402::motion::test {

inline constexpr std::uint32_t cycle_us = 1000;
inline constexpr std::int64_t revolution = 10000;

// floor(x / d) for d > 0.
inline std::int64_t floor_div(std::int64_t x, std::int64_t d) { return x / d - (x % d != 0 && x < 0 ? 1 : 0); }

// The machines: limit switches at -200,000 and +300,000, index pulses every revolution from 3,000,
// and a home switch that suits the method.
inline homing_machine with_home_switch(std::int64_t low, std::int64_t high) {
  homing_machine m;
  m.negative_limit = -200000;
  m.positive_limit = 300000;
  m.home_switch_low = low;
  m.home_switch_high = high;
  m.index_at = 3000;
  return m;
}
inline const homing_machine positive_home_switch = with_home_switch(50000, homing_machine::none_above);
inline const homing_machine negative_home_switch = with_home_switch(homing_machine::none_below, 50000);
inline const homing_machine cam = with_home_switch(50000, 80000);  // an edge either side

// A phase in which the run still looks for home; the cycle that leaves them found it.
inline bool searching(homing_phase p) {
  return p == homing_phase::not_started || p == homing_phase::searching_home_switch ||
         p == homing_phase::searching_limit_switch || p == homing_phase::searching_index_pulse;
}

struct homing_run {
  homing_status status;
  shaft s;
  std::int64_t offset = 0;
  long cycles = 0;  ///< cycles with bit 4 set, the last included
  // The cycle in which the run found home (its search ended): where the shaft was before and after.
  bool latched = false;
  std::int64_t latch_from = 0;
  std::int64_t latch_to = 0;
  std::int64_t latch_velocity = 0;
};

// One homing run (0x6098 = method, 0x607C = home_offset) from a shaft at rest as `start` is, with
// 0x6064's offset as given: bit 4 low for a cycle, then high until attained at rest or an error, or
// until max_cycles have passed.
inline homing_run home(int method, const homing_machine& m, const shaft& start, std::int64_t home_offset,
                       std::int64_t offset = 0, long max_cycles = 400000) {
  homing h;
  homing_parameters par;
  par.method = static_cast<std::int8_t>(method);
  par.home_offset = home_offset;
  homing_run r;
  r.s = start;
  r.offset = offset;
  h.step(false, par, m, r.s, r.offset, cycle_us);
  for (r.cycles = 1; r.cycles <= max_cycles; ++r.cycles) {
    const homing_phase before = h.phase();
    const std::int64_t from = r.s.position;
    r.status = h.step(true, par, m, r.s, r.offset, cycle_us);
    if (!r.latched && searching(before) && !searching(h.phase())) {
      r.latched = true;
      r.latch_from = from;
      r.latch_to = r.s.position;
      r.latch_velocity = r.s.velocity;
    }
    if (r.status.error || (r.status.attained && r.status.target_reached)) break;
  }
  return r;
}

// The same from a shaft standing exactly at `start`.
inline homing_run home(int method, const homing_machine& m, std::int64_t start, std::int64_t home_offset,
                       std::int64_t offset = 0, long max_cycles = 400000) {
  shaft s;
  s.position = start;
  return home(method, m, s, home_offset, offset, max_cycles);
}

}  // namespace cia402::motion::test
