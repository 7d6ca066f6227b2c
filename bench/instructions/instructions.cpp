// Steps the core and the bare lookup table through the scenarios of the speed targets, each in a
// function of its own, so callgrind (instructions.sh) can count the instructions of each and divide
// by the steps. Instruction counts do not depend on the machine's load, unlike nanoseconds.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "cia402/compiled.hpp"
#include "cia402/drive.hpp"
#include "cia402/master.hpp"
#include "lookup_table.hpp"

namespace {

constexpr std::uint32_t steps = 1u << 20;
volatile std::uint16_t sink;

using bench::enabled_axis;

__attribute__((noinline)) void core_quiet(const cia402::profile& p, cia402::axis& a) {
  cia402::drive_inputs in;
  in.control_word = 0x0F;
  for (std::uint32_t i = 0; i < steps; ++i) sink = cia402::step(p, a, in).status_word;
}

__attribute__((noinline)) void compiled_quiet(const cia402::compiled_profile& c, cia402::axis& a) {
  cia402::drive_inputs in;
  in.control_word = 0x0F;
  for (std::uint32_t i = 0; i < steps; ++i) sink = cia402::step(c, a, in).status_word;
}

__attribute__((noinline)) void compiled_transitions(const cia402::compiled_profile& c, cia402::axis& a) {
  cia402::drive_inputs in;
  std::uint32_t seed = 402;
  for (std::uint32_t i = 0; i < steps; ++i) {
    in.control_word = bench::transition_word(seed);
    sink = cia402::step(c, a, in).status_word;
  }
}

__attribute__((noinline)) void table_quiet(const bench::lookup_table& t, bench::lookup_table::axis& a) {
  for (std::uint32_t i = 0; i < steps; ++i) sink = t.step(a, 0x0F);
}

__attribute__((noinline)) void core_transitions(const cia402::profile& p, cia402::axis& a) {
  cia402::drive_inputs in;
  std::uint32_t seed = 402;
  for (std::uint32_t i = 0; i < steps; ++i) {
    in.control_word = bench::transition_word(seed);
    sink = cia402::step(p, a, in).status_word;
  }
}

__attribute__((noinline)) void table_transitions(const bench::lookup_table& t, bench::lookup_table::axis& a) {
  std::uint32_t seed = 402;
  for (std::uint32_t i = 0; i < steps; ++i) sink = t.step(a, bench::transition_word(seed));
}

// One loop for both: the status word is 0x0237 with bit 7 (warning) toggled by `toggle` every other
// cycle. The toggle is read through a volatile, so the loop's instructions are the same for a
// repeated word (toggle 0) and a new one: the counts differ only by what the master does.
volatile std::uint16_t warning_toggle = 0;

__attribute__((noinline)) void master_words(const cia402::master_policy& policy, std::uint16_t toggle) {
  warning_toggle = toggle;
  const std::uint16_t t = warning_toggle;
  cia402::master m;
  m.set_target(policy, 0, 0);
  for (std::uint32_t i = 0; i < steps; ++i) {
    sink = m.step(static_cast<std::uint16_t>(0x0237 | ((i & 1u) != 0 ? t : 0u)), i);
  }
}

// The scenarios instructions.sh counts by name.
__attribute__((noinline)) void master_repeated(const cia402::master_policy& policy) { master_words(policy, 0); }
__attribute__((noinline)) void master_changing(const cia402::master_policy& policy) {
  master_words(policy, cia402::status_bit::warning);
}

}  // namespace

int main(int argc, char** argv) {
  const char* which = argc > 1 ? argv[1] : "";
  const char* name = argc > 2 ? argv[2] : "cia402";
  const cia402::profile* p = cia402::find_builtin_profile(name);
  if (p == nullptr) return 2;
  const bench::lookup_table table;
  bench::lookup_table::axis ta;
  cia402::axis a = enabled_axis(*p);
  const cia402::compiled_profile compiled(*p);
  if (std::strcmp(which, "core_quiet") == 0) core_quiet(*p, a);
  else if (std::strcmp(which, "compiled_quiet") == 0) compiled_quiet(compiled, a);
  else if (std::strcmp(which, "compiled_transitions") == 0) compiled_transitions(compiled, a);
  else if (std::strcmp(which, "table_quiet") == 0) { ta.state = 3; table_quiet(table, ta); }
  else if (std::strcmp(which, "core_transitions") == 0) core_transitions(*p, a);
  else if (std::strcmp(which, "table_transitions") == 0) table_transitions(table, ta);
  else if (std::strcmp(which, "master_repeated") == 0 || std::strcmp(which, "master_changing") == 0) {
    const cia402::master_policy policy = cia402::master_policy::make(*p, a, cia402::state::operation_enabled);
    if (which[7] == 'r') master_repeated(policy); else master_changing(policy);
  } else {
    std::fprintf(stderr, "usage: instructions SCENARIO [PROFILE]\n");
    return 2;
  }
  std::printf("%u steps\n", steps);
  return 0;
}
