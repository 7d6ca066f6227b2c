// The core never touches the heap (DEVELOPERS.md: no heap in the per-cycle path; STYLE.md, ETL: "a
// test that fails if the core calls operator new"). Every global operator new and delete is replaced
// by the counting versions of tests/support/counting_allocator.hpp; the counts are read around
// stretches of core calls only, since gtest itself allocates. This file is its own executable so
// the replacement touches nothing else.

#include "test_support.hpp"

#include "cia402/error_codes.hpp"

#include "counting_allocator.hpp"

namespace cia402 {
namespace {

using test::heap_calls_during;

// A deterministic input generator that needs no heap.
struct lcg {
  std::uint32_t x;
  std::uint32_t next() {
    x = x * 1664525u + 1013904223u;
    return x >> 8;
  }
};

TEST(no_allocation, counter_sees_a_heap_allocation) {
  // So the zero counts below can mean something.
  EXPECT_EQ(test::heap_calls_of_two_known_allocations(), 4);
}

TEST(no_allocation, stepping_every_profile_never_allocates) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    axis a = make_axis(p);
    lcg rng{static_cast<std::uint32_t>(1234 + i)};
    std::uint32_t sink = 0;
    const long calls = heap_calls_during([&] {
      const std::uint16_t words[] = {0x00, 0x02, 0x06, 0x07, 0x0F, 0x1F, 0x0B, 0x8F, 0x10F};
      drive_inputs in;
      for (int s = 0; s < 50000; ++s) {
        const std::uint32_t r = rng.next();
        in.control_word = (r & 7) == 0 ? static_cast<std::uint16_t>(r >> 8) : words[r % 9];
        in.fault_code = (r & 0x3F0) == 0 ? 0x2310 : 0;
        in.fault_class = static_cast<std::uint8_t>((r >> 12) % 5);
        in.sto = (r & 0x7F000) == 0;
        in.dc_link = (r & 0x3F800) != 0;
        in.standstill = (r & 0x100000) != 0;
        in.brake_engaged = (r & 0x200000) != 0;
        in.connection_lost = (r & 0xF00000) == 0;
        in.actual_speed_rpm = static_cast<std::int32_t>((r >> 4) % 2001) - 1000;
        if ((r % 20011) == 0) a = make_axis(p);
        const drive_outputs o = step(p, a, in);
        sink += o.status_word + o.transition;
      }
      drive d(p);
      for (int s = 0; s < 1000; ++s) sink += d.step(in).status_word;
    });
    EXPECT_EQ(calls, 0) << p.name;
    EXPECT_NE(sink, 0u);
  }
}

TEST(no_allocation, option_writes_and_reads_never_allocate) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    axis a = make_axis(p);
    long accepted = 0;
    const long calls = heap_calls_during([&] {
      const std::uint16_t indices[] = {0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007, 0x6040};
      for (std::uint16_t index : indices) {
        for (std::int32_t v = -40; v <= 40; ++v) {
          if (write_option(p, a, index, v) == sdo_abort::none) ++accepted;
          std::int32_t back = 0;
          read_option(p, a, index, back);
        }
      }
    });
    EXPECT_EQ(calls, 0) << p.name;
    EXPECT_GE(accepted, 0);
  }
}

TEST(no_allocation, profile_checks_names_and_custom_profiles_never_allocate) {
  std::uint32_t sink = 0;
  const long calls = heap_calls_during([&] {
    for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
      const profile& p = builtin_profile(i);
      int row = 0;
      sink += check_profile(p, row) == nullptr;
      custom_profile c(p);
      custom_profile copy = c;
      copy.set_name("copy");
      copy.finalize();
      sink += copy.get().row_count;
      sink += find_builtin_profile(p.name) != nullptr;
    }
    for (int s = 0; s < state_count; ++s) sink += state_name(static_cast<state>(s))[0];
    state parsed{};
    sink += parse_state("operation_enabled", parsed);
    sink += sdo_abort_text(sdo_abort::invalid_value)[0];
    sink += sdo_abort_words(sdo_abort::cannot_store_in_present_state).c_str()[94];  // the closing ')'
    sink += to_hex(0x6041, 4).c_str()[2];
    for (unsigned code = 0; code <= 0xFFFF; code += 0x0101) {
      sink += error_code_text(static_cast<std::uint16_t>(code))[0];
    }
  });
  EXPECT_EQ(calls, 0);
  EXPECT_NE(sink, 0u);
}

}  // namespace
}  // namespace cia402
