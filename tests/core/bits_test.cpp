// The core's bit counting, with the builtins and without them (the path of a toolchain without
// builtins), agrees with the standard library on every pattern of one or two set bits and on a
// sample of the rest.
#include "../../src/core/bits.hpp"

#include <gtest/gtest.h>

#include <bitset>
#include <random>

namespace {

void expect_both(std::uint32_t v) {
  const std::bitset<32> b(v);
  EXPECT_EQ(cia402::detail::portable_set_bits(v), static_cast<int>(b.count())) << std::hex << v;
  EXPECT_EQ(cia402::detail::set_bits(v), static_cast<int>(b.count())) << std::hex << v;
  if (v == 0) return;
  int lowest = 0;
  while (!b.test(static_cast<std::size_t>(lowest))) ++lowest;
  EXPECT_EQ(cia402::detail::portable_lowest_bit(v), lowest) << std::hex << v;
  EXPECT_EQ(cia402::detail::lowest_bit(v), lowest) << std::hex << v;
}

TEST(portable_bits, agree_with_bitset) {
  expect_both(0);
  for (int i = 0; i < 32; ++i) {
    for (int j = i; j < 32; ++j) expect_both((1u << i) | (1u << j));
  }
  std::mt19937 rng(402);
  for (int k = 0; k < 10000; ++k) expect_both(static_cast<std::uint32_t>(rng()));
  expect_both(0xFFFFFFFFu);
}

}  // namespace
