// One datagram in a frame of its own through the in-process wire, as a master sends it, and what came
// back: its data, working counter and ADP. Shared by the ESC tests (esc_bus.hpp) and the drive
// slave's bench (drive_bench.hpp).
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/esc/frame.hpp"

namespace cia402::ethercat::testing {

inline constexpr std::array<std::uint8_t, 6> broadcast{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
inline constexpr std::array<std::uint8_t, 6> master_mac{0x02, 0, 0, 0, 0, 1};

struct datagram_answer {
  std::vector<std::uint8_t> data;
  std::uint16_t wkc = 0;
  std::uint16_t adp = 0;
};

inline datagram_answer one_datagram(chain& wire, command c, std::uint8_t index, std::uint32_t address,
                                    const std::vector<std::uint8_t>& data) {
  frame_builder b(broadcast, master_mac);
  const long at = b.add(c, index, address, data, static_cast<std::uint16_t>(data.size()));
  std::vector<std::uint8_t> f = b.finish();
  EXPECT_EQ(wire.pass(f), frame_error::none);
  const auto* p = f.data() + at;
  datagram_answer a;
  a.data.assign(p, p + data.size());
  a.wkc = static_cast<std::uint16_t>(p[data.size()] | (p[data.size() + 1] << 8));
  a.adp = static_cast<std::uint16_t>(f[static_cast<std::size_t>(at) - 8] | (f[static_cast<std::size_t>(at) - 7] << 8));
  return a;
}

}  // namespace cia402::ethercat::testing
