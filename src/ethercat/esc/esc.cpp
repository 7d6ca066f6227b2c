#include "cia402/ethercat/esc/esc.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include "sync_manager_bits.hpp"

namespace cia402::ethercat {
namespace {

using detail::al_event_sm_activation;
using detail::sm_status_mailbox_full;

constexpr std::uint16_t dl_pdi_operational = 1u << 0;
// ETG.1000.4 DL status bit 1: 1 = the PDI watchdog was reloaded, 0 = it expired. The PDI here is
// the drive's application in the same process, which serves the ESC every cycle it is given, so
// the watchdog never expires.
constexpr std::uint16_t dl_pdi_watchdog_reloaded = 1u << 1;
constexpr std::uint16_t dl_link_port0 = 1u << 4;
constexpr std::uint16_t dl_link_port1 = 1u << 5;
constexpr std::uint16_t dl_loop_port1 = 1u << 10;
constexpr std::uint16_t dl_communication_port0 = 1u << 9;
constexpr std::uint16_t dl_communication_port1 = 1u << 11;

constexpr std::uint16_t eeprom_read_8_bytes = 1u << 6;
constexpr std::uint16_t eeprom_command_mask = 0x0700;
constexpr std::uint16_t eeprom_read = 0x0100;
constexpr std::uint16_t eeprom_error_command = 1u << 13;


// The registers a master may write; everything else (identity, DL and AL status, watchdog status,
// the EEPROM's status bits, a sync manager's status and PDI control) keeps its value, while the
// datagram still counts as served.
bool master_writable(std::uint16_t a) noexcept {
  if (a >= reg::sync_manager0 && a < reg::sync_manager0 + 8 * esc::sync_manager_count) {
    const unsigned within = (a - reg::sync_manager0) % 8u;
    return within != reg::sm_status && within != reg::sm_pdi_control;
  }
  return (a >= 0x0010 && a <= 0x0013) || (a >= 0x0100 && a <= 0x0103) || (a >= 0x0120 && a <= 0x0121) ||
         (a >= 0x0200 && a <= 0x0203) || (a >= 0x0300 && a <= 0x030F) || (a >= 0x0400 && a <= 0x0401) ||
         (a >= 0x0410 && a <= 0x0421) || a == 0x0500 || a == 0x0502 || a == 0x0503 ||
         (a >= 0x0504 && a <= 0x050F) || (a >= 0x0600 && a <= 0x08FF) || (a >= 0x0900 && a <= 0x09FF) ||
         a >= reg::process_ram;
}

bool overlaps(std::uint32_t a, std::uint32_t a_len, std::uint32_t b, std::uint32_t b_len) noexcept {
  return a < b + b_len && b < a + a_len;
}

bool get_bit(const std::uint8_t* p, std::uint32_t bit) noexcept { return (p[bit >> 3] >> (bit & 7)) & 1u; }
void set_bit(std::uint8_t* p, std::uint32_t bit, bool v) noexcept {
  const auto mask = static_cast<std::uint8_t>(1u << (bit & 7));
  p[bit >> 3] = static_cast<std::uint8_t>(v ? (p[bit >> 3] | mask) : (p[bit >> 3] & ~mask));
}

}  // namespace

esc::esc(std::vector<std::uint8_t> eeprom) : eeprom_(std::move(eeprom)) {
  memory_[reg::type] = 0xC0;  // not a Beckhoff part: a software controller
  memory_[reg::fmmus_supported] = fmmu_count;
  memory_[reg::sync_managers_supported] = sync_manager_count;
  memory_[reg::ram_size] = 4;
  memory_[reg::port_descriptor] = 0x0F;  // ports 0 and 1 in use (MII), 2 and 3 not implemented
  // 0x0008 features: bit-oriented FMMUs (bit 0 = 0), distributed clocks (bit 2), 64 bits wide (bit 3).
  memory_[reg::features] = 0x0C;
  if (eeprom_.size() >= 10) {
    memory_[reg::station_alias] = eeprom_[8];
    memory_[reg::station_alias + 1] = eeprom_[9];
  }
  set_register16(reg::dl_status, dl_pdi_operational | dl_pdi_watchdog_reloaded | dl_link_port0 |
                                      dl_communication_port0 | dl_loop_port1);
  set_register16(reg::al_status, static_cast<std::uint16_t>(al_state::init));
  set_register16(reg::watchdog_divider, 2498);           // 100 us units: (2498 + 2) x 40 ns
  set_register16(reg::watchdog_time_process_data, 1000); // 100 ms
  set_register16(reg::watchdog_status_process_data, 1);  // 1 = active or not triggered yet
  set_register16(reg::eeprom_control, eeprom_read_8_bytes);
}

// ---- three buffers ---------------------------------------------------------------------------

std::uint8_t* esc::buffer(const sm_state& s, std::uint8_t which) noexcept {
  return which == 0 ? memory_.data() + s.config.start
                    : shadow_[which - 1u].data() + (s.config.start - reg::process_ram);
}
const std::uint8_t* esc::buffer(const sm_state& s, std::uint8_t which) const noexcept {
  return which == 0 ? memory_.data() + s.config.start
                    : shadow_[which - 1u].data() + (s.config.start - reg::process_ram);
}

const esc::sm_state* esc::triple_at(std::uint16_t address) const noexcept {
  if (address < reg::process_ram) return nullptr;
  for (const sm_state& s : sms_) {
    if (s.triple && address >= s.config.start && address - s.config.start < s.config.length) return &s;
  }
  return nullptr;
}

bool esc::any_triple_in(std::uint16_t address, std::uint16_t length) const noexcept {
  for (const sm_state& s : sms_) {
    if (s.triple && overlaps(address, length, s.config.start, s.config.length)) return true;
  }
  return false;
}

const esc::sm_state* esc::only_triple_holding(std::uint16_t address, std::uint16_t length) const noexcept {
  const sm_state* holder = nullptr;
  for (const sm_state& s : sms_) {
    if (!s.triple || !overlaps(address, length, s.config.start, s.config.length)) continue;
    if (holder != nullptr || address < s.config.start || address + length - s.config.start > s.config.length) return nullptr;
    holder = &s;
  }
  return holder;
}

std::uint8_t* esc::ecat_byte(std::uint16_t address) noexcept {
  const sm_state* s = triple_at(address);
  if (s == nullptr) return memory_.data() + address;
  // The master writes into the writer's buffer of its outputs and reads the buffer it opened of
  // the inputs (and, reading its own outputs back, what it is writing).
  const std::uint8_t which = s->config.ecat_writes() ? s->writer : s->reader;
  return buffer(*s, which) + (address - s->config.start);
}

void esc::publish(int n) noexcept {
  sm_state& s = sms_[static_cast<std::size_t>(n)];
  std::swap(s.writer, s.ready);
  s.fresh = true;
  s.published = true;
  s.written = false;
  // The writer goes on from what it published, so bytes it does not write keep their values.
  std::memcpy(buffer(s, s.writer), buffer(s, s.ready), s.config.length);
  show_buffer_state(n);
}

void esc::take_newest(int n) noexcept {
  sm_state& s = sms_[static_cast<std::size_t>(n)];
  if (!s.fresh) return;
  std::swap(s.reader, s.ready);
  s.fresh = false;
  show_buffer_state(n);
}

void esc::show_buffer_state(int n) noexcept {
  const sm_state& s = sms_[static_cast<std::size_t>(n)];
  // Status bits 4..5: the buffer last written (0..2), 3 when none was yet.
  const std::uint8_t last = !s.published ? 3 : (s.fresh ? s.ready : s.reader);
  std::uint8_t& status = memory_[static_cast<std::size_t>(reg::sync_manager0 + 8 * n + reg::sm_status)];
  status = static_cast<std::uint8_t>((status & 0x0F) | (last << 4));
}

void esc::configure_sync_manager(int n, bool reset) noexcept {
  sm_state& s = sms_[static_cast<std::size_t>(n)];
  const auto base = static_cast<std::size_t>(reg::sync_manager0 + 8 * n);
  sync_manager c;
  c.start = static_cast<std::uint16_t>(memory_[base] | (memory_[base + 1] << 8));
  c.length = static_cast<std::uint16_t>(memory_[base + 2] | (memory_[base + 3] << 8));
  c.control = memory_[base + reg::sm_control];
  // Enabled by the master (activate bit 0) and not deactivated by the application (PDI control bit 0).
  // A sync manager's area is process RAM: one set over the registers (or past the memory) is not
  // enabled, so no master can lock itself out of the registers that would undo it.
  c.enabled = (memory_[base + reg::sm_activate] & 1u) != 0 && (memory_[base + reg::sm_pdi_control] & 1u) == 0 &&
              c.length != 0 && c.start >= reg::process_ram && std::uint32_t{c.start} + c.length <= memory_size;
  const bool changed = c.start != s.config.start || c.length != s.config.length || c.control != s.config.control ||
                       c.enabled != s.config.enabled;
  if (!reset && !changed) return;
  s = sm_state{};
  s.config = c;
  watchdog_armed_ = false;  // kept here, where a sync manager changes, not looked up every advance
  for (const sm_state& any : sms_) watchdog_armed_ = watchdog_armed_ || (any.config.enabled && any.config.watchdog_trigger());
  s.triple = c.enabled && c.buffered();
  memory_[base + reg::sm_status] = 0;
  memory_[reg::al_event_request + 1] = static_cast<std::uint8_t>(memory_[reg::al_event_request + 1] & ~(1u << n));
  if (s.triple) {
    // All three buffers start as process RAM holds it.
    for (auto& shadow : shadow_) std::memcpy(shadow.data() + (c.start - reg::process_ram), memory_.data() + c.start, c.length);
    show_buffer_state(n);
  }
}

void esc::raise_sync_manager_event(int n) noexcept {
  sms_[static_cast<std::size_t>(n)].event = true;
  memory_[reg::al_event_request + 1] = static_cast<std::uint8_t>(memory_[reg::al_event_request + 1] | (1u << n));
}

// ---- the application (PDI) side: reads (its writes, events and buffers: esc_pdi.cpp) ------------

std::uint8_t esc::read8(std::uint16_t a) const noexcept {
  if (a >= memory_size) return 0;
  if (const sm_state* s = triple_at(a)) {
    const std::uint8_t which = s->config.ecat_writes() ? s->reader : s->writer;
    return buffer(*s, which)[a - s->config.start];
  }
  return memory_[a];
}
std::uint16_t esc::read16(std::uint16_t a) const noexcept {
  return static_cast<std::uint16_t>(read8(a) | (read8(static_cast<std::uint16_t>(a + 1)) << 8));
}
std::uint32_t esc::read32(std::uint16_t a) const noexcept {
  return read16(a) | (static_cast<std::uint32_t>(read16(static_cast<std::uint16_t>(a + 2))) << 16);
}

void esc::set_register16(std::uint16_t a, std::uint16_t v) noexcept {
  memory_[a] = static_cast<std::uint8_t>(v);
  memory_[a + 1u] = static_cast<std::uint8_t>(v >> 8);
}

void esc::set_next_port_open(bool open) noexcept {
  std::uint16_t dl = read16(reg::dl_status);
  dl = static_cast<std::uint16_t>(dl & ~(dl_link_port1 | dl_communication_port1 | dl_loop_port1));
  dl |= open ? (dl_link_port1 | dl_communication_port1) : dl_loop_port1;
  set_register16(reg::dl_status, dl);
}

// ---- the EtherCAT side -----------------------------------------------------------------------

bool esc::sync_managers_allow(std::uint16_t address, std::uint16_t length, bool read, bool write) const noexcept {
  for (const sm_state& st : sms_) {
    const sync_manager& s = st.config;
    if (!s.enabled || !overlaps(address, length, s.start, s.length)) continue;
    if (s.ecat_writes()) {
      // The master's outputs or its mailbox: a full mailbox takes nothing until the slave read it.
      if (write && s.mailbox() && st.full) return false;
    } else {
      // The slave's inputs or mailbox: the master only reads, a mailbox only when it is full.
      if (write) return false;
      if (read && s.mailbox() && !st.full) return false;
    }
  }
  return true;
}

void esc::before_ecat_access(std::uint16_t address, std::uint16_t length, bool read) noexcept {
  if (!read) return;
  dc_before_read(address, length);
  for (int n = 0; n < sync_manager_count; ++n) {
    sm_state& s = sms_[static_cast<std::size_t>(n)];
    if (!s.triple || s.config.ecat_writes()) continue;
    // Reading the first byte of the inputs opens the newest buffer; the master keeps it until it
    // opens the next, however many datagrams it reads it in.
    if (s.config.start < address || s.config.start - address >= length) continue;
    if (s.written) publish(n);  // what the application wrote by now, even without its last byte
    take_newest(n);
  }
}

void esc::after_ecat_access(std::uint16_t address, std::uint16_t length, bool read, bool write) noexcept {
  for (int n = 0; n < sync_manager_count; ++n) {
    sm_state& st = sms_[static_cast<std::size_t>(n)];
    const sync_manager& s = st.config;
    if (!s.enabled || !overlaps(address, length, s.start, s.length)) continue;
    const std::uint32_t last = std::uint32_t{s.start} + s.length - 1u;
    const bool covers_last = address <= last && last < std::uint32_t{address} + length;
    auto& status = memory_[static_cast<std::size_t>(reg::sync_manager0 + 8 * n + reg::sm_status)];
    if (s.ecat_writes() && write && covers_last) {
      // The buffer is complete when its last byte is written (mailbox full, new outputs).
      if (s.mailbox()) {
        st.full = true;
        status = static_cast<std::uint8_t>(status | sm_status_mailbox_full);
      }
      if (st.triple) publish(n);
      raise_sync_manager_event(n);
      if (s.watchdog_trigger()) {
        since_trigger_ns_ = 0;
        memory_[reg::watchdog_status_process_data] |= 1u;
      }
    }
    if (!s.ecat_writes() && read && covers_last && s.mailbox()) {
      st.full = false;  // read by the master: the slave may write the next one
      status = static_cast<std::uint8_t>(status & ~sm_status_mailbox_full);
      raise_sync_manager_event(n);
    }
  }
}

void esc::register_written(std::uint16_t address, std::uint16_t length) noexcept {
  const auto touched = [&](std::uint16_t a, std::uint16_t n) { return overlaps(address, length, a, n); };
  if (touched(reg::al_control, 2)) {
    al_control_event_ = true;
    memory_[reg::al_event_request] |= 1u;
  }
  if (touched(reg::sync_manager0, 8 * sync_manager_count)) {
    for (int n = 0; n < sync_manager_count; ++n) {
      // A sync manager configured (again) starts empty. Its activate register (ET1100 datasheet,
      // 0x0806 + 8 n) resets it only when the enable bit changes: a toggled repeat request (bit 1)
      // leaves the mailbox as it is and is the application's to answer (ETG.1000.4 mailbox repeat).
      const auto base = static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n);
      const auto activate = static_cast<std::uint16_t>(base + reg::sm_activate);
      if (touched(base, 5)) {
        configure_sync_manager(n, true);
      } else if (touched(activate, 1)) {
        configure_sync_manager(n, false);
        memory_[reg::al_event_request] |= al_event_sm_activation;
      }
    }
  }
  dc_written(address, length);
  if (touched(reg::eeprom_control + 1, 1)) {
    std::uint16_t control = read16(reg::eeprom_control);
    const std::uint16_t cmd = control & eeprom_command_mask;
    control = static_cast<std::uint16_t>((control & ~(eeprom_command_mask | eeprom_error_command)) | eeprom_read_8_bytes);
    if (cmd == eeprom_read) {
      const std::uint64_t word = read32(reg::eeprom_address);
      for (std::uint16_t i = 0; i < 8; ++i) {
        const std::uint64_t at = word * 2 + i;
        memory_[reg::eeprom_data + i] = at < eeprom_.size() ? eeprom_[at] : 0xFF;
      }
    } else if (cmd != 0 && cmd != 0x0400) {
      control |= eeprom_error_command;  // writes are not offered: the image is the drive's own
    }
    set_register16(reg::eeprom_control, control);
  }
}

bool esc::ecat_access(std::uint16_t address, std::uint8_t* data, std::uint16_t length, bool read, bool write,
                      bool or_read) noexcept {
  if (std::uint32_t{address} + length > memory_size) {
    ++errors_.past_memory;
    return false;
  }
  if (!sync_managers_allow(address, length, read, write)) {
    ++errors_.sync_manager;
    return false;
  }
  before_ecat_access(address, length, read);
  // Plain memory (no buffered sync manager in the range) is copied at once; otherwise byte by
  // byte, each to the buffer it belongs to.
  const bool plain = !any_triple_in(address, length);
  // Read before write, so a read-write returns what was there and writes what came.
  std::array<std::uint8_t, 2048> incoming;  // a datagram carries at most 2047 bytes
  const std::uint8_t* source = data;
  if (read && write) {
    std::memcpy(incoming.data(), data, length);
    source = incoming.data();
  }
  if (read) {
    if (plain && !or_read) {
      std::memcpy(data, memory_.data() + address, length);
    } else {
      for (std::uint16_t i = 0; i < length; ++i) {
        const std::uint8_t m = plain ? memory_[address + i] : *ecat_byte(static_cast<std::uint16_t>(address + i));
        data[i] = or_read ? static_cast<std::uint8_t>(data[i] | m) : m;
      }
    }
  }
  if (write) {
    if (plain && address >= reg::process_ram) {
      std::memcpy(memory_.data() + address, source, length);
    } else {
      for (std::uint16_t i = 0; i < length; ++i) {
        const auto a = static_cast<std::uint16_t>(address + i);
        if (master_writable(a)) *(plain ? memory_.data() + a : ecat_byte(a)) = source[i];
      }
    }
    if (address < reg::process_ram) register_written(address, length);
  }
  after_ecat_access(address, length, read, write);
  return true;
}

void esc::logical(datagram& d, bool read, bool write) noexcept {
  bool did_read = false;
  bool did_write = false;
  const std::uint64_t dg_first = std::uint64_t{d.address} * 8;
  const std::uint64_t dg_end = dg_first + std::uint64_t{d.length} * 8;
  // Writes first, from the master's data as it came; then reads replace the bits they map.
  for (int pass = 0; pass < 2; ++pass) {
    const bool writing = pass == 0;
    if (writing ? !write : !read) continue;
    for (int i = 0; i < fmmu_count; ++i) {
      const auto base = static_cast<std::size_t>(reg::fmmu0 + 16 * i);
      const std::uint8_t* f = memory_.data() + base;
      if ((f[12] & 1u) == 0) continue;  // not active
      const std::uint8_t type = f[11];
      if (writing ? (type & 2u) == 0 : (type & 1u) == 0) continue;
      const std::uint32_t log_start = f[0] | (f[1] << 8) | (f[2] << 16) | (static_cast<std::uint32_t>(f[3]) << 24);
      const auto log_len = static_cast<std::uint16_t>(f[4] | (f[5] << 8));
      const std::uint8_t start_bit = f[6] & 7u;
      const std::uint8_t end_bit = f[7] & 7u;
      const auto phys = static_cast<std::uint16_t>(f[8] | (f[9] << 8));
      const std::uint8_t phys_bit = f[10] & 7u;
      if (log_len == 0) continue;
      const std::uint64_t f_first = std::uint64_t{log_start} * 8 + start_bit;
      const std::uint64_t f_end = (std::uint64_t{log_start} + log_len - 1) * 8 + end_bit + 1;
      const std::uint64_t first = std::max(dg_first, f_first);
      const std::uint64_t end = std::min(dg_end, f_end);
      if (first >= end) continue;
      const std::uint64_t phys_first = std::uint64_t{phys} * 8 + phys_bit + (first - f_first);
      const std::uint64_t bits = end - first;
      const std::uint64_t phys_end_byte = (phys_first + bits + 7) / 8;
      if (phys_end_byte > memory_size) {
        ++errors_.past_memory;
        continue;
      }
      const auto phys_byte = static_cast<std::uint16_t>(phys_first / 8);
      const auto phys_bytes = static_cast<std::uint16_t>(phys_end_byte - phys_byte);
      if (!sync_managers_allow(phys_byte, phys_bytes, !writing, writing)) {
        ++errors_.sync_manager;
        continue;
      }
      before_ecat_access(phys_byte, phys_bytes, !writing);
      const bool plain = phys_byte >= reg::process_ram && !any_triple_in(phys_byte, phys_bytes);
      const auto dg_bit = static_cast<std::uint32_t>(first - dg_first);
      const bool whole_bytes = (first % 8) == 0 && (phys_first % 8) == 0 && (bits % 8) == 0;
      // Process data as drives map it: whole bytes inside one three-buffer sync manager, copied at
      // once from or into the buffer the master sees (as ecat_byte() would find it byte by byte,
      // which made every LRW cost a search per bit of every slave's process data).
      const sm_state* within = whole_bytes ? only_triple_holding(phys_byte, phys_bytes) : nullptr;
      if (plain && whole_bytes) {
        std::uint8_t* mem = memory_.data() + phys_first / 8;
        std::uint8_t* dat = d.data + dg_bit / 8;
        if (writing) {
          std::memcpy(mem, dat, bits / 8);
        } else {
          std::memcpy(dat, mem, bits / 8);
        }
      } else if (within != nullptr) {
        std::uint8_t* mem = ecat_byte(phys_byte);
        std::uint8_t* dat = d.data + dg_bit / 8;
        if (writing) {
          std::memcpy(mem, dat, phys_bytes);
        } else {
          std::memcpy(dat, mem, phys_bytes);
        }
      } else {
        // Bit by bit, each byte where it belongs (a buffer, or a register the master may write).
        for (std::uint64_t b = 0; b < bits; ++b) {
          const auto p = static_cast<std::uint32_t>(phys_first + b);
          const auto g = static_cast<std::uint32_t>(dg_bit + b);
          const auto byte = static_cast<std::uint16_t>(p / 8);
          if (writing) {
            if (master_writable(byte)) set_bit(ecat_byte(byte), p % 8, get_bit(d.data, g));
          } else {
            set_bit(d.data, g, get_bit(ecat_byte(byte), p % 8));
          }
        }
      }
      if (writing) {
        did_write = true;
        if (phys_byte < reg::process_ram) register_written(phys_byte, phys_bytes);
      } else {
        did_read = true;
      }
      after_ecat_access(phys_byte, phys_bytes, !writing, writing);
    }
  }
  std::uint16_t wkc = d.working_counter();
  if (did_read) wkc = static_cast<std::uint16_t>(wkc + 1);
  if (did_write) wkc = static_cast<std::uint16_t>(wkc + (read ? 2 : 1));
  d.set_working_counter(wkc);
}

void esc::process(datagram& d) noexcept {
  const command c = d.cmd;
  bool read = false;
  bool write = false;
  bool addressed = false;
  bool or_read = false;
  switch (c) {
    case command::nop: return;
    case command::aprd:
    case command::apwr:
    case command::aprw:
    case command::armw: {
      addressed = d.position() == 0;
      d.set_position(static_cast<std::uint16_t>(d.position() + 1));
      read = c == command::aprd || c == command::aprw || (c == command::armw && addressed);
      write = c == command::apwr || c == command::aprw || (c == command::armw && !addressed);
      if (c == command::armw) addressed = true;  // every slave takes part: one reads, the rest write
      break;
    }
    case command::fprd:
    case command::fpwr:
    case command::fprw:
    case command::frmw: {
      const bool mine = d.position() == read16(reg::station_address);
      addressed = mine || c == command::frmw;
      read = (c == command::fprd || c == command::fprw || (c == command::frmw && mine));
      write = (c == command::fpwr || c == command::fprw || (c == command::frmw && !mine));
      break;
    }
    case command::brd:
    case command::bwr:
    case command::brw:
      addressed = true;
      d.set_position(static_cast<std::uint16_t>(d.position() + 1));
      read = c != command::bwr;
      write = c != command::brd;
      or_read = true;
      break;
    case command::lrd:
    case command::lwr:
    case command::lrw:
      logical(d, c != command::lwr, c != command::lrd);
      return;
    default: ++errors_.unknown_command; return;  // not a command: the datagram passes untouched
  }
  if (!addressed) return;
  if (!ecat_access(d.offset(), d.data, d.length, read, write, or_read)) return;
  std::uint16_t wkc = d.working_counter();
  if (c == command::aprw || c == command::fprw || c == command::brw) {
    wkc = static_cast<std::uint16_t>(wkc + 3);
  } else {
    wkc = static_cast<std::uint16_t>(wkc + 1);
  }
  d.set_working_counter(wkc);
}

void esc::advance(std::uint64_t ns) noexcept {
  local_time_ns_ += ns;
  dc_advance();
  if (!watchdog_armed_) {
    since_trigger_ns_ = 0;
    return;
  }
  const std::uint64_t unit_ns = (std::uint64_t{read16(reg::watchdog_divider)} + 2) * 40;
  const std::uint64_t limit = std::uint64_t{read16(reg::watchdog_time_process_data)} * unit_ns;
  if (limit == 0) {
    since_trigger_ns_ = 0;
    return;
  }
  since_trigger_ns_ += ns;
  if (since_trigger_ns_ > limit && (read16(reg::watchdog_status_process_data) & 1u)) {
    set_register16(reg::watchdog_status_process_data, 0);  // expired
    set_register16(reg::watchdog_counter_process_data,
                   static_cast<std::uint16_t>(read16(reg::watchdog_counter_process_data) + 1));
    watchdog_event_ = true;
  }
}

void chain::add(esc& e) {
  if (!escs_.empty()) escs_.back()->set_next_port_open(true);
  e.set_next_port_open(false);
  escs_.push_back(&e);
}

frame_error chain::pass(std::vector<std::uint8_t>& frame) noexcept {
  const frame_error e = parse_frame(frame, parsed_);
  if (e != frame_error::none) {
    ++refused_frames_;
    ++refused_by_[static_cast<std::size_t>(e)];
    return e;
  }
  const std::size_t n = escs_.size();
  for (std::size_t i = 0; i < n; ++i) escs_[i]->process(parsed_, static_cast<std::uint32_t>(i * hop_delay_ns));
  // Back through every port 1: twice the hops behind each controller.
  for (std::size_t i = 0; i + 1 < n; ++i) escs_[i]->frame_returned(static_cast<std::uint32_t>(2 * (n - 1 - i) * hop_delay_ns));
  ++frames_;
  return frame_error::none;
}

}  // namespace cia402::ethercat
