// What the master reports when things go wrong: a fault, remote = 0, a timeout, an unreachable
// target, a status word that shows no state. And it never resets a fault on its own.
#include <gtest/gtest.h>

#include "cia402/master.hpp"

namespace {

using cia402::master_outcome;
using cia402::state;

const cia402::profile& standard = cia402::standard_profile();

// A master set toward `target` by its policy at `now`, with `timeout` as set_target() takes it: how
// every case starts. The policy lives beside the master, which steers by it.
class master_toward : public cia402::master {
 public:
  master_toward(state target, std::uint64_t now, std::uint64_t timeout, const cia402::profile& p = standard)
      : policy_(cia402::master_policy::make(p, cia402::make_axis(p), target)) {
    set_target(policy_, now, timeout);
  }
  const cia402::master_policy& policy() const { return policy_; }

 private:
  cia402::master_policy policy_;
};

TEST(master_outcome, fault_during_enable_is_reported_with_its_code_and_never_reset_by_the_master) {
  cia402::axis a = cia402::axis_at_rest(standard, cia402::make_axis(standard),
                                        state::switch_on_disabled, false);
  master_toward m(state::operation_enabled, 0, 100);
  std::uint16_t sw = 0x0250;
  for (int cycle = 0; cycle < 30; ++cycle) {
    const std::uint16_t cw = m.step(sw, static_cast<std::uint64_t>(cycle), 0x2310);
    if (a.current == state::fault || a.current == state::fault_reaction_active) {
      EXPECT_EQ(cw & 0x80, 0) << "cycle " << cycle << ": the master must not reset by itself";
    }
    cia402::drive_inputs in;
    in.control_word = cw;
    if (cycle == 2) in.fault_code = 0x2310;
    sw = cia402::step(standard, a, in).status_word;
  }
  EXPECT_EQ(m.outcome(), master_outcome::fault);
  EXPECT_EQ(m.error_code(), 0x2310);
  EXPECT_EQ(a.current, state::fault);
  EXPECT_EQ(m.last_control_word() & 0x8F, 0x00);  // Disable voltage, bit 7 clear

  // A new target is the user's decision to reset: it then goes through T15.
  m.set_target(m.policy(), 100, 100);
  int cycles = 0;
  for (; cycles < 10 && m.outcome() != master_outcome::reached; ++cycles) {
    cia402::drive_inputs in;
    in.control_word = m.step(sw, static_cast<std::uint64_t>(100 + cycles));
    if (m.outcome() == master_outcome::reached) break;
    sw = cia402::step(standard, a, in).status_word;
  }
  EXPECT_EQ(m.outcome(), master_outcome::reached);
  EXPECT_EQ(a.current, state::operation_enabled);
}

TEST(master_outcome, remote_bit_cleared_is_reported_and_the_control_word_is_not_changed) {
  master_toward m(state::operation_enabled, 0, 0);
  const std::uint16_t first = m.step(0x0250, 0);  // SOD, remote
  EXPECT_EQ(m.outcome(), master_outcome::in_progress);
  const std::uint16_t second = m.step(0x0031, 1);  // RTSO, remote cleared
  EXPECT_EQ(m.outcome(), master_outcome::not_remote);
  EXPECT_EQ(second, first);
  m.step(0x0231, 2);
  EXPECT_EQ(m.outcome(), master_outcome::in_progress);
}

TEST(master_outcome, a_drive_that_does_not_move_times_out_naming_the_expected_transition) {
  master_toward m(state::operation_enabled, 1000, 50);
  for (std::uint64_t t = 1000; t < 1049; t += 7) {
    m.step(0x0250, t);  // stays in SWITCH ON DISABLED
    ASSERT_EQ(m.outcome(), master_outcome::in_progress) << t;
  }
  m.step(0x0250, 1050);
  EXPECT_EQ(m.outcome(), master_outcome::timed_out);
  EXPECT_EQ(m.transition(), 2);
}

TEST(master_outcome, a_persisting_fault_cause_times_out_in_t15_and_the_edge_is_repeated) {
  cia402::axis a = cia402::axis_at_rest(standard, cia402::make_axis(standard), state::fault, false);
  master_toward m(state::switch_on_disabled, 0, 20);
  std::uint16_t sw = 0x0218;
  int edges = 0;
  std::uint16_t previous = 0;
  for (int cycle = 0; cycle < 25; ++cycle) {
    const std::uint16_t cw = m.step(sw, static_cast<std::uint64_t>(cycle));
    if ((cw & 0x80) && !(previous & 0x80)) ++edges;
    previous = cw;
    cia402::drive_inputs in;
    in.control_word = cw;
    in.fault_code = 0x4310;  // still there: every edge is used up (S2)
    sw = cia402::step(standard, a, in).status_word;
  }
  EXPECT_GE(edges, 5);
  EXPECT_EQ(a.current, state::fault);
  EXPECT_EQ(m.outcome(), master_outcome::timed_out);
  EXPECT_EQ(m.transition(), 15);
}

TEST(master_outcome, quick_stop_active_is_unreachable_without_quick_stop) {
  const cia402::profile& p = *cia402::find_builtin_profile("no-quick-stop");
  master_toward m(state::quick_stop_active, 0, 0, p);
  m.step(0x0250, 0);
  EXPECT_EQ(m.outcome(), master_outcome::unreachable);
}

TEST(master_outcome, a_word_showing_no_state_is_reported_and_the_next_good_one_resumes) {
  master_toward m(state::operation_enabled, 0, 0);
  m.step(0x0250, 0);
  const std::uint16_t before = m.last_control_word();
  EXPECT_EQ(m.step(0x0201, 1), before);  // 0x01 with bit 5 clear: no state
  EXPECT_EQ(m.outcome(), master_outcome::bad_status_word);
  m.step(0x0231, 2);
  EXPECT_EQ(m.outcome(), master_outcome::in_progress);
  EXPECT_EQ(m.last_control_word() & 0x0F, 0x0F);
}

TEST(master_outcome, halt_and_mode_bits_of_the_application_are_kept_in_every_word) {
  cia402::axis a = cia402::axis_at_rest(standard, cia402::make_axis(standard),
                                        state::switch_on_disabled, false);
  master_toward m(state::operation_enabled, 0, 0);
  m.application_bits = 0x0170;  // halt + mode bits 4..6
  std::uint16_t sw = 0x0250;
  for (int cycle = 0; cycle < 6; ++cycle) {
    const std::uint16_t cw = m.step(sw, static_cast<std::uint64_t>(cycle));
    EXPECT_EQ(cw & 0x0170, 0x0170) << cycle;
    cia402::drive_inputs in;
    in.control_word = cw;
    sw = cia402::step(standard, a, in).status_word;
  }
  EXPECT_EQ(m.outcome(), master_outcome::reached);
  EXPECT_EQ(a.current, state::operation_enabled);
}

TEST(master_outcome, the_master_step_does_not_depend_on_the_path_length) {
  // A policy is a lookup: its size is fixed, whatever the target.
  static_assert(sizeof(cia402::master) <= 48, "a master axis stays small");
  SUCCEED();
}

}  // namespace
