// Set-up the core's benchmarks share (compiled_bench.cpp, drive_bench.cpp, master_bench.cpp): the
// master's policy to OPERATION ENABLED on the standard profile, and benchmarks registered once for
// each built-in profile, named "NAME/PROFILE".
#pragma once

#include <benchmark/benchmark.h>

#include <cstddef>
#include <initializer_list>
#include <string>
#include <utility>

#include "cia402/master.hpp"
#include "cia402/profile.hpp"

namespace bench {

/// The policy the master benchmarks steer by: the standard profile, target OPERATION ENABLED.
inline cia402::master_policy enabled_policy() {
  const cia402::profile& p = cia402::standard_profile();
  return cia402::master_policy::make(p, cia402::make_axis(p), cia402::state::operation_enabled);
}

using profile_benchmark = void (*)(benchmark::State&, const cia402::profile*);

/// Each of `benchmarks` for each built-in profile, profile by profile in the order given.
inline void register_per_profile(std::initializer_list<std::pair<const char*, profile_benchmark>> benchmarks) {
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile* p = &cia402::builtin_profile(i);
    for (const auto& [name, fn] : benchmarks) {
      benchmark::RegisterBenchmark((std::string(name) + "/" + p->name).c_str(), fn, p);
    }
  }
}

}  // namespace bench
