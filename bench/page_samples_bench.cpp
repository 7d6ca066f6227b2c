// The scope's per-cycle samples (issue 35): what one sample costs beside the page's whole cycle it
// belongs to, measured in the same run. page_cycle is the baseline: one cycle of the instrument
// page over a virtual drive in this process turning at 1500 rpm (the session, the simulator's step,
// the recorder, the snapshot and the sample). sample_push is the ring's part of it; sample_batch
// is the event stream's: a batch of 50 moving samples (one 50 ms batch at 1 kHz) as JSON, with
// bytes_per_sample. The ratios to page_cycle are what docs/instrument-page.md states.
#include <benchmark/benchmark.h>

#include "cia402/apps/local_link.hpp"
#include "cia402/page/axis_page.hpp"
#include "cia402/profile.hpp"
#include "sample_ring.hpp"

namespace {

using cia402::page::detail::cycle_sample;
using cia402::page::detail::sample_ring;
using cia402::page::detail::signal;

cia402::page::drive_connection local(const cia402::profile& p) {
  auto link = std::make_unique<cia402::apps::local_link>(p);
  cia402::sim::virtual_drive* plant = &link->drive();
  return {std::move(link), plant};
}

// A moving drive: every analog column changes each cycle (the run-length code's worst case).
cycle_sample moving(std::uint64_t k) {
  cycle_sample s;
  s.time_us = 1000 * k;
  s.set(signal::status_word, 0x1237);
  s.set(signal::control_word, 0x000F);
  s.set(signal::state, 5);
  s.set(signal::velocity, 1500 + static_cast<std::int64_t>(k % 3));
  s.set(signal::position, static_cast<std::int64_t>(250 * k));
  s.set(signal::torque, 100 + static_cast<std::int64_t>(k % 7));
  s.set(signal::following_error, static_cast<std::int64_t>(k % 11));
  s.set(signal::set_point, 1500);
  s.set(signal::position_demand, static_cast<std::int64_t>(250 * k + k % 11));
  s.set(signal::digital_inputs, k % 40 == 0 ? 0x10000 : 0);
  s.set(signal::mode, 3);
  s.set(signal::error_code, 0);
  return s;
}

void page_cycle(benchmark::State& st) {
  cia402::page::axis_page page(cia402::standard_profile(), local);
  for (int i = 0; i < 20; ++i) page.step();
  for (const auto c : {cia402::page::page_command::shutdown, cia402::page::page_command::switch_on,
                       cia402::page::page_command::enable_operation}) {
    page.command(c);
    for (int i = 0; i < 20; ++i) page.step();
  }
  page.change_plant({.target_velocity = 1500});
  for (auto _ : st) page.step();
  std::uint64_t next = 0;
  benchmark::DoNotOptimize(page.samples_json(0, 1, next));
}

void sample_push(benchmark::State& st) {
  sample_ring ring;
  std::uint64_t k = 0;
  for (auto _ : st) ring.push(moving(++k));
  benchmark::DoNotOptimize(ring.end());
}

void sample_batch(benchmark::State& st) {
  sample_ring ring;
  for (std::uint64_t k = 0; k < 5000; ++k) ring.push(moving(k));
  std::uint64_t from = 0;
  std::size_t bytes = 0, batches = 0;
  for (auto _ : st) {
    std::uint64_t next = 0;
    const std::string b = ring.batch_json(from, 50, next, {});
    bytes += b.size();
    ++batches;
    from = next < ring.end() ? next : 0;
  }
  st.counters["bytes_per_sample"] = static_cast<double>(bytes) / static_cast<double>(batches * 50);
  st.SetItemsProcessed(static_cast<std::int64_t>(batches * 50));
}

BENCHMARK(page_cycle);
BENCHMARK(sample_push);
BENCHMARK(sample_batch);

}  // namespace

BENCHMARK_MAIN();
