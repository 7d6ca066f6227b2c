#include <gtest/gtest.h>
#include "cia402/drive.hpp"
// Every test file of this executable includes it, so gtest's printer for `state` is one definition.
#include "test_support.hpp"
using namespace cia402;
TEST(smoke, power_up_enable) {
  drive d(standard_profile());
  drive_inputs in;
  auto o = d.step(in); EXPECT_EQ(o.transition, 0);
  o = d.step(in); EXPECT_EQ(o.transition, 1); EXPECT_EQ(o.current, state::switch_on_disabled);
  in.control_word = 0x06; o = d.step(in); EXPECT_EQ(o.transition, 2);
  in.control_word = 0x0F; o = d.step(in); EXPECT_EQ(o.transition, 3);
  o = d.step(in); EXPECT_EQ(o.transition, 4); EXPECT_EQ(o.status_word, 0x0237); EXPECT_TRUE(o.torque);
}
