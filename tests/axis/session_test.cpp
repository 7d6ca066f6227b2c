// The axis session against a simulated drive behind a fake link: every operation to its end, with
// what the drive shows after it.
#include <gtest/gtest.h>

#include <cstdlib>

#include "bench.hpp"
#include "cia402/words.hpp"

namespace cia402::axes::test {
namespace {

TEST(session, start_up_reads_the_option_codes_the_modes_and_the_name) {
  bench b;
  b.link.own[{device_name_index, 0}] = {'d', 'r', 'i', 'v', 'e'};
  ASSERT_TRUE(b.run_until([&] { return b.s->prepared(); }, 100));
  EXPECT_EQ(b.s->device_name(), "drive");
  ASSERT_TRUE(b.s->supported_modes());
  EXPECT_EQ(*b.s->supported_modes(), 0x3ADu) << "the virtual drive's 0x6502";
  EXPECT_EQ(b.s->option_code(option::quick_stop), 2) << "0x605A as the drive has it";
}

TEST(session, enable_and_disable_reach_their_states_through_the_planner) {
  bench b;
  const result on = b.enable();
  ASSERT_TRUE(on.ok()) << on.error;
  EXPECT_EQ(on.shown, state::operation_enabled);
  EXPECT_EQ(b.link.drive.view().current(), state::operation_enabled);
  const result off = b.finish([&](completion d) { return b.s->go_to(state::switch_on_disabled, std::move(d)); });
  ASSERT_TRUE(off.ok()) << off.error;
  EXPECT_EQ(b.link.drive.view().current(), state::switch_on_disabled);
}

TEST(session, watching_never_commands_the_drive) {
  bench b;
  const result r = b.finish([&](completion d) { return b.s->watch(std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  b.run_ms(200);
  EXPECT_TRUE(b.link.words.empty()) << "no control word before a request needs one";
  EXPECT_FALSE(b.s->control_word());
}

TEST(session, move_switches_to_pp_and_runs_the_set_point_handshake_to_the_target) {
  bench b;
  const result r = b.finish([&](completion d) { return b.s->move({20000, false, 600u}, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_TRUE(r.position);
  EXPECT_EQ(*r.position, 20000);
  EXPECT_EQ(b.link.drive.view().position(), 20000);
  EXPECT_EQ(b.link.drive.view().operation_mode(), mode::profile_position);
  EXPECT_TRUE(b.sent(control_bit::new_set_point, control_bit::new_set_point)) << "bit 4 offered the set-point";
  EXPECT_FALSE(b.link.drive.view().control_word() & control_bit::new_set_point) << "and went down after the acknowledge";
  bool set_point = false;
  for (const auto& [k, res] : b.progress) set_point = set_point || (k == progress_kind::set_point && res.position == 20000);
  EXPECT_TRUE(set_point);
  // Relative: 5000 more.
  const result more = b.finish([&](completion d) { return b.s->move({5000, true, std::nullopt}, std::move(d)); });
  ASSERT_TRUE(more.ok()) << more.error;
  EXPECT_EQ(more.position, 25000);
}

// pv's status bit 12 (speed = 0) is still in the status word when 0x6061 already shows pp: a move
// right after must wait for a status word from after its own bit 4, or it takes that bit for the
// set-point acknowledge and reports a target it never went to.
TEST(session, a_move_right_after_a_mode_switch_waits_for_its_own_acknowledge) {
  bench b({}, standard_profile(), false);
  b.link.cycle = 10000;  // a status word every 10 ms (a SYNC), transfers answered within 1 ms
  ASSERT_TRUE(b.enable().ok());
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->set_mode(mode::profile_position, std::move(d)); }).ok());
  const result r = b.finish([&](completion d) { return b.s->move({20000, false, std::nullopt}, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.position, 20000);
  EXPECT_EQ(b.link.drive.view().position(), 20000);
}

TEST(session, a_mode_written_into_the_cyclic_outputs_needs_no_transfer) {
  bench b;
  const result r = b.finish([&](completion d) { return b.s->set_mode(mode::cyclic_synchronous_velocity, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(b.link.drive.view().operation_mode(), mode::cyclic_synchronous_velocity);
  for (const auto& d : b.link.downloads) EXPECT_NE(d.index, object_index::modes_of_operation) << "0x6060 went by SDO";
  bench sdo({}, standard_profile(), false);
  ASSERT_TRUE(sdo.finish([&](completion d) { return sdo.s->set_mode(mode::homing, std::move(d)); }).ok());
  ASSERT_FALSE(sdo.link.downloads.empty());
  EXPECT_EQ(sdo.link.downloads.back().index, object_index::modes_of_operation) << "not cyclic: by a transfer";
}

TEST(session, velocity_switches_to_pv_and_ends_within_one_percent) {
  bench b;
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->set_mode(mode::profile_position, std::move(d)); }).ok());
  const result r = b.finish([&](completion d) { return b.s->velocity(1500, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_TRUE(r.velocity);
  EXPECT_LE(std::abs(*r.velocity - 1500), 15);
  EXPECT_EQ(b.link.drive.view().operation_mode(), mode::profile_velocity);
}

TEST(session, torque_switches_to_tq_and_ends_at_the_target_torque) {
  bench b;
  const result r = b.finish([&](completion d) { return b.s->torque(200, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_TRUE(r.torque);
  EXPECT_LE(std::abs(*r.torque - 200), 2);
  EXPECT_EQ(b.link.drive.view().operation_mode(), mode::profile_torque);
}

TEST(session, home_sets_the_position_to_the_home_offset) {
  bench b;
  const result r = b.finish([&](completion d) { return b.s->home({std::int8_t{37}, 1234}, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.position, 1234);
  EXPECT_EQ(b.link.drive.view().position(), 1234);
}

TEST(session, a_homing_method_0x60E3_does_not_list_is_refused_before_anything_is_sent) {
  bench b;
  // Method 15 is reserved (CiA 402-2): 0x60E3 does not list it.
  const result r = b.finish([&](completion d) { return b.s->home({std::int8_t{15}, std::nullopt}, std::move(d)); });
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.bad_input);
  EXPECT_NE(r.error.find("homing method 15 is not among 0x60E3"), std::string::npos) << r.error;
  EXPECT_TRUE(b.link.words.empty()) << "no control word went out";
  EXPECT_TRUE(b.link.downloads.empty()) << "no object was written";
}

TEST(session, a_homing_method_the_drive_refuses_names_0x6098_and_its_abort) {
  bench b;
  b.link.refused[{object_index::homing_method, 0}] = sdo_abort::invalid_value;
  const result r = b.finish([&](completion d) { return b.s->home({std::int8_t{35}, std::nullopt}, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {"0x6098", "SDO abort 0x06090030"}));
}

TEST(session, csp_stream_ramps_0x607A_and_the_drive_follows_exactly) {
  bench b;
  const result r = b.finish([&](completion d) { return b.s->csp_stream(20000, 600, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.position, 20000);
  // 600 rpm x 10,000 increments a revolution = 100 increments a 1 ms cycle.
  EXPECT_EQ(r.set_points, 200u);
  EXPECT_EQ(r.max_following_error, 0);
  bool started = false;
  for (const auto& [k, res] : b.progress) started = started || (k == progress_kind::stream_started && res.stream_to == 20000);
  EXPECT_TRUE(started);
}

TEST(session, csv_stream_takes_its_set_points_from_the_source) {
  bench b;
  int k = 0;
  const result r = b.finish([&](completion d) {
    return b.s->stream(mode::cyclic_synchronous_velocity, [&k]() -> std::optional<std::int64_t> {
      if (k >= 100) return std::nullopt;
      return ++k * 3;  // to 300 rpm in 100 cycles
    }, std::move(d));
  });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.set_points, 100u);
  ASSERT_TRUE(r.velocity);
  EXPECT_LE(std::abs(*r.velocity - 300), 3);
}

TEST(session, a_stream_whose_set_point_is_not_cyclic_is_refused_with_where_it_is_missing) {
  bench b({}, standard_profile(), false);
  const result r = b.finish([&](completion d) { return b.s->csp_stream(1000, 60, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {"streaming needs 0x607A:0 in the cyclic outputs"}));
}

TEST(session, jog_turns_while_held_and_stops_when_released) {
  bench b;
  std::optional<result> got;
  b.s->jog(300, 400'000, [&](const result& r) { got = r; });
  ASSERT_TRUE(b.run_until([&] { return std::abs(b.link.drive.view().velocity_rpm() - 300) <= 3; }, 3000));
  b.s->renew_jog(500'000);  // still held
  b.run_ms(450);
  EXPECT_FALSE(got) << "renewed: still jogging";
  EXPECT_LE(std::abs(b.link.drive.view().velocity_rpm() - 300), 3);
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 5000));
  EXPECT_TRUE(got->ok()) << got->error;
  EXPECT_LE(std::abs(b.link.drive.view().velocity_rpm()), 1) << "standstill: within the plant's 1 rpm";
}

TEST(session, quick_stop_ends_as_0x605A_says) {
  for (const int code : {2, 6}) {
    bench b;
    ASSERT_EQ(b.link.drive.write(option_index(option::quick_stop), 0, code), sdo_abort::none);
    ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(1000, std::move(d)); }).ok());
    const result r = b.finish([&](completion d) { return b.s->quick_stop(std::move(d)); });
    ASSERT_TRUE(r.ok()) << code << ": " << r.error;
    EXPECT_EQ(b.link.drive.view().velocity_rpm(), 0) << code;
    EXPECT_EQ(b.link.drive.view().current(), code == 2 ? state::switch_on_disabled : state::quick_stop_active) << code;
  }
}

TEST(session, reset_clears_a_fault_with_an_edge_and_leaves_a_healthy_drive_alone) {
  bench b;
  const result nothing = b.finish([&](completion d) { return b.s->reset(std::move(d)); });
  ASSERT_TRUE(nothing.ok()) << nothing.error;
  EXPECT_EQ(nothing.note, "not in FAULT, nothing to reset");
  EXPECT_TRUE(b.link.words.empty()) << "looked, sent nothing";

  ASSERT_TRUE(b.enable().ok());
  ASSERT_TRUE(b.fault(0x2310));
  b.link.drive.view().clear_faults();
  const result r = b.finish([&](completion d) { return b.s->reset(std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.shown, state::switch_on_disabled);
  EXPECT_TRUE(b.sent(control_bit::fault_reset, control_bit::fault_reset)) << "bit 7 rose";
}

// A master polled far more often than the drive steps (its own cycle much shorter than the
// drive's): each word of the edge waits for the drive's answer, so the drive sees bit 7 rise.
TEST(session, a_fault_reset_edge_reaches_a_drive_that_steps_slower_than_the_pulse) {
  session_config c;
  c.reset_pulse_us = 1000;
  bench b(c);
  b.link.cycle = 40'000;
  ASSERT_TRUE(b.enable().ok());
  ASSERT_TRUE(b.fault(0x2310, 2000));
  b.link.drive.view().clear_faults();
  const result r = b.finish([&](completion d) { return b.s->reset(std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.shown, state::switch_on_disabled);
}

TEST(session, a_fault_reset_edge_to_a_drive_that_stopped_answering_ends_and_says_so) {
  bench b;
  ASSERT_TRUE(b.enable().ok());
  ASSERT_TRUE(b.fault(0x2310));
  b.link.drive.view().clear_faults();
  b.link.cycle = 100'000'000;  // no status word for 100 s
  const result r = b.finish([&](completion d) { return b.s->reset(std::move(d)); }, 5000);
  EXPECT_TRUE(failed_naming(r, {"the drive did not answer the control words sent"}));
}

TEST(session, a_reset_whose_cause_persists_says_so) {
  bench b;
  ASSERT_TRUE(b.enable().ok());
  ASSERT_TRUE(b.fault(0x2310));
  const result r = b.finish([&](completion d) { return b.s->reset(std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {
      "still in FAULT after the fault-reset edge: error code 0x2310 (continuous over-current)"
  }));
}

TEST(session, stop_halts_and_keeps_the_drive_enabled_until_the_next_motion_command) {
  bench b;
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(1000, std::move(d)); }).ok());
  const result r = b.finish([&](completion d) { return b.s->stop(std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_LE(std::abs(b.link.drive.view().velocity_rpm()), 1);
  EXPECT_EQ(b.link.drive.view().current(), state::operation_enabled);
  EXPECT_TRUE(b.link.drive.view().control_word() & control_bit::halt);
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(500, std::move(d)); }).ok());
  EXPECT_FALSE(b.link.drive.view().control_word() & control_bit::halt) << "the next motion command clears it";
}

TEST(session, a_new_motion_command_supersedes_the_running_one) {
  bench b;
  std::optional<result> first;
  b.s->move({2'000'000, false, 100u}, [&](const result& r) { first = r; });
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().velocity_rpm() > 50; }, 5000));
  const result second = b.finish([&](completion d) { return b.s->velocity(200, std::move(d)); });
  ASSERT_TRUE(first);
  EXPECT_EQ(first->end, outcome::superseded);
  EXPECT_NE(first->error.find("superseded by velocity"), std::string::npos) << first->error;
  EXPECT_TRUE(second.ok()) << second.error;
}

TEST(session, a_lost_link_ends_the_operation_with_its_reason) {
  bench b;
  std::optional<result> got;
  b.s->move({2'000'000, false, 100u}, [&](const result& r) { got = r; });
  b.run_ms(100);
  b.link.fail("the bus went away");
  b.run_ms(2);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->end, outcome::failed);
  EXPECT_NE(got->error.find("the bus went away"), std::string::npos) << got->error;
}

}  // namespace
}  // namespace cia402::axes::test
