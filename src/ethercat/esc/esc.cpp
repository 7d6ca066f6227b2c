#include "cia402/ethercat/esc/esc.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

namespace cia402::ethercat {
namespace {

constexpr std::uint16_t dl_pdi_operational = 1u << 0;
constexpr std::uint16_t dl_link_port0 = 1u << 4;
constexpr std::uint16_t dl_link_port1 = 1u << 5;
constexpr std::uint16_t dl_loop_port1 = 1u << 10;
constexpr std::uint16_t dl_communication_port0 = 1u << 9;
constexpr std::uint16_t dl_communication_port1 = 1u << 11;

constexpr std::uint16_t eeprom_read_8_bytes = 1u << 6;
constexpr std::uint16_t eeprom_command_mask = 0x0700;
constexpr std::uint16_t eeprom_read = 0x0100;
constexpr std::uint16_t eeprom_error_command = 1u << 13;

constexpr std::uint8_t sm_status_mailbox_full = 1u << 3;

// The registers a master may write; everything else (identity, DL and AL status, watchdog status,
// the EEPROM's status bits) keeps its value, while the datagram still counts as served.
bool master_writable(std::uint16_t a) noexcept {
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
  // 0x0008 features: 0 = bit-oriented FMMUs, no distributed clocks, no 64-bit DC.
  if (eeprom_.size() >= 10) {
    memory_[reg::station_alias] = eeprom_[8];
    memory_[reg::station_alias + 1] = eeprom_[9];
  }
  write16(reg::dl_status, dl_pdi_operational | dl_link_port0 | dl_communication_port0 | dl_loop_port1);
  write16(reg::al_status, static_cast<std::uint16_t>(al_state::init));
  write16(reg::watchdog_divider, 2498);           // 100 us units: (2498 + 2) x 40 ns
  write16(reg::watchdog_time_process_data, 1000); // 100 ms
  write16(reg::watchdog_status_process_data, 1);  // 1 = active or not triggered yet
  write16(reg::eeprom_control, eeprom_read_8_bytes);
}

std::uint8_t esc::read8(std::uint16_t a) const noexcept { return a < memory_size ? memory_[a] : 0; }
std::uint16_t esc::read16(std::uint16_t a) const noexcept {
  return static_cast<std::uint16_t>(read8(a) | (read8(static_cast<std::uint16_t>(a + 1)) << 8));
}
std::uint32_t esc::read32(std::uint16_t a) const noexcept {
  return read16(a) | (static_cast<std::uint32_t>(read16(static_cast<std::uint16_t>(a + 2))) << 16);
}
void esc::write8(std::uint16_t a, std::uint8_t v) noexcept {
  if (a < memory_size) memory_[a] = v;
}
void esc::write16(std::uint16_t a, std::uint16_t v) noexcept {
  write8(a, static_cast<std::uint8_t>(v));
  write8(static_cast<std::uint16_t>(a + 1), static_cast<std::uint8_t>(v >> 8));
}

void esc::set_al_status(std::uint8_t status, std::uint16_t code) noexcept {
  write16(reg::al_status, status);
  write16(reg::al_status_code, code);
}

void esc::set_next_port_open(bool open) noexcept {
  std::uint16_t dl = read16(reg::dl_status);
  dl = static_cast<std::uint16_t>(dl & ~(dl_link_port1 | dl_communication_port1 | dl_loop_port1));
  dl |= open ? (dl_link_port1 | dl_communication_port1) : dl_loop_port1;
  write16(reg::dl_status, dl);
}

bool esc::take_al_control_event() noexcept { return std::exchange(al_control_event_, false); }
bool esc::take_watchdog_event() noexcept { return std::exchange(watchdog_event_, false); }
bool esc::take_sync_manager_event(int n) noexcept {
  if (n < 0 || n >= sync_manager_count) return false;
  return std::exchange(sms_[static_cast<std::size_t>(n)].event, false);
}

esc::sync_manager esc::sm(int n) const noexcept {
  sync_manager s;
  if (n < 0 || n >= sync_manager_count) return s;
  const auto base = static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n);
  s.start = read16(base);
  s.length = read16(static_cast<std::uint16_t>(base + 2));
  s.control = read8(static_cast<std::uint16_t>(base + 4));
  s.enabled = (read8(static_cast<std::uint16_t>(base + 6)) & 1u) != 0 && s.length != 0;
  return s;
}

bool esc::mailbox_full(int n) const noexcept {
  return n >= 0 && n < sync_manager_count && sms_[static_cast<std::size_t>(n)].full;
}

bool esc::read_mailbox(int n, std::vector<std::uint8_t>& out) noexcept {
  const sync_manager s = sm(n);
  if (!s.enabled || !s.mailbox() || !s.ecat_writes() || !mailbox_full(n)) return false;
  out.assign(memory_.begin() + s.start, memory_.begin() + s.start + s.length);
  sms_[static_cast<std::size_t>(n)].full = false;
  const auto status = static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n + 5);
  write8(status, static_cast<std::uint8_t>(read8(status) & ~sm_status_mailbox_full));
  return true;
}

bool esc::write_mailbox(int n, const std::vector<std::uint8_t>& data) noexcept {
  const sync_manager s = sm(n);
  if (!s.enabled || !s.mailbox() || s.ecat_writes() || mailbox_full(n) || data.size() > s.length) return false;
  std::fill(memory_.begin() + s.start, memory_.begin() + s.start + s.length, std::uint8_t{0});
  std::copy(data.begin(), data.end(), memory_.begin() + s.start);
  sms_[static_cast<std::size_t>(n)].full = true;
  const auto status = static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n + 5);
  write8(status, static_cast<std::uint8_t>(read8(status) | sm_status_mailbox_full));
  return true;
}

bool esc::sync_managers_allow(std::uint16_t address, std::uint16_t length, bool read, bool write) const noexcept {
  for (int n = 0; n < sync_manager_count; ++n) {
    const sync_manager s = sm(n);
    if (!s.enabled || !overlaps(address, length, s.start, s.length)) continue;
    if (s.ecat_writes()) {
      // The master's outputs or its mailbox: a full mailbox takes nothing until the slave read it.
      if (write && s.mailbox() && sms_[static_cast<std::size_t>(n)].full) return false;
    } else {
      // The slave's inputs or mailbox: the master only reads, a mailbox only when it is full.
      if (write) return false;
      if (read && s.mailbox() && !sms_[static_cast<std::size_t>(n)].full) return false;
    }
  }
  return true;
}

void esc::after_ecat_access(std::uint16_t address, std::uint16_t length, bool read, bool write) noexcept {
  for (int n = 0; n < sync_manager_count; ++n) {
    const sync_manager s = sm(n);
    if (!s.enabled || !overlaps(address, length, s.start, s.length)) continue;
    const std::uint32_t last = std::uint32_t{s.start} + s.length - 1u;
    const bool covers_last = address <= last && last < std::uint32_t{address} + length;
    sm_state& st = sms_[static_cast<std::size_t>(n)];
    const auto status = static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n + 5);
    if (s.ecat_writes() && write && covers_last) {
      // The buffer is complete when its last byte is written (mailbox full, new outputs).
      if (s.mailbox()) {
        st.full = true;
        write8(status, static_cast<std::uint8_t>(read8(status) | sm_status_mailbox_full));
      }
      st.event = true;
      if (s.watchdog_trigger()) {
        since_trigger_ns_ = 0;
        write16(reg::watchdog_status_process_data, 1);
      }
    }
    if (!s.ecat_writes() && read && covers_last && s.mailbox()) {
      st.full = false;  // read by the master: the slave may write the next one
      write8(status, static_cast<std::uint8_t>(read8(status) & ~sm_status_mailbox_full));
      st.event = true;
    }
  }
}

void esc::register_written(std::uint16_t address, std::uint16_t length) noexcept {
  const auto touched = [&](std::uint16_t a, std::uint16_t n) { return overlaps(address, length, a, n); };
  if (touched(reg::al_control, 2)) al_control_event_ = true;
  for (int n = 0; n < sync_manager_count; ++n) {
    // A sync manager configured (again) starts empty.
    const auto base = static_cast<std::uint16_t>(reg::sync_manager0 + 8 * n);
    if (touched(base, 5) || touched(static_cast<std::uint16_t>(base + 6), 1)) {
      sms_[static_cast<std::size_t>(n)] = sm_state{};
      write8(static_cast<std::uint16_t>(base + 5), 0);
    }
  }
  if (touched(reg::eeprom_control + 1, 1)) {
    std::uint16_t control = read16(reg::eeprom_control);
    const std::uint16_t cmd = control & eeprom_command_mask;
    control = static_cast<std::uint16_t>((control & ~(eeprom_command_mask | eeprom_error_command)) | eeprom_read_8_bytes);
    if (cmd == eeprom_read) {
      const std::uint64_t word = read32(reg::eeprom_address);
      for (std::uint16_t i = 0; i < 8; ++i) {
        const std::uint64_t at = word * 2 + i;
        write8(static_cast<std::uint16_t>(reg::eeprom_data + i), at < eeprom_.size() ? eeprom_[at] : 0xFF);
      }
    } else if (cmd != 0 && cmd != 0x0400) {
      control |= eeprom_error_command;  // writes are not offered: the image is the drive's own
    }
    write16(reg::eeprom_control, control);
  }
}

bool esc::ecat_access(std::uint16_t address, std::uint8_t* data, std::uint16_t length, bool read, bool write,
                      bool or_read) noexcept {
  if (std::uint32_t{address} + length > memory_size) {
    ++refused_;
    return false;
  }
  if (!sync_managers_allow(address, length, read, write)) {
    ++refused_;
    return false;
  }
  // Read before write, so a read-write returns what was there.
  std::array<std::uint8_t, 2048> incoming{};
  if (write) std::memcpy(incoming.data(), data, length);
  if (read) {
    for (std::uint16_t i = 0; i < length; ++i) {
      data[i] = or_read ? static_cast<std::uint8_t>(data[i] | memory_[address + i]) : memory_[address + i];
    }
  }
  if (write) {
    for (std::uint16_t i = 0; i < length; ++i) {
      const auto a = static_cast<std::uint16_t>(address + i);
      if (master_writable(a)) memory_[a] = incoming[i];
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
      const auto base = static_cast<std::uint16_t>(reg::fmmu0 + 16 * i);
      if ((read8(static_cast<std::uint16_t>(base + 12)) & 1u) == 0) continue;  // not active
      const std::uint8_t type = read8(static_cast<std::uint16_t>(base + 11));
      if (writing ? (type & 2u) == 0 : (type & 1u) == 0) continue;
      const std::uint32_t log_start = read32(base);
      const std::uint16_t log_len = read16(static_cast<std::uint16_t>(base + 4));
      const std::uint8_t start_bit = read8(static_cast<std::uint16_t>(base + 6)) & 7u;
      const std::uint8_t end_bit = read8(static_cast<std::uint16_t>(base + 7)) & 7u;
      const std::uint16_t phys = read16(static_cast<std::uint16_t>(base + 8));
      const std::uint8_t phys_bit = read8(static_cast<std::uint16_t>(base + 10)) & 7u;
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
        ++refused_;
        continue;
      }
      const auto phys_byte = static_cast<std::uint16_t>(phys_first / 8);
      const auto phys_bytes = static_cast<std::uint16_t>(phys_end_byte - phys_byte);
      if (!sync_managers_allow(phys_byte, phys_bytes, !writing, writing)) {
        ++refused_;
        continue;
      }
      const auto dg_bit = static_cast<std::uint32_t>(first - dg_first);
      if ((first % 8) == 0 && (phys_first % 8) == 0 && (bits % 8) == 0) {
        std::uint8_t* mem = memory_.data() + phys_first / 8;
        std::uint8_t* dat = d.data + dg_bit / 8;
        if (writing) {
          std::memcpy(mem, dat, bits / 8);
        } else {
          std::memcpy(dat, mem, bits / 8);
        }
      } else {
        for (std::uint64_t b = 0; b < bits; ++b) {
          const auto p = static_cast<std::uint32_t>(phys_first + b);
          const auto g = static_cast<std::uint32_t>(dg_bit + b);
          if (writing) {
            set_bit(memory_.data(), p, get_bit(d.data, g));
          } else {
            set_bit(d.data, g, get_bit(memory_.data(), p));
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
    default: ++refused_; return;  // not a command: the datagram passes untouched
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
  const std::uint64_t unit_ns = (std::uint64_t{read16(reg::watchdog_divider)} + 2) * 40;
  const std::uint64_t limit = std::uint64_t{read16(reg::watchdog_time_process_data)} * unit_ns;
  bool armed = false;
  for (int n = 0; n < sync_manager_count; ++n) armed = armed || (sm(n).enabled && sm(n).watchdog_trigger());
  if (!armed || limit == 0) {
    since_trigger_ns_ = 0;
    return;
  }
  since_trigger_ns_ += ns;
  if (since_trigger_ns_ > limit && (read16(reg::watchdog_status_process_data) & 1u)) {
    write16(reg::watchdog_status_process_data, 0);  // expired
    write16(reg::watchdog_counter_process_data,
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
    return e;
  }
  for (esc* s : escs_) s->process(parsed_);
  ++frames_;
  return frame_error::none;
}

}  // namespace cia402::ethercat
