// The controller's distributed clocks unit (esc.hpp; ET1100 datasheet section II 0x0900..0x09FF,
// ETG.1000.4 §9.1): receive time latches, the system time with its offset and delay, the difference
// a drift distribution write leaves, and the SYNC0 unit. No allocation, no loop that time does not
// bound (a SYNC0 catch-up is one division).
#include <algorithm>
#include <cstring>

#include "cia402/ethercat/esc/esc.hpp"

namespace cia402::ethercat {
namespace {

constexpr std::uint8_t activation_cyclic_unit = 1u << 0;
constexpr std::uint8_t activation_sync0 = 1u << 1;
constexpr std::uint32_t difference_local_smaller = 1u << 31;
constexpr std::uint64_t max_slew_step_ns = 1000;

bool overlaps(std::uint32_t a, std::uint32_t a_len, std::uint32_t b, std::uint32_t b_len) noexcept {
  return a < b + b_len && b < a + a_len;
}

}  // namespace

std::uint64_t esc::read64(std::uint16_t a) const noexcept {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | memory_[static_cast<std::size_t>(a + i)];
  return v;
}

void esc::set_register64(std::uint16_t a, std::uint64_t v) noexcept {
  for (int i = 0; i < 8; ++i) memory_[static_cast<std::size_t>(a + i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

std::uint64_t esc::system_time() const noexcept { return local_time_ns_ + read64(reg::dc_system_time_offset); }

bool esc::sync0_active() const noexcept {
  const std::uint8_t a = memory_[reg::dc_activation];
  return (a & activation_cyclic_unit) && (a & activation_sync0);
}

bool esc::take_sync0_event() noexcept {
  memory_[reg::dc_sync0_status] = 0;
  const bool pulsed = sync0_event_;
  sync0_event_ = false;
  return pulsed;
}

void esc::dc_before_read(std::uint16_t address, std::uint16_t length) noexcept {
  // The system time reads as the local copy when the frame passes.
  if (overlaps(address, length, reg::dc_system_time, 8)) set_register64(reg::dc_system_time, system_time() + arrival_ns_);
}

void esc::dc_written(std::uint16_t address, std::uint16_t length) noexcept {
  const auto touched = [&](std::uint16_t a, std::uint16_t n) { return overlaps(address, length, a, n); };
  const std::uint64_t now = local_time_ns_ + arrival_ns_;
  if (touched(reg::dc_receive_time, 4)) {
    // A write to port 0's receive time latches every port; the value written is not kept.
    set_register16(reg::dc_receive_time, static_cast<std::uint16_t>(now));
    set_register16(reg::dc_receive_time + 2, static_cast<std::uint16_t>(now >> 16));
    std::memset(memory_.data() + reg::dc_receive_time_port1, 0, 12);  // ports 1..3 until the frame is back
    set_register64(reg::dc_receive_time_unit, now);
    latched_ = true;
  }
  if (touched(reg::dc_system_time, 8)) {
    // The master's drift distribution: the reference clock's system time, plus the delay to here,
    // against the local copy. A write of the low 32 bits compares 32 bits.
    const bool wide = touched(reg::dc_system_time + 4, 4);
    std::uint64_t received = wide ? read64(reg::dc_system_time) : std::uint64_t{read64(reg::dc_system_time) & 0xFFFFFFFFu};
    received += static_cast<std::uint32_t>(memory_[reg::dc_system_time_delay] | (memory_[reg::dc_system_time_delay + 1] << 8) |
                                           (memory_[reg::dc_system_time_delay + 2] << 16) |
                                           (static_cast<std::uint32_t>(memory_[reg::dc_system_time_delay + 3]) << 24));
    std::uint64_t local = system_time() + arrival_ns_;
    if (!wide) {
      local &= 0xFFFFFFFFu;
      received &= 0xFFFFFFFFu;
    }
    const bool smaller = local < received;
    const std::uint64_t magnitude = smaller ? received - local : local - received;
    const std::uint32_t difference = (magnitude > 0x7FFFFFFFu ? 0x7FFFFFFFu : static_cast<std::uint32_t>(magnitude)) |
                                     (smaller ? difference_local_smaller : 0u);
    set_register16(reg::dc_system_time_difference, static_cast<std::uint16_t>(difference));
    set_register16(reg::dc_system_time_difference + 2, static_cast<std::uint16_t>(difference >> 16));
    // The time control loop (ETG.1000.4 §9.1): the local clock steered towards the time received,
    // an eighth of the difference a write finds, at least 1 ns and at most 1 us, so a difference the
    // offsets left (a master's offset without the hop delay leaves that delay) goes to 0 within a few
    // hundred writes, in steps no SYNC0 cycle notices. The clocks share one time base and do not drift.
    const std::uint64_t step = std::min<std::uint64_t>(std::max<std::uint64_t>(magnitude / 8, 1), max_slew_step_ns);
    if (magnitude != 0) local_time_ns_ = smaller ? local_time_ns_ + step : local_time_ns_ - std::min(step, local_time_ns_);
  }
  if (touched(reg::dc_activation, 1)) {
    if (sync0_active()) {
      // The first pulse at the start time; one already past starts at the next whole cycle after it.
      next_sync0_ = read64(reg::dc_start_time);
      const std::uint64_t cycle = read32(reg::dc_sync0_cycle_time);
      const std::uint64_t st = system_time();
      if (next_sync0_ < st && cycle != 0) next_sync0_ += ((st - next_sync0_) / cycle + 1) * cycle;
      set_register64(reg::dc_start_time, next_sync0_);
    }
  }
}

void esc::frame_returned(std::uint32_t downstream_ns) noexcept {
  if (!latched_) return;
  const std::uint32_t port0 = read32(reg::dc_receive_time);
  const std::uint32_t port1 = port0 + downstream_ns;
  set_register16(reg::dc_receive_time_port1, static_cast<std::uint16_t>(port1));
  set_register16(reg::dc_receive_time_port1 + 2, static_cast<std::uint16_t>(port1 >> 16));
  latched_ = false;
}

void esc::dc_advance() noexcept {
  if (!sync0_active()) return;
  const std::uint64_t st = system_time();
  if (st < next_sync0_) return;
  const std::uint64_t cycle = read32(reg::dc_sync0_cycle_time);
  sync0_event_ = true;
  memory_[reg::dc_sync0_status] = 1;
  if (cycle == 0) {
    // One pulse only (single shot): the unit stops.
    memory_[reg::dc_activation] = static_cast<std::uint8_t>(memory_[reg::dc_activation] & ~activation_sync0);
    return;
  }
  // Pulses missed while no time was passed in are one pulse, not a burst.
  next_sync0_ += ((st - next_sync0_) / cycle + 1) * cycle;
  set_register64(reg::dc_start_time, next_sync0_);
}

}  // namespace cia402::ethercat
