// The application (PDI) side of the controller (esc.hpp): what a slave's application writes, the
// events it takes, its mailboxes and its whole process data buffers. Off the per-frame path, which
// lives in esc.cpp.
#include <algorithm>
#include <cstring>
#include <utility>

#include "cia402/ethercat/esc/esc.hpp"
#include "sync_manager_bits.hpp"

namespace cia402::ethercat {

using detail::al_event_sm_activation;
using detail::sm_repeat;
using detail::sm_status_mailbox_full;

bool esc::pdi_writable(std::uint16_t a) noexcept {
  if (a >= reg::process_ram) return a < memory_size;
  if (a >= reg::sync_manager0 && a < reg::sync_manager0 + 8 * sync_manager_count) {
    return (a - reg::sync_manager0) % 8u == reg::sm_pdi_control;
  }
  // AL status and its code, and the AL event mask: the rest is the master's or the controller's.
  return (a >= reg::al_status && a <= reg::al_status + 1) || (a >= reg::al_status_code && a <= reg::al_status_code + 1) ||
         (a >= reg::al_event_mask && a <= reg::al_event_mask + 3);
}

void esc::write8(std::uint16_t a, std::uint8_t v) noexcept {
  if (!pdi_writable(a)) {
    ++errors_.pdi_refused;
    return;
  }
  if (a >= reg::process_ram) {
    for (int n = 0; n < sync_manager_count; ++n) {
      sm_state& s = sms_[static_cast<std::size_t>(n)];
      if (!s.triple || a < s.config.start || a - s.config.start >= s.config.length) continue;
      const auto at = static_cast<std::size_t>(a - s.config.start);
      if (s.config.ecat_writes()) {
        buffer(s, s.reader)[at] = v;  // the outputs it holds: its own copy to scribble on
        return;
      }
      buffer(s, s.writer)[at] = v;
      s.written = true;
      if (at + 1 == s.config.length) publish(n);  // the last byte closes the buffer, as on an ESC
      return;
    }
    memory_[a] = v;
    return;
  }
  memory_[a] = v;
  if (a >= reg::sync_manager0 && a < reg::sync_manager0 + 8 * sync_manager_count) {
    configure_sync_manager((a - reg::sync_manager0) / 8, false);
  }
}
void esc::write16(std::uint16_t a, std::uint16_t v) noexcept {
  write8(a, static_cast<std::uint8_t>(v));
  write8(static_cast<std::uint16_t>(a + 1), static_cast<std::uint8_t>(v >> 8));
}

void esc::set_al_status(std::uint8_t status, std::uint16_t code) noexcept {
  write16(reg::al_status, status);
  write16(reg::al_status_code, code);
}

bool esc::take_al_control_event() noexcept {
  memory_[reg::al_event_request] = static_cast<std::uint8_t>(memory_[reg::al_event_request] & ~1u);
  return std::exchange(al_control_event_, false);
}
bool esc::take_watchdog_event() noexcept { return std::exchange(watchdog_event_, false); }
bool esc::take_sync_manager_event(int n) noexcept {
  if (n < 0 || n >= sync_manager_count) return false;
  sm_state& s = sms_[static_cast<std::size_t>(n)];
  memory_[reg::al_event_request + 1] = static_cast<std::uint8_t>(memory_[reg::al_event_request + 1] & ~(1u << n));
  if (s.triple && s.config.ecat_writes()) take_newest(n);
  return std::exchange(s.event, false);
}

esc::sync_manager esc::sm(int n) const noexcept {
  if (n < 0 || n >= sync_manager_count) return sync_manager{};
  return sms_[static_cast<std::size_t>(n)].config;
}

bool esc::mailbox_full(int n) const noexcept {
  return n >= 0 && n < sync_manager_count && sms_[static_cast<std::size_t>(n)].full;
}

bool esc::repeat_requested(int n) const noexcept {
  if (n < 0 || n >= sync_manager_count) return false;
  const auto base = static_cast<std::size_t>(reg::sync_manager0 + 8 * n);
  return ((memory_[base + reg::sm_activate] ^ memory_[base + reg::sm_pdi_control]) & sm_repeat) != 0;
}

void esc::acknowledge_repeat(int n) noexcept {
  if (n < 0 || n >= sync_manager_count) return;
  const auto base = static_cast<std::size_t>(reg::sync_manager0 + 8 * n);
  memory_[base + reg::sm_pdi_control] = static_cast<std::uint8_t>((memory_[base + reg::sm_pdi_control] & ~sm_repeat) |
                                                                   (memory_[base + reg::sm_activate] & sm_repeat));
  memory_[reg::al_event_request] = static_cast<std::uint8_t>(memory_[reg::al_event_request] & ~al_event_sm_activation);
}

bool esc::read_mailbox(int n, std::vector<std::uint8_t>& out) noexcept {
  const sync_manager s = sm(n);
  if (!s.enabled || !s.mailbox() || !s.ecat_writes() || !mailbox_full(n) ||
      std::uint32_t{s.start} + s.length > memory_size) {
    return false;
  }
  out.assign(memory_.begin() + s.start, memory_.begin() + s.start + s.length);
  sms_[static_cast<std::size_t>(n)].full = false;
  auto& status = memory_[static_cast<std::size_t>(reg::sync_manager0 + 8 * n + reg::sm_status)];
  status = static_cast<std::uint8_t>(status & ~sm_status_mailbox_full);
  return true;
}

bool esc::write_mailbox(int n, const std::vector<std::uint8_t>& data) noexcept {
  const sync_manager s = sm(n);
  if (!s.enabled || !s.mailbox() || s.ecat_writes() || mailbox_full(n) || data.size() > s.length ||
      std::uint32_t{s.start} + s.length > memory_size) {
    return false;
  }
  std::fill(memory_.begin() + s.start, memory_.begin() + s.start + s.length, std::uint8_t{0});
  std::copy(data.begin(), data.end(), memory_.begin() + s.start);
  sms_[static_cast<std::size_t>(n)].full = true;
  auto& status = memory_[static_cast<std::size_t>(reg::sync_manager0 + 8 * n + reg::sm_status)];
  status = static_cast<std::uint8_t>(status | sm_status_mailbox_full);
  return true;
}

bool esc::read_buffer(int n, std::span<std::uint8_t> out) noexcept {
  if (n < 0 || n >= sync_manager_count) return false;
  const sm_state& s = sms_[static_cast<std::size_t>(n)];
  if (!s.triple || !s.config.ecat_writes() || out.size() != s.config.length) return false;
  take_newest(n);
  std::memcpy(out.data(), buffer(s, s.reader), out.size());
  return true;
}

bool esc::write_buffer(int n, std::span<const std::uint8_t> in) noexcept {
  if (n < 0 || n >= sync_manager_count) return false;
  const sm_state& s = sms_[static_cast<std::size_t>(n)];
  if (!s.triple || s.config.ecat_writes() || in.size() != s.config.length) return false;
  std::memcpy(buffer(s, s.writer), in.data(), in.size());
  publish(n);
  return true;
}

}  // namespace cia402::ethercat
