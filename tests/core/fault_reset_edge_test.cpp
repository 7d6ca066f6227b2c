// cia402::fault_reset_edge (words.hpp): the words a master sends for "Fault reset". Checked against
// the drive itself: in FAULT with the cause gone, the words one per cycle take T15 in every built-in
// profile, whether the last word sent had bit 7 set (a level does not reset, S2) or not.
#include <gtest/gtest.h>

#include "cia402/drive.hpp"
#include "cia402/words.hpp"
#include "test_support.hpp"

namespace cia402 {
namespace {

TEST(fault_reset_edge, starts_low_only_when_the_last_word_was_high) {
  const fault_reset_words from_low = fault_reset_edge(0x0000, 0x0006);
  ASSERT_EQ(from_low.count, 2);
  EXPECT_EQ(from_low.words[0], 0x0086);
  EXPECT_EQ(from_low.words[1], 0x0006);
  const fault_reset_words from_high = fault_reset_edge(0x0080, 0x0086);
  ASSERT_EQ(from_high.count, 3);
  EXPECT_EQ(from_high.words[0], 0x0006) << "bit 7 of the given word is the edge's, not kept";
  EXPECT_EQ(from_high.words[1], 0x0086);
  EXPECT_EQ(from_high.words[2], 0x0006);
}

TEST(fault_reset_edge, takes_t15_in_every_profile_from_either_level_of_bit_7) {
  for (const profile* p : test::all_builtins()) {
    for (const std::uint16_t last : {std::uint16_t{0x0000}, std::uint16_t{0x0080}}) {
      test::bench b(*p);
      ASSERT_TRUE(test::reach(b, state::switch_on_disabled)) << p->name;
      b.in.control_word = last;  // the level of bit 7 the drive sees when the fault comes
      b.step();
      b.in.fault_code = 0x5530;
      b.in.fault_class = 2;
      b.settle();
      b.in.fault_code = 0;
      b.settle();
      ASSERT_EQ(b.a.current, state::fault) << p->name << ": a held level of bit 7 does not reset";
      b.taken.clear();
      const fault_reset_words edge = fault_reset_edge(last, 0x0000);
      for (std::uint8_t i = 0; i < edge.count; ++i) {
        b.in.control_word = edge.words[i];
        b.step();
      }
      EXPECT_EQ(b.a.current, state::switch_on_disabled) << p->name << " last " << last;
      ASSERT_EQ(b.taken.size(), 1u) << p->name;
      EXPECT_EQ(b.taken[0], 15) << p->name;
    }
  }
}

}  // namespace
}  // namespace cia402
