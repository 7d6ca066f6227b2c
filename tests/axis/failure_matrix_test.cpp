// S20 proven like the core: every motion command against every failure injected at every point of
// its way (exhaustive over a grid of moments, then seeded random over the ramps and the moments),
// on a simulated drive in virtual time. Whatever happens, the request ends within a bound, its
// error names the cause, the shaft ends at standstill wherever the link still reaches the drive,
// and a drive that did not fault takes the next command without a reset.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <string>

#include "bench.hpp"
#include "cia402/words.hpp"
#include "failure_matrix.hpp"

namespace cia402::axes::test {
namespace {

using namespace failure_matrix;

// How this bus says a lost link.
const std::string link_lost_words = "the bus went away";

// The command of kind `k` on this bench's session.
void start(bench& b, kind k, completion done) { failure_matrix::start(*b.s, k, std::move(done)); }

void inject(bench& b, failure f) {
  switch (f) {
    case failure::cancel: b.s->cancel("the client gave up"); break;
    case failure::link_lost: b.link.fail("the bus went away"); break;
    case failure::fault: b.link.drive.view().inject_fault(0x7121); break;
    case failure::sto: b.link.drive.view().set_sto(true); break;
    case failure::dc_link_lost: b.link.drive.view().set_dc_link(false); break;
    case failure::refused_sdo:
      // Every object the command writes from now on is refused, as a drive that changed its mind.
      for (const std::uint16_t index : {object_index::target_position, object_index::target_velocity,
                                        object_index::target_torque, object_index::profile_velocity,
                                        object_index::homing_method, object_index::home_offset,
                                        object_index::modes_of_operation}) {
        b.link.refused[{index, 0}] = sdo_abort::invalid_value;
      }
      break;
  }
}

struct ramps {
  std::int64_t acceleration = 1000;  // 0x6083, rpm/s
  std::int64_t deceleration = 1000;  // 0x6084
};

// One run: the command, the failure after `at_ms`, then the checks.
void run_one(kind k, failure f, int at_ms, const ramps& r) {
  const std::string where = std::string(name(k)) + ", " + name(f) + " at " + std::to_string(at_ms) + " ms, 0x6083 = " +
                            std::to_string(r.acceleration) + ", 0x6084 = " + std::to_string(r.deceleration);
  SCOPED_TRACE(where);
  // Set-points by SDO, so a refused SDO can strike mid-way.
  bench b({}, standard_profile(), k == kind::csp);
  ASSERT_EQ(b.link.drive.write(object_index::profile_acceleration, 0, r.acceleration), sdo_abort::none);
  ASSERT_EQ(b.link.drive.write(object_index::profile_deceleration, 0, r.deceleration), sdo_abort::none);
  std::optional<result> got;
  start(b, k, [&](const result& res) { got = res; });
  b.run_ms(at_ms);
  const bool ended_before = got.has_value();
  const bool enabled = b.link.drive.view().current() == state::operation_enabled;
  inject(b, f);
  // The bound: the failure stop's three stages, and the time to say it.
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 3 * 10'000 + 1000)) << "the request never ended";
  if (ended_before || got->ok()) return;  // the failure came after the end, or changed nothing the command needed
  EXPECT_TRUE(names_one(got->error, cause_words(f, link_lost_words))) << got->error;
  if (f == failure::link_lost) {
    // What the drive does then, said where the command had it enabled.
    if (enabled) EXPECT_NE(got->error.find("0x6007"), std::string::npos) << got->error;
    return;  // no cycle reaches the drive any more: it stops as its 0x6007 says, out of the session's hands
  }
  // At standstill: at once where the session stopped it; after the drive's own fault reaction (or a
  // coast under STO) where the drive took over.
  const bool stands = b.run_until([&] { return std::abs(b.link.drive.view().velocity_rpm()) <= 1; },
                                  f == failure::cancel || f == failure::refused_sdo ? 100 : 30'000);
  EXPECT_TRUE(stands) << got->error << " (" << b.link.drive.view().velocity_rpm() << " rpm)";
  const state now = b.link.drive.view().current();
  if (f == failure::cancel || f == failure::refused_sdo) {
    EXPECT_NE(now, state::fault) << got->error;
    b.link.refused.clear();
    // The next command runs without a reset.
    const result next = b.finish([&](completion d) { return b.s->velocity(100, std::move(d)); });
    EXPECT_TRUE(next.ok()) << next.error;
  }
}

TEST(failure_matrix, every_motion_command_every_failure_every_20_ms_of_its_first_half_second) {
  for (const kind k : kinds) {
    for (const failure f : failures) {
      for (int at = 0; at <= 500; at += 20) run_one(k, f, at, {});
    }
  }
}

TEST(failure_matrix, seeded_random_ramps_and_moments) {
  std::mt19937 random(42);
  std::uniform_int_distribution<int> pick_kind(0, 5), pick_failure(0, 5), moment(0, 3000), ramp(50, 20000);
  for (int i = 0; i < 150; ++i) {
    const ramps r{ramp(random), ramp(random)};
    run_one(kinds[pick_kind(random)], failures[pick_failure(random)], moment(random), r);
  }
}

}  // namespace
}  // namespace cia402::axes::test
