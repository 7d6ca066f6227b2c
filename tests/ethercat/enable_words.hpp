// The control word a bus test sends a drive through ecat_master's word API (send_control_word) on
// its way to OPERATION ENABLED, chosen from the status word the last cycle brought: a fault-reset
// edge in FAULT, Shutdown in SWITCH ON DISABLED, Switch on in READY TO SWITCH ON, Enable operation
// in SWITCHED ON and OPERATION ENABLED. The master carries words and steers nothing; a bus test that
// needs an enabled drive (to see its words carried) sends these, and what the steering does is
// tested on the axis session (tests/ethercat/ecat_session_steering_test.cpp). Shared by
// master_test.cpp, hostile_slave_test.cpp and tests/fuzz/ethercat_master_fuzz.cpp.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/master.hpp"
#include "cia402/profile.hpp"
#include "cia402/words.hpp"

namespace cia402::ethercat::testing {

inline std::uint16_t enable_word(std::uint16_t status, std::uint16_t last_sent) {
  state s = state::start;
  if (!decode_status(standard_profile(), status, s)) return 0;
  constexpr std::uint16_t shutdown = control_bit::enable_voltage | control_bit::quick_stop;
  switch (s) {
    case state::fault:  // bit 7 rising acts: low first if it was high
      return (last_sent & control_bit::fault_reset) ? 0 : control_bit::fault_reset;
    case state::switch_on_disabled: return shutdown;
    case state::ready_to_switch_on: return shutdown | control_bit::switch_on;
    case state::switched_on:
    case state::operation_enabled: return shutdown | control_bit::switch_on | control_bit::enable_operation;
    default: return shutdown;
  }
}

/// One cycle's word for drive `i` on the way to OPERATION ENABLED (send before the cycle).
inline void send_enable_word(ecat_master& m, std::size_t i) {
  const ecat_slave& s = m.slaves().at(i);
  m.send_control_word(i, enable_word(s.last_status, s.last_control));
}

}  // namespace cia402::ethercat::testing
