// Drive-side step: the core on every built-in profile against the plain switch baseline.
#include <benchmark/benchmark.h>

#include <vector>

#include "baseline_switch.hpp"
#include "cia402/drive.hpp"
#include "core_setup.hpp"
#include "inputs.hpp"

namespace {

constexpr std::size_t mixed_length = 4096;  // a power of two: index with a mask

void drive_step_steady(benchmark::State& st, const cia402::profile* p) {
  cia402::axis a = cia402::make_axis(*p);
  cia402::drive_inputs in;
  for (std::uint16_t w : {0x06, 0x0F, 0x0F}) {
    in.control_word = w;
    cia402::step(*p, a, in);
  }
  for (auto _ : st) {
    benchmark::DoNotOptimize(cia402::step(*p, a, in));
  }
  st.counters["bytes_per_axis"] = sizeof(cia402::axis);
}

void drive_step_mixed(benchmark::State& st, const cia402::profile* p) {
  const auto seq = bench::mixed_inputs(mixed_length);
  std::vector<cia402::drive_inputs> inputs(mixed_length);
  for (std::size_t i = 0; i < mixed_length; ++i) {
    inputs[i].control_word = seq[i].control_word;
    inputs[i].fault_code = seq[i].fault ? 0x1000 : 0;
  }
  cia402::axis a = cia402::make_axis(*p);
  std::size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(cia402::step(*p, a, inputs[i]));
    i = (i + 1) & (mixed_length - 1);
  }
  st.counters["bytes_per_axis"] = sizeof(cia402::axis);
}

void baseline_step_steady(benchmark::State& st) {
  baseline::drive d;
  for (std::uint16_t w : {0x06, 0x0F, 0x0F, 0x0F}) baseline::step(d, w, false);
  for (auto _ : st) {
    benchmark::DoNotOptimize(baseline::step(d, 0x0F, false));
  }
  st.counters["bytes_per_axis"] = sizeof(baseline::drive);
}

void baseline_step_mixed(benchmark::State& st) {
  const auto seq = bench::mixed_inputs(mixed_length);
  baseline::drive d;
  std::size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(baseline::step(d, seq[i].control_word, seq[i].fault));
    i = (i + 1) & (mixed_length - 1);
  }
  st.counters["bytes_per_axis"] = sizeof(baseline::drive);
}

// One cycle of N axes sharing a profile, each axis at its own point of a held-command sequence:
// what a multi-axis controller pays per cycle.
void drive_cycle_axes(benchmark::State& st) {
  const auto n = static_cast<std::size_t>(st.range(0));
  const cia402::profile& p = cia402::standard_profile();
  const auto seq = bench::held_inputs(mixed_length);
  std::vector<cia402::axis> axes(n, cia402::make_axis(p));
  std::vector<std::uint16_t> status(n);
  std::size_t t = 0;
  for (auto _ : st) {
    for (std::size_t k = 0; k < n; ++k) {
      cia402::drive_inputs in;
      const auto& c = seq[(t + k) & (mixed_length - 1)];
      in.control_word = c.control_word;
      in.fault_code = c.fault ? 0x1000 : 0;
      status[k] = cia402::step(p, axes[k], in).status_word;
    }
    benchmark::DoNotOptimize(status.data());
    ++t;
  }
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations()) * static_cast<std::int64_t>(n));
  st.counters["bytes_per_axis"] = sizeof(cia402::axis);
}

void baseline_cycle_axes(benchmark::State& st) {
  const auto n = static_cast<std::size_t>(st.range(0));
  const auto seq = bench::held_inputs(mixed_length);
  std::vector<baseline::drive> axes(n);
  std::vector<std::uint16_t> status(n);
  std::size_t t = 0;
  for (auto _ : st) {
    for (std::size_t k = 0; k < n; ++k) {
      const auto& c = seq[(t + k) & (mixed_length - 1)];
      status[k] = baseline::step(axes[k], c.control_word, c.fault).status_word;
    }
    benchmark::DoNotOptimize(status.data());
    ++t;
  }
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations()) * static_cast<std::int64_t>(n));
  st.counters["bytes_per_axis"] = sizeof(baseline::drive);
}

const bool registered = [] {
  bench::register_per_profile({{"drive_step_steady", drive_step_steady}, {"drive_step_mixed", drive_step_mixed}});
  benchmark::RegisterBenchmark("baseline_step_steady", baseline_step_steady);
  benchmark::RegisterBenchmark("baseline_step_mixed", baseline_step_mixed);
  for (int n : {1, 100, 10000}) {
    benchmark::RegisterBenchmark("drive_cycle_axes", drive_cycle_axes)->Arg(n);
    benchmark::RegisterBenchmark("baseline_cycle_axes", baseline_cycle_axes)->Arg(n);
  }
  return true;
}();

}  // namespace
