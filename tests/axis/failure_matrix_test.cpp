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

// The bench with what the matrix's run asks of it.
struct matrix_bench : bench {
  explicit matrix_bench(bool cyclic_setpoints) : bench({}, standard_profile(), cyclic_setpoints) {}
  sim::drive_view view() { return link.drive.view(); }
  void clear_refusals() { link.refused.clear(); }
};

void inject(matrix_bench& b, failure f) {
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

// No cycle reaches the drive once the link is lost: it stops as its 0x6007 says, out of the
// session's hands and out of the test's sight.
const bus_traits fake_bus{"the bus went away", 1000, 100, false};

// One run: the command, the failure after `at_ms`, then the checks.
void run_one(kind k, failure f, int at_ms, const ramps& r) {
  SCOPED_TRACE(where(k, f, at_ms) + ", 0x6083 = " + std::to_string(r.acceleration) +
               ", 0x6084 = " + std::to_string(r.deceleration));
  // Set-points by SDO, so a refused SDO can strike mid-way.
  matrix_bench b(k == kind::csp);
  ASSERT_EQ(b.link.drive.write(object_index::profile_acceleration, 0, r.acceleration), sdo_abort::none);
  ASSERT_EQ(b.link.drive.write(object_index::profile_deceleration, 0, r.deceleration), sdo_abort::none);
  check_run(b, k, f, at_ms, fake_bus, inject);
}

TEST(failure_matrix, every_motion_command_every_failure_every_20_ms_of_its_first_half_second) {
  std::vector<int> every_20_ms;
  for (int at = 0; at <= 500; at += 20) every_20_ms.push_back(at);
  for_every_case(every_20_ms, [](kind k, failure f, int at) { run_one(k, f, at, {}); });
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
