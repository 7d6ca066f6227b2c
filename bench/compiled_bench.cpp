// The compiled step (cia402/compiled.hpp) against a bare 256-entry lookup table (lookup_table.hpp),
// in the three scenarios of the speed targets, and the master with a status word that changes in
// bits the state does not show against one that repeats. main.cpp prints each as a ratio to its
// yardstick measured in the same run.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "cia402/compiled.hpp"
#include "cia402/master.hpp"
#include "core_setup.hpp"
#include "lookup_table.hpp"

namespace {

using bench::enabled_axis;

void lookup_quiet(benchmark::State& st) {
  const bench::lookup_table t;
  bench::lookup_table::axis a{3};
  for (auto _ : st) benchmark::DoNotOptimize(t.step(a, 0x0F));
}

void compiled_quiet(benchmark::State& st, const cia402::profile* p) {
  const cia402::compiled_profile c(*p);
  cia402::axis a = enabled_axis(*p);
  cia402::drive_inputs in;
  in.control_word = 0x0F;
  for (auto _ : st) benchmark::DoNotOptimize(cia402::step(c, a, in));
}

void lookup_transitions(benchmark::State& st) {
  const bench::lookup_table t;
  bench::lookup_table::axis a;
  std::uint32_t seed = 402;
  for (auto _ : st) benchmark::DoNotOptimize(t.step(a, bench::transition_word(seed)));
}

void compiled_transitions(benchmark::State& st, const cia402::profile* p) {
  const cia402::compiled_profile c(*p);
  cia402::axis a = enabled_axis(*p);
  cia402::drive_inputs in;
  std::uint32_t seed = 402;
  for (auto _ : st) {
    in.control_word = bench::transition_word(seed);
    benchmark::DoNotOptimize(cia402::step(c, a, in));
  }
}

// The interpreting step on the same sequence: what the table replaces.
void profile_transitions(benchmark::State& st, const cia402::profile* p) {
  cia402::axis a = enabled_axis(*p);
  cia402::drive_inputs in;
  std::uint32_t seed = 402;
  for (auto _ : st) {
    in.control_word = bench::transition_word(seed);
    benchmark::DoNotOptimize(cia402::step(*p, a, in));
  }
}

constexpr std::size_t axes = 10000;

void lookup_axes(benchmark::State& st) {
  const bench::lookup_table t;
  std::vector<bench::lookup_table::axis> a(axes);
  std::vector<std::uint16_t> status(axes);
  std::uint32_t seed = 403;
  for (auto _ : st) {
    for (std::size_t k = 0; k < axes; ++k) status[k] = t.step(a[k], bench::transition_word(seed));
    benchmark::DoNotOptimize(status.data());
  }
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations() * axes));
}

void compiled_axes(benchmark::State& st) {
  const cia402::compiled_profile c(cia402::standard_profile());
  std::vector<cia402::axis> a(axes, cia402::make_axis(cia402::standard_profile()));
  std::vector<std::uint16_t> status(axes);
  std::uint32_t seed = 403;
  for (auto _ : st) {
    for (std::size_t k = 0; k < axes; ++k) {
      cia402::drive_inputs in;
      in.control_word = bench::transition_word(seed);
      status[k] = cia402::step(c, a[k], in).status_word;
    }
    benchmark::DoNotOptimize(status.data());
  }
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations() * axes));
}

// The master in OPERATION ENABLED, its status word XORed with `toggle` every cycle: 0 repeats the
// word, the warning bit 7 gives a new word in the same state each time.
void master_words(benchmark::State& st, std::uint16_t toggle) {
  const cia402::master_policy policy = bench::enabled_policy();
  cia402::master m;
  m.set_target(policy, 0, 0);
  std::uint64_t now = 0;
  std::uint16_t word = 0x0237;
  // Opaque, so both variants run the same loop: only the data differs.
  benchmark::DoNotOptimize(toggle);
  for (auto _ : st) {
    benchmark::DoNotOptimize(m.step(word, ++now));
    word ^= toggle;
    benchmark::DoNotOptimize(word);
  }
}

void master_repeated_word(benchmark::State& st) { master_words(st, 0); }
void master_new_word(benchmark::State& st) { master_words(st, cia402::status_bit::warning); }

const bool registered = [] {
  benchmark::RegisterBenchmark("lookup_quiet", lookup_quiet);
  benchmark::RegisterBenchmark("lookup_transitions", lookup_transitions);
  bench::register_per_profile({{"compiled_quiet", compiled_quiet},
                               {"compiled_transitions", compiled_transitions},
                               {"profile_transitions", profile_transitions}});
  benchmark::RegisterBenchmark("lookup_axes", lookup_axes);
  benchmark::RegisterBenchmark("compiled_axes", compiled_axes);
  benchmark::RegisterBenchmark("master_repeated_word", master_repeated_word);
  benchmark::RegisterBenchmark("master_new_word", master_new_word);
  return true;
}();

}  // namespace
