// The stop a master commands when its client goes silent (cia402/lost_client.hpp): 0x6007 as the
// standard gives it (cia402-reference.md §3: 0 no action, 1 fault signal, 2 Disable voltage, 3 Quick
// stop), as far as a master can command it.
#include <gtest/gtest.h>

#include "cia402/lost_client.hpp"

namespace {

TEST(lost_client, the_stop_per_0x6007_is_the_standards_where_a_master_can_command_it) {
  using cia402::lost_client_stop;
  using cia402::stop_for_lost_client;
  // Exhaustive over the standard's codes and a manufacturer-specific one, with and without a halt.
  for (const bool halt : {false, true}) {
    EXPECT_EQ(stop_for_lost_client(0, halt), halt ? lost_client_stop::halt : lost_client_stop::quick_stop);
    EXPECT_EQ(stop_for_lost_client(1, halt), lost_client_stop::quick_stop);
    EXPECT_EQ(stop_for_lost_client(2, halt), lost_client_stop::disable_voltage);
    EXPECT_EQ(stop_for_lost_client(3, halt), lost_client_stop::quick_stop);
    EXPECT_EQ(stop_for_lost_client(-1, halt), lost_client_stop::quick_stop);
  }
}

}  // namespace
