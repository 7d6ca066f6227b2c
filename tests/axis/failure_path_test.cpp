// S20, the master side of the failure path: a target beyond the drive's limits is refused before
// anything moves, naming the object; a motion command that fails once it commanded the drive stops
// what it set moving (halt, then quick stop, then Disable voltage) and says what it did; a lapsed
// lease stops the way up too, a stop is never refused, and every wait for a stop ends.
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <random>

#include "bench.hpp"
#include "cia402/words.hpp"

namespace cia402::axes::test {
namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// --- limits before motion -----------------------------------------------------------------------

// The request is refused as bad input before anything moves: its error names `why` and no control
// word went out. The result.
result expect_refused_before_motion(bench& b, const std::function<std::uint64_t(completion)>& request,
                                    const std::string& why) {
  const result r = b.finish(request);
  EXPECT_TRUE(r.bad_input);
  EXPECT_TRUE(has(r.error, why)) << r.error;
  EXPECT_TRUE(b.link.words.empty()) << "no control word went out";
  return r;
}

TEST(limits, a_velocity_beyond_0x607F_is_refused_naming_it_and_nothing_moves) {
  bench b;
  const result r =
      expect_refused_before_motion(b, [&](completion d) { return b.s->velocity(99999, std::move(d)); },
                                   "velocity 99999 rpm is beyond 0x607F (max profile velocity) = 6000 rpm");
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(b.link.drive.view().current(), state::switch_on_disabled);
}

TEST(limits, a_velocity_within_0x607F_but_beyond_0x6080_names_0x6080) {
  bench b;
  ASSERT_EQ(b.link.drive.write(object_index::max_motor_speed, 0, 2000), sdo_abort::none);
  expect_refused_before_motion(b, [&](completion d) { return b.s->velocity(-3000, std::move(d)); },
                               "velocity -3000 rpm is beyond 0x6080 (max motor speed) = 2000 rpm");
}

TEST(limits, a_torque_beyond_0x6072_is_refused) {
  bench b;
  expect_refused_before_motion(b, [&](completion d) { return b.s->torque(5000, std::move(d)); },
                               "torque 5000 permille is beyond 0x6072 (max torque) = 3000 permille");
}

TEST(limits, a_move_beyond_0x607D_is_refused_absolute_and_relative) {
  bench b;
  ASSERT_EQ(b.link.drive.write(object_index::software_position_limit, 1, -1000), sdo_abort::none);
  ASSERT_EQ(b.link.drive.write(object_index::software_position_limit, 2, 10000), sdo_abort::none);
  expect_refused_before_motion(
      b, [&](completion d) { return b.s->move({20000, false, std::nullopt}, std::move(d)); },
      "target position 20000 is beyond 0x607D:02 (max position limit) = 10000");
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->move({8000, false, std::nullopt}, std::move(d)); }).ok());
  const result more = b.finish([&](completion d) { return b.s->move({3000, true, std::nullopt}, std::move(d)); });
  EXPECT_TRUE(more.bad_input);
  EXPECT_TRUE(has(more.error, "target position 11000 (3000 from here) is beyond 0x607D:02")) << more.error;
  const result back = b.finish([&](completion d) { return b.s->move({-9500, true, std::nullopt}, std::move(d)); });
  EXPECT_TRUE(has(back.error, "0x607D:01 (min position limit) = -1000")) << back.error;
  EXPECT_EQ(b.link.drive.view().position(), 8000) << "a refused move moves nothing";
}

TEST(limits, a_profile_velocity_beyond_0x607F_refuses_the_move) {
  bench b;
  const result r = b.finish([&](completion d) { return b.s->move({1000, false, 7000u}, std::move(d)); });
  EXPECT_TRUE(r.bad_input);
  EXPECT_TRUE(has(r.error, "profile velocity 7000 rpm is beyond 0x607F")) << r.error;
}

TEST(limits, a_mode_0x6502_does_not_announce_is_refused_before_the_limits_are_read) {
  bench b;
  b.link.own[{object_index::supported_drive_modes, 0}] = {0x01, 0x00, 0x00, 0x00};  // pp only
  expect_refused_before_motion(b, [&](completion d) { return b.s->velocity(100, std::move(d)); },
                               "pv (3) is not among the modes 0x6502");
}

TEST(limits, a_drive_without_the_limit_objects_is_not_judged) {
  bench b;
  b.link.refused[{object_index::max_profile_velocity, 0}] = sdo_abort::object_does_not_exist;
  b.link.refused[{object_index::max_motor_speed, 0}] = sdo_abort::object_does_not_exist;
  const result r = b.finish([&](completion d) { return b.s->velocity(500, std::move(d)); });
  EXPECT_TRUE(r.ok()) << r.error;
}

TEST(limits, a_drive_that_cuts_the_set_point_while_running_is_said_to_with_bit_11) {
  bench b;
  // pv towards the end of 0x607D: the drive brakes for the limit and shows status bit 11.
  ASSERT_EQ(b.link.drive.write(object_index::software_position_limit, 2, 30000), sdo_abort::none);
  std::optional<result> got;
  b.s->velocity(1000, [&](const result& r) { got = r; });
  ASSERT_TRUE(b.run_until([&] { return (b.link.status_word() & status_bit::internal_limit_active) != 0; }, 10000));
  b.run_ms(50);
  b.s->cancel("given up");
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 20000));
  EXPECT_TRUE(has(got->error, "the drive limited the set-point: status bit 11 (internal limit active) was set")) << got->error;
}

// --- a failed step stops what it started ----------------------------------------------------------

TEST(failure_path, a_velocity_cut_short_by_its_client_is_halted_to_standstill_and_says_so) {
  bench b;
  ASSERT_EQ(b.link.drive.write(object_index::profile_acceleration, 0, 100), sdo_abort::none);
  std::optional<result> got;
  b.s->velocity(3000, [&](const result& r) { got = r; });
  b.run_ms(300);
  ASSERT_FALSE(got);
  ASSERT_GT(std::abs(b.link.drive.view().velocity_rpm()), 5) << "turning when the client gives up";
  b.s->cancel("did not finish within 300 ms");
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 20000));
  EXPECT_EQ(got->end, outcome::failed);
  EXPECT_TRUE(has(got->error, "did not finish within 300 ms; stopped by halt (control bit 8, as 0x605D = 1): at standstill"))
      << got->error;
  EXPECT_LE(std::abs(b.link.drive.view().velocity_rpm()), 1);
  EXPECT_EQ(b.link.drive.view().current(), state::operation_enabled) << "halted, not disabled";
  // The next command runs without a reset.
  EXPECT_TRUE(b.finish([&](completion d) { return b.s->velocity(200, std::move(d)); }).ok());
}

TEST(failure_path, a_set_point_acknowledge_that_never_comes_stops_the_move) {
  session_config c;
  c.acknowledge_timeout_us = 200'000;
  bench b(c);
  b.link.hidden_status_bits = status_bit::set_point_acknowledge;
  const result r = b.finish([&](completion d) { return b.s->move({2'000'000, false, 1000u}, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {
      "no set-point acknowledge (status bit 12) within 200 ms",
      "stopped by halt"
  }));
  EXPECT_LE(std::abs(b.link.drive.view().velocity_rpm()), 1);
}

TEST(failure_path, a_halt_that_does_not_stop_the_shaft_escalates_to_quick_stop) {
  session_config c;
  c.stop_timeout_us = 50'000;
  bench b(c);
  ASSERT_EQ(b.link.drive.write(object_index::profile_deceleration, 0, 1), sdo_abort::none);  // 1 rpm/s: halt takes hours
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(1000, std::move(d)); }).ok());
  std::optional<result> got;
  b.s->velocity(2000, [&](const result& r) { got = r; });
  b.run_ms(20);
  b.s->cancel("given up");
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 20000));
  EXPECT_TRUE(has(got->error, "given up; halt (control bit 8, as 0x605D = 1) did not stop the shaft within 50 ms; then quick stop"))
      << got->error;
  b.run_ms(3000);
  EXPECT_LE(std::abs(b.link.drive.view().velocity_rpm()), 1);
}

TEST(failure_path, a_refused_set_point_stops_what_the_command_already_moved) {
  bench b({}, standard_profile(), false);  // set-points by SDO
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(1000, std::move(d)); }).ok());
  b.link.refused[{object_index::target_position, 0}] = sdo_abort::invalid_value;
  const result r = b.finish([&](completion d) { return b.s->move({50000, false, std::nullopt}, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {"0x607A", "stopped by"}));
  EXPECT_LE(std::abs(b.link.drive.view().velocity_rpm()), 1);
}

// --- what a disable holds -------------------------------------------------------------------------

TEST(failure_path, once_asked_to_disable_the_session_never_sends_enable_operation_again) {
  bench b;
  ASSERT_TRUE(b.enable().ok());
  const result off = b.finish([&](completion d) { return b.s->go_to(state::switch_on_disabled, std::move(d)); });
  ASSERT_TRUE(off.ok()) << off.error;
  const std::size_t from = b.link.words.size();
  b.run_ms(200);
  ASSERT_TRUE(b.s->control_word());
  EXPECT_EQ(*b.s->control_word() & 0x008F, 0x0000) << "Disable voltage is held, not the 0x000F a path from START ends on";
  for (std::size_t i = from; i < b.link.words.size(); ++i) EXPECT_NE(b.link.words[i].second & 0x000F, 0x000F) << i;
  // A quick stop held with 0x605A = 6: a disable from there goes to SWITCH ON DISABLED, never back up (T16).
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->write_object(0x605A, 0, object_value::of_integer(6), std::move(d)); }).ok());
  EXPECT_EQ(b.s->option_code(option::quick_stop), 6);
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(500, std::move(d)); }).ok());
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->go_to(state::quick_stop_active, std::move(d)); }).ok());
  const result down = b.finish([&](completion d) { return b.s->go_to(state::switch_on_disabled, std::move(d)); });
  ASSERT_TRUE(down.ok()) << down.error;
  b.run_ms(200);
  EXPECT_EQ(b.link.drive.view().current(), state::switch_on_disabled);
}

// --- the lease and the stops ------------------------------------------------------------------------

TEST(failure_path, a_lease_that_lapses_on_the_way_up_stops_the_enable_and_a_quick_stop_is_not_refused) {
  session_config c;
  c.lease_us = 3'000;
  bench b(c);
  b.s->renew("client");
  std::optional<result> up;
  b.s->go_to(state::operation_enabled, [&](const result& r) { up = r; });
  b.run_ms(20);
  ASSERT_TRUE(b.s->lease_lapsed());
  const result qs = b.finish([&](completion d) { return b.s->quick_stop(std::move(d)); });
  EXPECT_TRUE(qs.ok()) << qs.error;
  b.run_ms(200);
  ASSERT_TRUE(up);
  EXPECT_NE(up->end, outcome::done);
  EXPECT_NE(b.link.drive.view().current(), state::operation_enabled) << "a lapse leaves no drive enabled";
}

TEST(failure_path, a_quick_stop_the_session_misjudged_ends_at_standstill_and_close_ends) {
  bench b;
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(1000, std::move(d)); }).ok());
  // The drive takes 0x605A = 6 but the answer is lost: the session reads the code back.
  b.link.refused[{option_index(option::quick_stop), 0}] = sdo_abort::general_error;
  ASSERT_EQ(b.link.drive.write(option_index(option::quick_stop), 0, 6), sdo_abort::none);
  const result w = b.finish([&](completion d) { return b.s->write_object(0x605A, 0, object_value::of_integer(6), std::move(d)); });
  EXPECT_FALSE(w.ok());
  b.link.refused.clear();
  const result again = b.finish([&](completion d) { return b.s->read_object(0x605A, 0, std::move(d)); });
  ASSERT_TRUE(again.ok());
  b.s->close(true);
  ASSERT_TRUE(b.run_until([&] { return b.s->closed(); }, 20000)) << "the close ends";
  EXPECT_LE(std::abs(b.link.drive.view().velocity_rpm()), 1);
}

TEST(failure_path, every_wait_for_a_stop_ends_with_a_reason) {
  session_config c;
  c.stop_timeout_us = 100'000;
  bench b(c);
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->velocity(1000, std::move(d)); }).ok());
  b.link.hidden_status_bits = status_bit::target_reached;  // standstill never shown
  ASSERT_EQ(b.link.drive.write(object_index::profile_deceleration, 0, 1), sdo_abort::none);
  const result r = b.finish([&](completion d) { return b.s->stop(std::move(d)); }, 5000);
  EXPECT_TRUE(failed_naming(r, {"did not show standstill within 100 ms"}));
}

}  // namespace
}  // namespace cia402::axes::test
