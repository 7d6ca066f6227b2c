// The CoE slave's cycle runs as SOES runs its application: the outputs in, the device's step on them,
// the inputs out. So the inputs a slave step leaves in SM3 already answer the outputs it took in that
// step (no cycle of lag on top of the frame's own), and our master's next LRW reads them. Outside OP
// the outputs are still not applied, while the inputs are still served in SAFE-OP. Free run here: in
// DC SYNC0 mode (our master's line) the outputs wait for the pulse, which the step before latched.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "cia402/master.hpp"
#include "cia402/profile.hpp"
#include "cia402/words.hpp"
#include "drive_bench.hpp"

namespace cia402::ethercat {
namespace {

using testing::bench;

// The state a status word shows, and the Shutdown command's word, as the core's tables say.
state shown(std::uint16_t status) {
  state s = state::start;
  EXPECT_TRUE(decode_status(standard_profile(), status, s)) << "status word " << status;
  return s;
}

std::uint16_t word_of(cia402::command c) {
  std::uint16_t word = 0;
  EXPECT_TRUE(encode_command(standard_profile(), c, 0, word));
  return word;
}

std::uint16_t status_in_sm3(bench& b) {
  const bench::answer in = b.send(command::lrd, 0x10100, std::vector<std::uint8_t>(b.slave.input_bytes(), 0));
  EXPECT_EQ(in.wkc, 1) << "the inputs are served";
  return static_cast<std::uint16_t>(in.data[0] | (in.data[1] << 8));
}

// Disable voltage until the drive shows SWITCH ON DISABLED (it starts in NOT READY TO SWITCH ON).
void settle_in_switch_on_disabled(bench& b) {
  for (int i = 0; i < 20 && shown(b.cycle(word_of(cia402::command::disable_voltage))) != state::switch_on_disabled; ++i) {
  }
  ASSERT_EQ(shown(b.cycle(word_of(cia402::command::disable_voltage))), state::switch_on_disabled);
}

TEST(coe_cycle_order, the_inputs_of_a_step_answer_the_control_word_that_step_took) {
  bench b;
  b.to_op();
  b.drain_mailbox();
  settle_in_switch_on_disabled(b);
  // Shutdown written, one step, the inputs read: READY TO SWITCH ON already (before, the inputs were
  // copied out ahead of the drive's step and still showed SWITCH ON DISABLED).
  EXPECT_EQ(shown(b.cycle(word_of(cia402::command::shutdown))), state::ready_to_switch_on);
  EXPECT_EQ(b.slave.device().drive().view().current(), state::ready_to_switch_on);
}

TEST(coe_cycle_order, in_safe_op_the_outputs_are_not_applied_and_the_inputs_are_served_after_the_step) {
  bench b;
  b.to_pre_op();
  const slave_description& d = b.slave.description();
  b.sync_manager(2, d.sync_managers[2]);
  b.sync_manager(3, d.sync_managers[3]);
  b.fmmu(0, 0x10000, d.sync_managers[2].length, d.sync_managers[2].start, 2);
  b.fmmu(1, 0x10100, d.sync_managers[3].length, d.sync_managers[3].start, 1);
  ASSERT_EQ(b.request(4), 4);
  b.drain_mailbox();
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(shown(b.cycle(word_of(cia402::command::shutdown))), state::switch_on_disabled) << "cycle " << i << ": SAFE-OP applies no outputs";
  }
  EXPECT_EQ(b.slave.device().drive().view().current(), state::switch_on_disabled);
  // A fault injected over CoE: the step that takes the request leaves the status word showing it.
  EXPECT_EQ(b.download(0x2001, 0, 0x2310, 2), 0u);
  EXPECT_NE(status_in_sm3(b) & status_bit::fault, 0) << "the inputs of that same step";
  EXPECT_EQ(b.slave.state(), al_state::safe_operational);
}

}  // namespace
}  // namespace cia402::ethercat
