// Helpers for the operation-mode tests: a virtual drive driven through its objects as a master
// drives it (SDO-like reads and writes, the enable sequence in a mode, stepping until something
// holds).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>

#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace mode_test {

using cia402::sdo_abort;
using cia402::standard_profile;
using cia402::state;
using cia402::sim::virtual_drive;

constexpr std::uint16_t bit10 = 1u << 10, bit11 = 1u << 11, bit12 = 1u << 12, bit13 = 1u << 13;

inline std::int64_t read(virtual_drive& d, std::uint16_t index, std::uint8_t sub = 0) {
  std::int64_t v = 0;
  EXPECT_EQ(d.read(index, sub, v), sdo_abort::none) << std::hex << index;
  return v;
}

inline void write(virtual_drive& d, std::uint16_t index, std::int64_t value, std::uint8_t sub = 0) {
  ASSERT_EQ(d.write(index, sub, value), sdo_abort::none) << std::hex << index << " = " << value;
}

// 0x607D, the software position limit, in increments: sub 1 the minimum, sub 2 the maximum.
inline void write_position_limits(virtual_drive& d, std::int64_t min, std::int64_t max) {
  write(d, 0x607D, min, 1);
  write(d, 0x607D, max, 2);
}

inline std::uint16_t status(virtual_drive& d) { return d.view().outputs().status_word; }

// Shutdown, switch on, enable operation: the brake (30 ms) opens within the 60 cycles each gets.
inline void enable_in_mode(virtual_drive& d, std::int8_t mode) {
  write(d, 0x6060, mode);
  for (int word : {0x06, 0x07, 0x0F}) {
    write(d, 0x6040, word);
    for (int i = 0; i < 60; ++i) d.step();
  }
  ASSERT_EQ(d.view().current(), state::operation_enabled);
  ASSERT_EQ(read(d, 0x6061), mode);
}

// Homing with `method` (0x6098) started as a master starts it: the drive enabled in homing mode,
// then bit 4 (homing operation start) with Enable operation, 0x1F. A case writes the other homing
// objects (0x607C, 0x6099, ...) before.
inline void start_homing(virtual_drive& d, std::int8_t method) {
  write(d, 0x6098, method);
  enable_in_mode(d, cia402::mode::homing);
  write(d, 0x6040, 0x1F);
}

// Steps until `done` holds (at most `limit` cycles); the cycles it took, or -1.
inline int cycles_until(virtual_drive& d, const std::function<bool()>& done, int limit = 20000) {
  for (int i = 1; i <= limit; ++i) {
    d.step();
    if (done()) return i;
  }
  return -1;
}

}  // namespace mode_test
