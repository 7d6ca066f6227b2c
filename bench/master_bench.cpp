// Master step: the core's policy lookup against the plain switch master.
#include <benchmark/benchmark.h>

#include <vector>

#include "baseline_switch.hpp"
#include "cia402/master.hpp"
#include "core_setup.hpp"

namespace {

// Status words of a drive being enabled, run, quick-stopped, faulted and reset.
std::vector<std::uint16_t> status_trace() {
  return {0x0250, 0x0231, 0x0233, 0x0237, 0x0237, 0x0237, 0x0237, 0x0217, 0x0250, 0x0231,
          0x0233, 0x0237, 0x021F, 0x0218, 0x0218, 0x0250, 0x0231, 0x0233, 0x0237, 0x0237};
}

void master_step_steady(benchmark::State& st) {
  const cia402::master_policy policy = bench::enabled_policy();
  cia402::master m;
  m.set_target(policy, 0, 0);
  std::uint64_t now = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(m.step(0x0237, ++now));
  }
  st.counters["bytes_per_axis"] = sizeof(cia402::master);
}

void master_step_trace(benchmark::State& st) {
  const cia402::master_policy policy = bench::enabled_policy();
  const auto trace = status_trace();
  cia402::master m;
  std::uint64_t now = 0;
  std::size_t i = 0;
  for (auto _ : st) {
    if (i == 0) m.set_target(policy, now, 0);  // a fault latches: start each pass afresh
    benchmark::DoNotOptimize(m.step(trace[i], ++now));
    i = i + 1 == trace.size() ? 0 : i + 1;
  }
  st.counters["bytes_per_axis"] = sizeof(cia402::master);
}

void baseline_master_steady(benchmark::State& st) {
  std::uint16_t last = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(baseline::master_step(0x0237, last));
  }
  st.counters["bytes_per_axis"] = sizeof(last);
}

void baseline_master_trace(benchmark::State& st) {
  const auto trace = status_trace();
  std::uint16_t last = 0;
  std::size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(baseline::master_step(trace[i], last));
    i = i + 1 == trace.size() ? 0 : i + 1;
  }
  st.counters["bytes_per_axis"] = sizeof(last);
}

BENCHMARK(master_step_steady);
BENCHMARK(master_step_trace);
BENCHMARK(baseline_master_steady);
BENCHMARK(baseline_master_trace);

}  // namespace
