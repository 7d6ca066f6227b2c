#include "baseline_switch.hpp"

namespace baseline {

output step(drive& d, std::uint16_t cw, bool fault_present) noexcept {
  const bool reset_edge = (cw & 0x80) && !d.last_reset;
  d.last_reset = (cw & 0x80) != 0;
  const bool disable_voltage = (cw & 0x02) == 0;
  const bool quick_stop = !disable_voltage && (cw & 0x04) == 0;
  const bool shutdown = !disable_voltage && !quick_stop && (cw & 0x01) == 0;
  const bool switch_on = !disable_voltage && !quick_stop && !shutdown && (cw & 0x08) == 0;
  const bool enable = !disable_voltage && !quick_stop && !shutdown && !switch_on;
  if (fault_present && d.current != state::reaction && d.current != state::fault) {
    d.current = state::reaction;
  } else {
    switch (d.current) {
      case state::not_ready: d.current = state::disabled; break;
      case state::disabled:
        if (shutdown) d.current = state::ready;
        break;
      case state::ready:
        if (switch_on || enable) d.current = state::switched_on;
        else if (disable_voltage || quick_stop) d.current = state::disabled;
        break;
      case state::switched_on:
        if (enable) d.current = state::enabled;
        else if (shutdown) d.current = state::ready;
        else if (disable_voltage || quick_stop) d.current = state::disabled;
        break;
      case state::enabled:
        if (switch_on) d.current = state::switched_on;
        else if (shutdown) d.current = state::ready;
        else if (disable_voltage) d.current = state::disabled;
        else if (quick_stop) d.current = state::quick_stop;
        break;
      case state::quick_stop: d.current = state::disabled; break;
      case state::reaction: d.current = state::fault; break;
      case state::fault:
        if (reset_edge && !fault_present) d.current = state::disabled;
        break;
    }
  }
  static constexpr std::uint16_t pattern[] = {0x00, 0x40, 0x21, 0x23, 0x27, 0x07, 0x0F, 0x08};
  const auto s = static_cast<unsigned>(d.current);
  return {static_cast<std::uint16_t>(pattern[s] | 0x0210),
          d.current == state::enabled || d.current == state::quick_stop};
}

std::uint16_t master_step(std::uint16_t sw, std::uint16_t& last) noexcept {
  std::uint16_t cw = 0x0F;
  if ((sw & 0x4F) == 0x08) {
    cw = (last & 0x80) ? 0x00 : 0x80;  // fault: pulse reset
  } else if ((sw & 0x4F) == 0x40) {
    cw = 0x06;
  } else if ((sw & 0x6F) == 0x21) {
    cw = 0x07;
  }
  last = cw;
  return cw;
}

}  // namespace baseline
