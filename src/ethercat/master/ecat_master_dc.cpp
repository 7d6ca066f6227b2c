// Our master's distributed clocks set-up (ecat_master.hpp): delay measurement, offsets, the static
// drift distribution and SYNC0, on the way to SAFE-OP. Every time a slave reports is its own to
// give: a read that does not come back, or spans that no line can have, end the set-up with the
// slave and the reason named.
#include <string>

#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "master_text.hpp"

namespace cia402::ethercat {
namespace {

std::uint64_t le(const std::vector<std::uint8_t>& d, std::size_t bytes) {
  std::uint64_t v = 0;
  for (std::size_t k = bytes; k-- > 0;) v = (v << 8) | (k < d.size() ? d[k] : 0);
  return v;
}

std::vector<std::uint8_t> bytes_of(std::uint64_t v, std::size_t n) {
  std::vector<std::uint8_t> d(n);
  for (std::size_t k = 0; k < n; ++k) d[k] = static_cast<std::uint8_t>(v >> (8 * k));
  return d;
}

constexpr int static_drift_frames = 16;
// 0x1C32 SM output parameter, sub 5 minimum cycle time (ETG.1020 §5.3), in ns.
constexpr std::uint16_t sm_output_parameter = 0x1C32;
constexpr std::uint8_t minimum_cycle_time = 5;

}  // namespace

bool ecat_master::configure_distributed_clocks() {
  dc_reference_.reset();
  for (ecat_slave& s : slaves_) {
    const single f = read_register(s, reg::features, 2);
    s.dc = f.ok && f.wkc == 1 && (f.data[0] & 0x04) != 0;
    s.sync0 = false;
    s.dc_delay_ns = 0;
  }
  std::optional<std::size_t> reference;
  for (std::size_t i = 0; i < slaves_.size() && !reference; ++i) {
    if (slaves_[i].dc) reference = i;
  }
  if (!reference) return true;  // no slave has DC: the line runs free
  (void)one(command::bwr, static_cast<std::uint32_t>(reg::dc_receive_time) << 16, {0, 0, 0, 0});
  // Each DC slave's port span (port 1 back minus port 0 in: the time the frame spent behind it, 0 on
  // the last of the line) and its processing unit's receive time.
  std::vector<std::uint64_t> span(slaves_.size(), 0);
  std::vector<std::uint64_t> unit(slaves_.size(), 0);
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    ecat_slave& s = slaves_[i];
    if (!s.dc) continue;
    const single ports = read_register(s, reg::dc_receive_time, 8);
    const single processing = read_register(s, reg::dc_receive_time_unit, 8);
    if (!ports.ok || ports.wkc != 1 || !processing.ok || processing.wkc != 1) {
      return fail(detail::slave_text(s) + " did not give its DC receive times (0x0900, 0x0918)");
    }
    const auto t0 = static_cast<std::uint32_t>(le(ports.data, 4));
    const auto t1 = static_cast<std::uint32_t>(le(std::vector<std::uint8_t>(ports.data.begin() + 4, ports.data.end()), 4));
    span[i] = i + 1 < slaves_.size() ? static_cast<std::uint32_t>(t1 - t0) : 0;
    unit[i] = le(processing.data, 8);
  }
  const std::size_t r = *reference;
  for (std::size_t i = r; i < slaves_.size(); ++i) {
    ecat_slave& s = slaves_[i];
    if (!s.dc) continue;
    // A line: what the frame spends behind the reference, less what it spends behind this slave,
    // is twice the way between them. More behind a later slave than behind the reference is no line.
    if (span[i] > span[r]) {
      return fail(detail::slave_text(s) + " reports " + std::to_string(span[i]) +
                  " ns behind its port 1, more than the reference clock's " + std::to_string(span[r]) +
                  " ns: not a line whose delays this master can measure");
    }
    s.dc_delay_ns = static_cast<std::uint32_t>((span[r] - span[i]) / 2);
    const std::uint64_t offset = unit[r] - unit[i] + s.dc_delay_ns;  // modulo 2^64, as the ESC adds it
    if (!write_register(s, reg::dc_system_time_delay, bytes_of(s.dc_delay_ns, 4)) ||
        !write_register(s, reg::dc_system_time_offset, bytes_of(i == r ? 0 : offset, 8))) {
      return fail(detail::slave_text(s) + " did not take its DC delay and offset (0x0928, 0x0920)");
    }
  }
  const std::uint32_t reference_time = slaves_[r].station | (static_cast<std::uint32_t>(reg::dc_system_time) << 16);
  for (int k = 0; k < static_drift_frames; ++k) (void)one(command::frmw, reference_time, std::vector<std::uint8_t>(8, 0));
  dc_reference_ = r;
  return start_sync0();
}

bool ecat_master::start_sync0() {
  const std::uint64_t cycle = std::uint64_t{cycle_us_} * 1000;
  if (cycle == 0 || cycle > 0xFFFFFFFFu || !dc_reference_) return true;  // no cycle SYNC0 can run at: free run
  // First pass: which slaves run SYNC0 at this cycle, each stopped and given the cycle. Its time on
  // the link bounds the second pass (two writes a slave), which must end before the first pulse: a
  // start time already past when a 64-bit ESC is activated would never come.
  const std::uint64_t first_pass_from = link_->now_us();
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    ecat_slave& s = slaves_[i];
    if (!s.dc) continue;
    // A drive that says it cannot run this cycle (0x1C32:05) is left to run free.
    if (s.mailbox) {
      const ecat_sdo_result minimum = sdo_read(i, sm_output_parameter, minimum_cycle_time);
      if (minimum.ok && static_cast<std::uint64_t>(minimum.value(false)) > cycle) continue;
    }
    if (!write_register(s, reg::dc_activation, {0x00}) || !write_register(s, reg::dc_sync0_cycle_time, bytes_of(cycle, 4))) {
      return fail(detail::slave_text(s) + " did not take its SYNC0 cycle (0x0981, 0x09A0)");
    }
    s.sync0 = true;
  }
  const std::uint64_t pass_ns = (link_->now_us() - first_pass_from) * 1000;
  const single now = read_register(slaves_[*dc_reference_], reg::dc_system_time, 8);
  if (!now.ok || now.wkc != 1) return fail(detail::slave_text(slaves_[*dc_reference_]) + " did not give its system time (0x0910)");
  const std::uint64_t earliest = le(now.data, 8) + 2 * pass_ns + 2 * cycle;
  const std::uint64_t start = (earliest / cycle + 1) * cycle;
  for (ecat_slave& s : slaves_) {
    if (!s.sync0) continue;
    if (!write_register(s, reg::dc_start_time, bytes_of(start, 8)) || !write_register(s, reg::dc_activation, {0x03})) {
      s.sync0 = false;
      return fail(detail::slave_text(s) + " did not take its SYNC0 start (0x0990, 0x0981)");
    }
  }
  return true;
}

}  // namespace cia402::ethercat
