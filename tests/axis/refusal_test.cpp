// A request that cannot work says why at once (or as soon as the drive has answered), with the
// words a user needs: the mode 0x6502 lacks, the fault and its text, no DC link, remote off, halt
// set by hand, the drive's SDO abort. None of them commands the drive.
#include <gtest/gtest.h>

#include "bench.hpp"
#include "cia402/words.hpp"

namespace cia402::axes::test {
namespace {

TEST(refusal, a_mode_0x6502_does_not_announce_is_refused_before_0x6060_is_written) {
  bench b({}, standard_profile(), false);
  const result r = b.finish([&](completion d) { return b.s->set_mode(2, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {
      "mode 2 is not among the modes 0x6502 announces (pp (1), pv (3), tq (4), hm (6), csp (8), csv (9), cst (10))"
  }));
  for (const auto& d : b.link.downloads) EXPECT_NE(d.index, object_index::modes_of_operation);
}

TEST(refusal, a_mode_the_drive_refuses_names_its_abort_when_0x6502_is_not_known) {
  bench b({}, standard_profile(), false);
  b.link.refused[{object_index::supported_drive_modes, 0}] = sdo_abort::object_does_not_exist;
  const result r = b.finish([&](completion d) { return b.s->set_mode(2, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {
      "the drive refused 0x6060:0 = 2: SDO abort 0x06090030 (invalid value for parameter)"
  }));
}

TEST(refusal, a_mode_0x6061_never_shows_is_named_with_what_it_shows) {
  session_config c;
  c.mode_timeout_us = 200'000;
  bench b(c, standard_profile(), false);
  // The write is taken, but the drive stays where it was: 0x6061 keeps showing pv.
  b.link.own[{object_index::modes_of_operation, 0}] = {3};
  const result r = b.finish([&](completion d) { return b.s->set_mode(mode::profile_position, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {"0x6061 still shows pv (3) 200 ms after 0x6060 = pp (1)"}));
}

TEST(refusal, a_drive_in_fault_is_named_with_its_error_code_and_text) {
  bench b;
  ASSERT_TRUE(b.enable().ok());
  ASSERT_TRUE(b.fault(0x2310));
  const std::size_t words = b.link.words.size();
  for (const auto& request : std::vector<std::function<std::uint64_t(completion)>>{
           [&](completion d) { return b.s->move({100, false, std::nullopt}, std::move(d)); },
           [&](completion d) { return b.s->go_to(state::operation_enabled, std::move(d)); },
           [&](completion d) { return b.s->quick_stop(std::move(d)); }}) {
    const result r = b.finish(request);
    EXPECT_TRUE(failed_naming(r, {
        "the drive is in FAULT: error code 0x2310 (continuous over-current); reset it first"
    }));
  }
  // The master step sends Disable voltage after a fault; the refusals add nothing to it.
  for (std::size_t i = words; i < b.link.words.size(); ++i) EXPECT_EQ(b.link.words[i].second & 0x008F, 0) << i;
}

TEST(refusal, a_fault_during_a_move_ends_it_with_the_code) {
  bench b;
  std::optional<result> got;
  b.s->move({2'000'000, false, 100u}, [&](const result& r) { got = r; });
  ASSERT_TRUE(b.run_until([&] { return b.link.drive.view().velocity_rpm() > 50; }, 5000));
  b.link.drive.view().inject_fault(0x7121);
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 1000));
  EXPECT_NE(got->error.find("error code 0x7121"), std::string::npos) << got->error;
}

TEST(refusal, no_dc_link_is_said_at_once) {
  bench b;
  b.link.drive.view().set_dc_link(false);
  b.run_ms(5);
  const result r = b.finish([&](completion d) { return b.s->velocity(100, std::move(d)); }, 100);
  EXPECT_TRUE(failed_naming(r, {"no DC link: status bit 4 (voltage enabled) is 0"}));
  EXPECT_TRUE(b.link.words.empty());
}

TEST(refusal, remote_off_is_said_at_once) {
  bench b;
  b.link.hidden_status_bits = status_bit::remote;
  const result r = b.finish([&](completion d) { return b.s->go_to(state::operation_enabled, std::move(d)); }, 100);
  EXPECT_TRUE(failed_naming(r, {"remote is off (status bit 9 is 0"}));
  EXPECT_TRUE(b.link.words.empty());
}

TEST(refusal, a_motion_command_under_a_halt_set_by_hand_says_so) {
  bench b;
  ASSERT_TRUE(b.enable().ok());
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->halt(true, std::move(d)); }).ok());
  EXPECT_TRUE(b.link.drive.view().control_word() & control_bit::halt);
  const result r = b.finish([&](completion d) { return b.s->velocity(100, std::move(d)); });
  EXPECT_NE(r.error.find("halt is on (control bit 8): halt off first"), std::string::npos) << r.error;
  ASSERT_TRUE(b.finish([&](completion d) { return b.s->halt(false, std::move(d)); }).ok());
  EXPECT_TRUE(b.finish([&](completion d) { return b.s->velocity(100, std::move(d)); }).ok());
}

TEST(refusal, halt_on_a_profile_without_one_is_bad_input) {
  bench b({}, find_builtin_profile("s300-profibus") != nullptr ? *find_builtin_profile("s300-profibus") : standard_profile());
  const result r = b.finish([&](completion d) { return b.s->halt(true, std::move(d)); });
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.bad_input);
  EXPECT_NE(r.error.find("has no halt (0x605D)"), std::string::npos) << r.error;
}

TEST(refusal, a_transition_that_does_not_happen_names_it_and_the_state) {
  session_config c;
  c.transition_timeout_us = 300'000;
  bench b(c);
  b.link.drive.view().set_sto(true);
  const result r = b.finish([&](completion d) { return b.s->go_to(state::operation_enabled, std::move(d)); });
  EXPECT_TRUE(failed_naming(r, {
      "did not happen within 300 ms (the drive shows",
      "status bit 7 (warning) is set: safe torque off or another warning"
  }));
}

}  // namespace
}  // namespace cia402::axes::test
