// The master side never touches the heap either (include/cia402/master.hpp: "No heap"; STYLE.md,
// ETL: "a test that fails if the core calls operator new"). As in
// tests/core/no_allocation_test.cpp, every global operator new and delete is replaced here by a
// counting version, and the counts are read around stretches of master calls only, since gtest
// itself allocates. This file is its own executable so the replacement touches nothing else.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>

#include "cia402/drive.hpp"
#include "cia402/master.hpp"
#include "cia402/profile.hpp"

namespace {

std::atomic<long> allocations{0};
std::atomic<long> deallocations{0};

void* counted_alloc(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}

void* counted_aligned_alloc(std::size_t size, std::align_val_t align) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  void* p = nullptr;
  std::size_t a = static_cast<std::size_t>(align);
  if (a < sizeof(void*)) a = sizeof(void*);
  if (posix_memalign(&p, a, size == 0 ? 1 : size) != 0) return nullptr;
  return p;
}

void counted_free(void* p) {
  if (p == nullptr) return;
  deallocations.fetch_add(1, std::memory_order_relaxed);
  std::free(p);
}

}  // namespace

// The replaceable global allocation functions ([new.delete]), all of them.
void* operator new(std::size_t n) {
  if (void* p = counted_alloc(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = counted_alloc(n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return counted_alloc(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return counted_alloc(n); }
void* operator new(std::size_t n, std::align_val_t a) {
  if (void* p = counted_aligned_alloc(n, a)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t a) {
  if (void* p = counted_aligned_alloc(n, a)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return counted_aligned_alloc(n, a);
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return counted_aligned_alloc(n, a);
}
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { counted_free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { counted_free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  counted_free(p);
}

namespace cia402 {
namespace {

// Counts heap calls made while `body` runs. Nothing inside may use gtest or the standard library's
// allocating types.
template <typename Body>
long heap_calls_during(Body body) {
  const long a0 = allocations.load();
  const long d0 = deallocations.load();
  body();
  return (allocations.load() - a0) + (deallocations.load() - d0);
}

constexpr state fsa_states[] = {
    state::not_ready_to_switch_on, state::switch_on_disabled, state::ready_to_switch_on,
    state::switched_on,            state::operation_enabled,  state::quick_stop_active,
    state::fault_reaction_active,  state::fault,
};

TEST(master_no_allocation, counter_sees_a_heap_allocation) {
  // So the zero counts below can mean something.
  int* volatile p = nullptr;
  const long calls = heap_calls_during([&] {
    p = new int(7);
    delete p;
    p = new (std::nothrow) int[3];
    delete[] p;
  });
  EXPECT_EQ(calls, 4);
}

TEST(master_no_allocation, plan_path_from_every_state_to_every_target_never_allocates) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    const axis options = make_axis(p);
    int reachable = 0;
    const long calls = heap_calls_during([&] {
      for (const state from : fsa_states) {
        for (const bool reset_bit : {false, true}) {
          const axis start = axis_at_rest(p, options, from, reset_bit);
          for (const state target : fsa_states) {
            const command_path path = plan_path(p, start, target);
            reachable += path.reachable ? 1 : 0;
          }
        }
      }
    });
    EXPECT_EQ(calls, 0) << p.name;
    EXPECT_GT(reachable, 0) << p.name << ": the searches ran";
  }
}

TEST(master_no_allocation, master_policy_make_for_every_target_never_allocates) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    const axis options = make_axis(p);
    std::uint32_t sink = 0;
    const long calls = heap_calls_during([&] {
      for (const state target : fsa_states) {
        const master_policy policy = master_policy::make(p, options, target);
        sink += policy.first[static_cast<int>(state::switch_on_disabled)][0].cycles;
      }
    });
    EXPECT_EQ(calls, 0) << p.name;
    EXPECT_NE(sink, 0u) << p.name << ": the policies were computed";
  }
}

// A master and a drive in a closed loop, through every target, faults, late and frozen status
// words, a word that shows no state, remote off, timeouts and cleared targets, so the master step
// takes each of its branches. Only the loop is counted; the policies are made before it.
TEST(master_no_allocation, master_step_in_a_closed_loop_never_allocates) {
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    const axis options = make_axis(p);
    master_policy policies[sizeof(fsa_states) / sizeof(fsa_states[0])];
    for (std::size_t t = 0; t < sizeof(fsa_states) / sizeof(fsa_states[0]); ++t) {
      policies[t] = master_policy::make(p, options, fsa_states[t]);
    }
    std::uint32_t sink = 0;
    int reached = 0;
    const long calls = heap_calls_during([&] {
      axis a = make_axis(p);
      master m;
      std::uint16_t status = 0;
      std::uint64_t now = 0;
      for (int round = 0; round < 40; ++round) {
        const master_policy& policy = policies[static_cast<std::size_t>(round) % 8];
        m.set_target(policy, now, round % 3 == 0 ? 5 : 0);
        m.application_bits = static_cast<std::uint16_t>(round % 2 ? 0x0100 : 0x0000);
        for (int cycle = 0; cycle < 30; ++cycle, ++now) {
          const std::uint16_t cw = m.step(status, now, 0x2310);
          drive_inputs in;
          in.control_word = cw;
          in.fault_code = (round % 5 == 4 && cycle == 3) ? 0x2310 : 0;
          in.remote = !(round % 7 == 6 && cycle > 10);
          const drive_outputs out = step(p, a, in);
          // Odd rounds see the status word only every other cycle; some rounds freeze it long
          // enough for a timeout, or show once a word that decodes to no state.
          const bool frozen = round % 6 == 3 && cycle >= 1 && cycle < 15;
          if (!frozen && (round % 2 == 0 || cycle % 2 == 0)) status = out.status_word;
          if (round % 10 == 9 && cycle == 5) status = 0x0201;
          if (m.outcome() == master_outcome::reached) ++reached;
          sink += cw + static_cast<std::uint32_t>(m.outcome());
        }
        if (round % 4 == 3) m.clear_target();
        sink += m.step(status, now);
      }
    });
    EXPECT_EQ(calls, 0) << p.name;
    EXPECT_GT(reached, 0) << p.name << ": the loop reached targets";
    EXPECT_NE(sink, 0u);
  }
}

}  // namespace
}  // namespace cia402
