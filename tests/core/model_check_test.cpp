// The exhaustive model check (model_check.hpp) of every built-in profile, under every option-code
// set that changes behaviour: the reachable states and checked pairs are printed, and docs/semantics.md
// records them.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <thread>

#include "model_check.hpp"

namespace cia402 {
namespace {

void check_profile(const char* name) {
  const profile* p = find_builtin_profile(name);
  ASSERT_NE(p, nullptr);
  std::size_t states = 0;
  std::size_t pairs = 0;
  int deepest = 0;
  const auto sets = model_check::option_sets(*p);
  const compiled_profile compiled(*p);
  // The option sets are independent searches: two threads, as the machines have two cores.
  std::vector<model_check::report> reports(sets.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t k; (k = next++) < sets.size();) {
      reports[k] = model_check::check(*p, sets[k], &compiled);
    }
  };
  std::thread helper(worker);
  worker();
  helper.join();
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const auto& options = sets[k];
    const model_check::report& r = reports[k];
    states += r.states;
    pairs += r.pairs;
    deepest = std::max(deepest, r.deepest_settle);
    std::string first;
    for (const std::string& v : r.first_violations) first += "\n  " + v;
    EXPECT_EQ(r.violations, 0u) << name << " options " << int(options[0]) << "," << int(options[1])
                                << "," << int(options[2]) << "," << int(options[3]) << ","
                                << int(options[4]) << "," << int(options[5]) << ":" << first;
  }
  std::printf("model check %s: %zu option sets, %zu reachable states, %zu (state, input) pairs, "
              "%zu inputs, rest within %d steps; compiled table answers %zu of %zu entries, its "
              "stop table %zu\n",
              name, sets.size(), states, pairs, model_check::alphabet(*p).size(), deepest,
              compiled.covered(), std::size_t{state_count} * 64u, compiled.stops_covered());
  EXPECT_LE(deepest, model_check::settle_bound);
  // Every built-in profile has stops with torque on (T5/T8 ramps, a quick stop or a fault
  // reaction), so a stop table with no entry standing would mean its derivation broke.
  EXPECT_GT(compiled.stops_covered(), 0u) << name;
  // And every key with a stop to answer found room: none is left to the full step for lack of it.
  EXPECT_TRUE(compiled.stops_complete()) << name;
}

TEST(model_check, cia402) { check_profile("cia402"); }
TEST(model_check, no_quick_stop) { check_profile("no-quick-stop"); }
TEST(model_check, lexium32) { check_profile("lexium32"); }
TEST(model_check, s300_profibus) { check_profile("s300-profibus"); }
TEST(model_check, ax2000_profibus) { check_profile("ax2000-profibus"); }

}  // namespace
}  // namespace cia402

namespace cia402 {
namespace {

// The check must be able to fail: broken variants of the standard profile, each one defect.
std::size_t violations_of(const custom_profile& p, const char* what) {
  std::array<std::int8_t, option_count> defaults{};
  for (int o = 0; o < option_count; ++o) defaults[o] = p.get().options[o].default_value;
  const compiled_profile compiled(p.get());
  const model_check::report r = model_check::check(p.get(), defaults, &compiled);
  std::size_t matching = 0;
  for (const auto& [kind, count] : r.kinds) {
    if (kind.find(what) != std::string::npos) matching += count;
  }
  return matching;
}

custom_profile standard_with(void (*edit)(transition_row*, std::size_t&)) {
  custom_profile c(standard_profile());
  std::array<transition_row, max_rows> rows{};
  std::size_t n = c.get().row_count;
  for (std::size_t i = 0; i < n; ++i) rows[i] = c.get().row(i);
  edit(rows.data(), n);
  c.set_rows(rows.data(), n);
  c.finalize();
  return c;
}

TEST(model_check, reports_each_broken_invariant) {
  // T2 without its STO guard: the drive leaves SWITCH ON DISABLED under STO.
  const custom_profile no_t2_guard = standard_with([](transition_row* rows, std::size_t& n) {
    for (std::size_t i = 0; i < n; ++i) {
      if (rows[i].number == 2) rows[i].none = fact_set();
    }
  });
  EXPECT_GT(violations_of(no_t2_guard, "entered under STO"), 0u);

  // T7 without STO: READY TO SWITCH ON is kept under STO.
  const custom_profile no_t7_sto = standard_with([](transition_row* rows, std::size_t& n) {
    for (std::size_t i = 0; i < n; ++i) {
      if (rows[i].number == 7) rows[i].any = fact::disable_voltage | fact::quick_stop;
    }
  });
  EXPECT_GT(violations_of(no_t7_sto, "T7"), 0u);

  // T13 without its trigger's priority: a fault waits behind the commands.
  const custom_profile t13_last = standard_with([](transition_row* rows, std::size_t& n) {
    const transition_row t13 = rows[0];
    for (std::size_t i = 0; i + 1 < n; ++i) rows[i] = rows[i + 1];
    rows[n - 1] = t13;
  });
  EXPECT_GT(violations_of(t13_last, "did not take T13"), 0u);

  // T6 and T3 automatic: SWITCHED ON and READY TO SWITCH ON trade places forever.
  const custom_profile restless = standard_with([](transition_row* rows, std::size_t& n) {
    for (std::size_t i = 0; i < n; ++i) {
      if (rows[i].number == 3 || rows[i].number == 6) {
        rows[i].any = fact_set(fact::automatic);
        rows[i].all = fact_set();
        rows[i].none = fact_set();
      }
    }
  });
  EXPECT_GT(violations_of(restless, "no rest"), 0u);
}

}  // namespace
}  // namespace cia402

namespace cia402 {
namespace {

// The compiled step's speed test must not overflow for any limit or speed a profile file can hold.
TEST(compiled_step, extreme_speed_limits_and_speeds_agree_with_the_full_step) {
  for (const std::int32_t limit : {1, 1000, 0x3FFFFFFF, INT32_MAX}) {
    custom_profile c(*find_builtin_profile("lexium32"));
    c.settings().speed_limit_rpm = limit;
    c.finalize();
    const compiled_profile compiled(c.get());
    for (const std::int32_t speed : {INT32_MIN, INT32_MIN + 1, -limit, -limit + 1, -1, 0, 1,
                                     limit - 1, limit, INT32_MAX}) {
      axis a = make_axis(c.get());
      axis b = a;
      drive_inputs in;
      in.actual_speed_rpm = speed;
      for (const std::uint16_t cw : {0x00, 0x00, 0x06, 0x0F, 0x0F, 0x07, 0x0F}) {
        in.control_word = cw;
        const drive_outputs x = detail::full_step(c.get(), a, in);
        const drive_outputs y = step(compiled, b, in);
        EXPECT_TRUE(model_check::same_outputs(x, y)) << "limit " << limit << " speed " << speed;
        EXPECT_EQ(std::memcmp(&a, &b, sizeof(axis)), 0) << "limit " << limit << " speed " << speed;
      }
    }
  }
}

}  // namespace
}  // namespace cia402
