// The cyclic synchronous modes' interpolation between set-points over the interpolation time period
// 0x60C2 (CiA 402-2): a master that sends a set-point every 10 ms to a drive with a 1 ms cycle sees
// its axis move smoothly between them, not jump to each and wait.
#include "../plant_internal.hpp"

namespace cia402::sim::detail {

std::int64_t interpolate(const plant_constants& k, axis_state& a, std::int64_t sample) noexcept {
  const std::uint32_t period = a.objects.interpolation_period_us;
  if (period <= k.cycle_us) return sample;
  a.interpolation_elapsed_us = add_cycle(a.interpolation_elapsed_us, k.cycle_us);
  if (a.interpolation_elapsed_us > period) {
    // A new period: from the set-point the last one ended at towards the one written now.
    a.interpolation_from = a.interpolation_to;
    a.interpolation_to = sample;
    a.interpolation_elapsed_us -= period;
    if (a.interpolation_elapsed_us > period) a.interpolation_elapsed_us = k.cycle_us;
  }
  const wide span = static_cast<wide>(a.interpolation_to) - a.interpolation_from;
  return a.interpolation_from + static_cast<std::int64_t>(span * a.interpolation_elapsed_us / period);
}

}  // namespace cia402::sim::detail
