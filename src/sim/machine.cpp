// A machine's axes on several threads. A cycle of a thousand axes takes microseconds, less than
// waking a sleeping thread: helpers spin for a while after a cycle (the caller's next cycle usually
// comes within it) and only then sleep on the atomic.
#include "cia402/sim/machine.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace cia402::sim {
namespace {

// A busy wait's pause: lets the sibling hyper-thread run and saves power.
inline void relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

// How long a thread spins for the next change before it sleeps.
constexpr auto spin_for = std::chrono::microseconds(200);

// Waits until `value` differs from `old`: spins for spin_for, then sleeps on the atomic.
template <typename T>
T wait_for_change(const std::atomic<T>& value, T old) noexcept {
  const auto until = std::chrono::steady_clock::now() + spin_for;
  for (unsigned spins = 0;; ++spins) {
    const T now = value.load(std::memory_order_acquire);
    if (now != old) return now;
    relax();
    if ((spins & 255u) == 255u && std::chrono::steady_clock::now() > until) break;
  }
  for (;;) {
    value.wait(old, std::memory_order_acquire);
    const T now = value.load(std::memory_order_acquire);
    if (now != old) return now;
  }
}

unsigned threads_for(std::size_t axes, unsigned asked) noexcept {
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const unsigned wanted = asked == 0 ? hardware : asked;
  const std::size_t most = std::max<std::size_t>(1, axes / machine::axes_per_thread_at_least);
  return static_cast<unsigned>(std::min<std::size_t>(wanted, most));
}

}  // namespace

machine::machine(const profile& p, std::size_t axes, const plant_config& config, unsigned threads)
    : profile_(&p), constants_(checked_constants(config)), axes_(axes, make_axis_state(p, constants_)) {
  const unsigned n = threads_for(axes, threads);
  parts_ = n;
  helpers_.reserve(n - 1);
  try {
    for (unsigned part = 1; part < n; ++part) helpers_.emplace_back([this, part] { helper(part); });
  } catch (...) {  // a thread that cannot be started: the ones that were end before the throw
    stop_helpers();
    throw;
  }
}

machine::~machine() { stop_helpers(); }

void machine::stop_helpers() noexcept {
  stopping_.store(true, std::memory_order_relaxed);
  go_.fetch_add(1, std::memory_order_release);
  go_.notify_all();
  for (std::thread& t : helpers_) t.join();
  helpers_.clear();
}

// Part i of threads(): contiguous, sizes differing by at most one axis.
void machine::step_part(std::size_t part) noexcept {
  const std::size_t n = parts_;
  const std::size_t first = axes_.size() * part / n;
  const std::size_t last = axes_.size() * (part + 1) / n;
  // Locals: the loop must not reload them after every call.
  const profile& p = *profile_;
  const plant_constants& k = constants_;
  axis_state* const axes = axes_.data();
  if (master_.call != nullptr) {
    master_.call(master_.master, p, k, axes, first, last);
    return;
  }
  for (std::size_t i = first; i < last; ++i) step_axis(p, k, axes[i]);
}

void machine::step_on_threads() noexcept {
  left_.store(static_cast<unsigned>(helpers_.size()), std::memory_order_relaxed);
  go_.fetch_add(1, std::memory_order_release);  // publishes the writes made since the last cycle
  go_.notify_all();
  step_part(0);
  for (unsigned left = left_.load(std::memory_order_acquire); left != 0;) {
    left = wait_for_change(left_, left);
  }
}

void machine::helper(std::size_t part) noexcept {
  std::uint64_t seen = 0;
  for (;;) {
    seen = wait_for_change(go_, seen);
    if (stopping_.load(std::memory_order_relaxed)) return;
    step_part(part);
    if (left_.fetch_sub(1, std::memory_order_acq_rel) == 1) left_.notify_one();
  }
}

}  // namespace cia402::sim
