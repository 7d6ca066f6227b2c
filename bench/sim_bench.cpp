// The simulator with many axes: axis-steps per second for machines of 1, 100, 1,000 and 10,000 virtual
// drives (core state machine + plant each), and 1,000 axes through 60 s of virtual time at a 1 ms
// cycle, reported as wall seconds per virtual second (counter `wall_s_per_virtual_s`; below 1 is
// faster than real time). The wall clock is read here, by the benchmark, never by the simulator.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdint>

#include "cia402/objects.hpp"
#include "cia402/sim/machine.hpp"

namespace {

using namespace cia402;
using namespace cia402::sim;

// Every axis enabled and turning (a different speed each), so cycles are the common running case:
// the core's quiet cycle plus a plant that tracks its set-point.
void enable_all(machine& m) {
  for (std::size_t i = 0; i < m.size(); ++i) m.drive(i).write(0x6040, 0, 0x0006);
  for (int c = 0; c < 3; ++c) m.step();
  for (std::size_t i = 0; i < m.size(); ++i) m.drive(i).write(0x6040, 0, 0x000F);
  for (int c = 0; c < 3; ++c) m.step();
  for (std::size_t i = 0; i < m.size(); ++i) {
    m.drive(i).write(0x60FF, 0, static_cast<std::int64_t>(500 + i % 1000));
  }
}

void sim_axis_steps(benchmark::State& st) {
  const auto n = static_cast<std::size_t>(st.range(0));
  machine m(standard_profile(), n);
  enable_all(m);
  for (int c = 0; c < 400; ++c) m.step();  // past the brake release and the ramp-up
  for (auto _ : st) {
    m.step();
    benchmark::ClobberMemory();
  }
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations()) * static_cast<std::int64_t>(n));
  st.counters["axis_steps_per_s"] = benchmark::Counter(
      static_cast<double>(st.iterations()) * static_cast<double>(n), benchmark::Counter::kIsRate);
  st.counters["bytes_per_axis"] = static_cast<double>(machine::bytes_per_axis);
}
BENCHMARK(sim_axis_steps)->Arg(1)->Arg(100)->Arg(1000)->Arg(10000)->UseRealTime();

// 1,000 axes, 60 s at 1 ms: enable, run up, and through the minute a quick stop and re-enable on
// every 7th axis, a fault, its clearing and a reset on every 11th, STO on every 13th, a halt on
// every 5th.
void sim_1000_axes_60_s(benchmark::State& st) {
  constexpr std::size_t axes = 1000;
  constexpr std::uint64_t cycles = 60000;  // 60 s of 1 ms
  double wall_s = 0;
  for (auto _ : st) {
    machine m(standard_profile(), axes);
    const auto t0 = std::chrono::steady_clock::now();
    for (std::uint64_t c = 0; c < cycles; ++c) {
      const std::uint64_t second = c / 1000;
      const bool at_second = c % 1000 == 0;
      if (c == 10 || c == 20 || c == 30 || (at_second && second > 0)) {
        for (std::size_t i = 0; i < axes; ++i) {
          drive_view d = m.drive(i);
          if (c == 10) d.write(0x6040, 0, 0x0006);
          if (c == 20) d.write(0x6040, 0, 0x000F);
          if (c == 30) d.write(0x60FF, 0, static_cast<std::int64_t>(300 + (i * 37) % 2700));
          if (!at_second || second == 0) continue;
          const std::uint64_t phase = second % 10;
          if (i % 7 == 0 && phase == 3) d.write(0x6040, 0, 0x000B);
          if (i % 7 == 0 && phase == 5) d.write(0x6040, 0, 0x0006);
          if (i % 7 == 0 && phase == 6) d.write(0x6040, 0, 0x000F);
          if (i % 7 == 0 && phase == 7) d.write(0x60FF, 0, 1000);
          if (i % 11 == 0 && phase == 2) d.inject_fault(0x2310);
          if (i % 11 == 0 && phase == 4) d.clear_faults();
          if (i % 11 == 0 && phase == 5) d.write(0x6040, 0, 0x0080);
          if (i % 11 == 0 && phase == 6) d.write(0x6040, 0, 0x0006);
          if (i % 11 == 0 && phase == 7) d.write(0x6040, 0, 0x000F);
          if (i % 11 == 0 && phase == 8) d.write(0x60FF, 0, 800);
          if (i % 13 == 0 && phase == 1) d.set_sto(true);
          if (i % 13 == 0 && phase == 2) d.set_sto(false);
          if (i % 13 == 0 && phase == 3) d.write(0x6040, 0, 0x0080);
          if (i % 13 == 0 && phase == 4) d.write(0x6040, 0, 0x0006);
          if (i % 13 == 0 && phase == 5) d.write(0x6040, 0, 0x000F);
          if (i % 13 == 0 && phase == 6) d.write(0x60FF, 0, 1200);
          if (i % 5 == 0 && phase == 8) d.write(0x6040, 0, 0x010F);
          if (i % 5 == 0 && phase == 9) d.write(0x6040, 0, 0x000F);
        }
      }
      m.step();
    }
    wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(m.axis_at(axes - 1).velocity);
  }
  const double runs = static_cast<double>(st.iterations());
  st.counters["wall_s_per_virtual_s"] = wall_s / runs / 60.0;
  st.counters["axis_steps_per_s"] =
      static_cast<double>(axes) * static_cast<double>(cycles) * runs / wall_s;
}
BENCHMARK(sim_1000_axes_60_s)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

namespace {

// The position modes: axis-steps per second with every axis in a profile position move (pp) or
// following a cyclic set-point (csp), and 1,000 csp axes through 10 s at 1 kHz, each cycle's
// 0x607A written through the object interface as a master's PDO would: `realtime_factor` is
// virtual seconds per wall second (the issue asks at least 100).
void enable_in_mode(machine& m, std::int64_t mode) {
  for (std::size_t i = 0; i < m.size(); ++i) {
    m.drive(i).write(0x6060, 0, mode);
    m.drive(i).write(0x6040, 0, 0x0006);
  }
  for (int c = 0; c < 3; ++c) m.step();
  for (std::size_t i = 0; i < m.size(); ++i) m.drive(i).write(0x6040, 0, 0x000F);
  for (int c = 0; c < 60; ++c) m.step();  // past the brake release
}

void sim_pp_axis_steps(benchmark::State& st) {
  const auto n = static_cast<std::size_t>(st.range(0));
  machine m(standard_profile(), n);
  enable_in_mode(m, mode::profile_position);
  std::uint64_t c = 0;
  for (auto _ : st) {
    // A new set-point every 2 s of virtual time: most cycles run the trapezoid.
    if (c % 2000 == 0) {
      for (std::size_t i = 0; i < n; ++i) {
        m.drive(i).write(0x607A, 0, static_cast<std::int64_t>(((c / 2000) % 2 ? 0 : 50000 + 100 * (i % 100))));
        m.drive(i).write(0x6040, 0, 0x003F);
      }
    } else if (c % 2000 == 2) {
      for (std::size_t i = 0; i < n; ++i) m.drive(i).write(0x6040, 0, 0x000F);
    }
    m.step();
    ++c;
    benchmark::ClobberMemory();
  }
  st.counters["axis_steps_per_s"] = benchmark::Counter(
      static_cast<double>(st.iterations()) * static_cast<double>(n), benchmark::Counter::kIsRate);
}
BENCHMARK(sim_pp_axis_steps)->Arg(100)->UseRealTime();

// Arguments: the machine's threads, and whether the set-points are written by a master inside the
// step (machine::step(master): on the thread that steps the axis, just before it) or by the caller
// between steps.
void sim_1000_axes_csp_1khz(benchmark::State& st) {
  constexpr std::size_t axes = 1000;
  constexpr std::uint64_t cycles = 10000;  // 10 s of 1 ms
  const auto threads = static_cast<unsigned>(st.range(0));
  const bool master_in_step = st.range(1) != 0;
  double wall_s = 0;
  for (auto _ : st) {
    machine m(standard_profile(), axes, {}, threads);
    enable_in_mode(m, mode::cyclic_synchronous_position);
    const auto t0 = std::chrono::steady_clock::now();
    for (std::uint64_t c = 0; c < cycles; ++c) {
      // A sine-free ramp back and forth: 20 increments a ms (120 rpm), turning every 2 s.
      const std::int64_t leg = static_cast<std::int64_t>(c % 4000);
      const std::int64_t target = leg < 2000 ? 20 * leg : 20 * (4000 - leg);
      if (master_in_step) {
        m.step([target](drive_view d, std::size_t i) {
          d.write(0x607A, 0, target + static_cast<std::int64_t>(i));
        });
      } else {
        for (std::size_t i = 0; i < axes; ++i) m.drive(i).write(0x607A, 0, target + static_cast<std::int64_t>(i));
        m.step();
      }
    }
    wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(m.axis_at(axes - 1).position);
    st.counters["threads"] = m.threads();
  }
  const double runs = static_cast<double>(st.iterations());
  st.counters["realtime_factor"] = 10.0 * runs / wall_s;
  st.counters["axis_steps_per_s"] = static_cast<double>(axes) * static_cast<double>(cycles) * runs / wall_s;
}
BENCHMARK(sim_1000_axes_csp_1khz)
    ->ArgNames({"threads", "master_in_step"})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
