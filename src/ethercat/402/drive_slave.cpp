#include "cia402/ethercat/402/drive_slave.hpp"

#include <algorithm>
#include <array>
#include <span>

#include "cia402/ethercat/402/drive_description.hpp"

namespace cia402::ethercat {
namespace {

std::vector<canopen::object_entry> table_with_serial(std::uint32_t serial) {
  std::vector<canopen::object_entry> t = coe_drive_objects();
  for (canopen::object_entry& o : t) {
    if (o.index != 0x1018) continue;
    for (canopen::sub_entry& e : o.subs) {
      if (e.sub == 4) e.default_value = serial;
    }
  }
  return t;
}

bool mapping_object(std::uint16_t index) noexcept {
  return (index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF);
}
bool assignment_object(std::uint16_t index) noexcept { return index == 0x1C12 || index == 0x1C13; }

constexpr std::uint8_t al_error_flag = 0x10;
constexpr std::uint8_t al_acknowledge = 0x10;
constexpr int sm_outputs = 2;
constexpr int sm_inputs = 3;

}  // namespace

drive_slave::drive_slave(const profile& p, std::uint32_t serial, const sim::plant_config& plant)
    : dictionary_access(od_),
      od_(table_with_serial(serial), 0),
      device_(p, plant),
      description_(drive_slave_description(od_.table(), serial)),
      esc_(sii_image(description_)),
      coe_(*this, od_, mailbox_size) {
  device_.attach(this);
  esc_.set_al_status(static_cast<std::uint8_t>(al_state::init), al_code::none);
}

drive_slave::~drive_slave() { device_.attach(nullptr); }

std::vector<drive_slave::mapped> drive_slave::mapping(std::uint16_t assignment) const {
  std::vector<mapped> out;
  const std::int64_t pdos = od_.number(assignment, 0);
  for (std::int64_t i = 1; i <= pdos; ++i) {
    const auto pdo = static_cast<std::uint16_t>(od_.number(assignment, static_cast<std::uint8_t>(i)));
    const std::int64_t entries = od_.number(pdo, 0);
    for (std::int64_t k = 1; k <= entries; ++k) {
      const auto m = static_cast<std::uint32_t>(od_.number(pdo, static_cast<std::uint8_t>(k)));
      out.push_back({static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>(m >> 8),
                     static_cast<std::uint8_t>(m)});
    }
  }
  return out;
}

std::uint16_t drive_slave::output_bytes() const noexcept {
  unsigned bits = 0;
  for (const mapped& m : mapping(0x1C12)) bits += m.bits;
  return static_cast<std::uint16_t>((bits + 7) / 8);
}

std::uint16_t drive_slave::input_bytes() const noexcept {
  unsigned bits = 0;
  for (const mapped& m : mapping(0x1C13)) bits += m.bits;
  return static_cast<std::uint16_t>((bits + 7) / 8);
}

sdo_abort drive_slave::read_value(const canopen::object_dictionary::slot& s, std::int64_t& v) {
  if (s.entry->where == canopen::backing::device) return device_.read(s.object->index, s.entry->sub, v);
  v = s.number;
  return sdo_abort::none;
}

bool drive_slave::entry_mappable(std::uint16_t mapping, std::uint32_t m) const {
  // An entry names an object of the dictionary, mappable in this direction, of its own size.
  const canopen::object_dictionary::slot* target = od_.find(static_cast<std::uint16_t>(m >> 16),
                                                              static_cast<std::uint8_t>(m >> 8));
  const bool rx = mapping < 0x1A00;
  return target != nullptr && target->entry->pdo_mappable &&
         (rx ? canopen::writable(target->entry->acc) : !canopen::writable(target->entry->acc)) &&
         canopen::type_size(target->entry->type) * 8 == (m & 0xFFu) && (m & 0xFFu) != 0;
}

sdo_abort drive_slave::write_value(canopen::object_dictionary::slot& s, std::int64_t v) {
  const std::uint16_t index = s.object->index;
  const std::uint8_t sub = s.entry->sub;
  if (s.entry->where == canopen::backing::device) return device_.write(index, sub, v);
  if (mapping_object(index) || assignment_object(index)) {
    // The process data are configured in PRE-OP only.
    if (state_ != al_state::pre_operational) return sdo_abort::cannot_store_in_present_state;
    if (mapping_object(index) && sub != 0 && v != 0 && !entry_mappable(index, static_cast<std::uint32_t>(v))) {
      return sdo_abort::cannot_map_to_pdo;
    }
    if (mapping_object(index) && sub == 0) {
      // The entries it counts in are checked again: one left 0 (or never written) maps nothing of
      // no length, which the process data cannot carry.
      unsigned bits = 0;
      for (std::int64_t k = 1; k <= v; ++k) {
        const auto m = static_cast<std::uint32_t>(od_.number(index, static_cast<std::uint8_t>(k)));
        if (!entry_mappable(index, m)) return sdo_abort::cannot_map_to_pdo;
        bits += m & 0xFFu;
      }
      if ((bits + 7) / 8 > max_process_data) return sdo_abort::pdo_length_exceeded;
    }
    if (assignment_object(index) && sub != 0 && v != 0) {
      const std::uint16_t first = index == 0x1C12 ? 0x1600 : 0x1A00;
      if (v != first && v != first + 1) return sdo_abort::invalid_value;
    }
  }
  s.number = v;
  return sdo_abort::none;
}

void drive_slave::error_changed(std::uint16_t code) noexcept {
  std::int64_t reg = 0;
  (void)device_.read(0x1001, 0, reg);
  coe_.emergency(code, static_cast<std::uint8_t>(reg), device_.manufacturer_error_field());
}

void drive_slave::refuse(std::uint16_t code) {
  error_ = true;
  code_ = code;
  esc_.set_al_status(static_cast<std::uint8_t>(static_cast<std::uint8_t>(state_) | al_error_flag), code_);
}

void drive_slave::enter(al_state s) {
  const al_state before = state_;
  state_ = s;
  if (s == al_state::init) coe_.reset();
  // Leaving OP the master no longer commands the drive; entering it, it does again (0x6007, S10).
  if (before == al_state::operational && s != al_state::operational) device_.set_connection_lost(true);
  if (s == al_state::operational) device_.set_connection_lost(false);
  esc_.set_al_status(static_cast<std::uint8_t>(static_cast<std::uint8_t>(state_) | (error_ ? al_error_flag : 0)),
                     error_ ? code_ : al_code::none);
}

bool drive_slave::mailbox_sync_managers_sound() const {
  for (int n = 0; n < 2; ++n) {
    const esc::sync_manager sm = esc_.sm(n);
    const sync_manager_description& want = description_.sync_managers[static_cast<std::size_t>(n)];
    if (!sm.enabled || sm.start != want.start || sm.length != want.length || !sm.mailbox() ||
        sm.ecat_writes() != (n == 0)) {
      return false;
    }
  }
  return true;
}

bool drive_slave::process_data_sync_manager_sound(int n, std::uint16_t bytes, bool outputs) const {
  const esc::sync_manager sm = esc_.sm(n);
  if (bytes == 0) return !sm.enabled || sm.length == 0;
  return sm.enabled && !sm.mailbox() && sm.ecat_writes() == outputs && sm.length == bytes &&
         std::uint32_t{sm.start} + sm.length <= esc::memory_size && sm.start >= reg::process_ram;
}

void drive_slave::handle_al_control() {
  const std::uint16_t control = esc_.read16(reg::al_control);
  if ((control & al_acknowledge) && error_) {
    error_ = false;
    code_ = al_code::none;
  }
  const unsigned wanted = control & 0x0Fu;
  const auto current = static_cast<unsigned>(state_);
  switch (wanted) {
    case 1: enter(al_state::init); return;
    case 3: refuse(al_code::bootstrap_not_supported); return;
    case 2:
      if (state_ == al_state::init && !mailbox_sync_managers_sound()) return refuse(al_code::invalid_mailbox_configuration);
      enter(al_state::pre_operational);
      return;
    case 4:
      if (state_ == al_state::init) return refuse(al_code::invalid_state_change);
      if (state_ == al_state::pre_operational) {
        if (!process_data_sync_manager_sound(sm_outputs, output_bytes(), true)) {
          return refuse(al_code::invalid_output_configuration);
        }
        if (!process_data_sync_manager_sound(sm_inputs, input_bytes(), false)) {
          return refuse(al_code::invalid_input_configuration);
        }
        outputs_checked_ = esc_.sm(sm_outputs);
        inputs_checked_ = esc_.sm(sm_inputs);
      }
      enter(al_state::safe_operational);
      return;
    case 8:
      if (current < static_cast<unsigned>(al_state::safe_operational)) return refuse(al_code::invalid_state_change);
      enter(al_state::operational);
      return;
    default: refuse(al_code::unknown_state); return;
  }
}

bool drive_slave::same(const esc::sync_manager& a, const esc::sync_manager& b) noexcept {
  return a.start == b.start && a.length == b.length && a.control == b.control && a.enabled == b.enabled;
}

void drive_slave::watch_sync_managers() {
  // A sync manager the master changes after the state that checked it takes the slave back to where
  // it is checked again, with the code that says which (as the ETG's slave code does): the mailbox
  // to INIT, the process data to PRE-OP. Until then nothing is read from it or written to it.
  if (state_ == al_state::init) return;
  if (!mailbox_sync_managers_sound()) {
    refuse(al_code::invalid_mailbox_configuration);
    return enter(al_state::init);
  }
  if (state_ != al_state::safe_operational && state_ != al_state::operational) return;
  if (!same(esc_.sm(sm_outputs), outputs_checked_)) {
    refuse(al_code::invalid_output_configuration);
    return enter(al_state::pre_operational);
  }
  if (!same(esc_.sm(sm_inputs), inputs_checked_)) {
    refuse(al_code::invalid_input_configuration);
    return enter(al_state::pre_operational);
  }
}

void drive_slave::serve_mailbox() {
  if (state_ == al_state::init) return;
  std::vector<std::uint8_t> request;
  if (esc_.read_mailbox(0, request)) coe_.on_mailbox(request);
  if (coe_.has_reply() && !esc_.mailbox_full(1)) (void)esc_.write_mailbox(1, coe_.take_reply());
}

void drive_slave::exchange_process_data() {
  if (state_ != al_state::safe_operational && state_ != al_state::operational) return;
  // Whole buffers through the sync managers checked on the way to SAFE-OP: the application reaches
  // process RAM only, in the buffer the controller gives it.
  std::array<std::uint8_t, max_process_data> buffer{};
  const bool outputs_arrived = esc_.take_sync_manager_event(sm_outputs);
  const std::size_t out_bytes = outputs_checked_.enabled ? outputs_checked_.length : 0;
  if (state_ == al_state::operational && outputs_arrived && out_bytes <= buffer.size() &&
      esc_.read_buffer(sm_outputs, std::span(buffer.data(), out_bytes))) {
    unsigned bit = 0;
    for (const mapped& m : mapping(0x1C12)) {
      if (m.bits == 0 || m.bits > 64 || bit + m.bits > 8 * out_bytes) break;
      std::uint64_t raw = 0;
      for (unsigned b = 0; b < m.bits; ++b, ++bit) raw |= static_cast<std::uint64_t>((buffer[bit / 8] >> (bit % 8)) & 1u) << b;
      std::int64_t value = static_cast<std::int64_t>(raw);
      if (m.bits < 64 && (raw >> (m.bits - 1)) & 1u) {
        // Signed objects come sign-extended: the dictionary's type decides.
        const canopen::object_dictionary::slot* s = od_.find(m.index, m.sub);
        if (s != nullptr && canopen::type_is_signed(s->entry->type)) value -= std::int64_t{1} << m.bits;
      }
      if (m.index != 0) (void)write(m.index, m.sub, value);
    }
  }
  // Inputs: every cycle, so the master always reads the present values.
  const std::size_t in_bytes = inputs_checked_.enabled ? inputs_checked_.length : 0;
  if (in_bytes == 0 || in_bytes > buffer.size()) return;
  buffer.fill(0);
  unsigned bit = 0;
  for (const mapped& m : mapping(0x1C13)) {
    if (m.bits == 0 || m.bits > 64 || bit + m.bits > 8 * in_bytes) break;
    std::int64_t value = 0;
    if (m.index != 0) (void)read(m.index, m.sub, value);
    const auto raw = static_cast<std::uint64_t>(value);
    for (unsigned b = 0; b < m.bits; ++b, ++bit) {
      if ((raw >> b) & 1u) buffer[bit / 8] = static_cast<std::uint8_t>(buffer[bit / 8] | (1u << (bit % 8)));
    }
  }
  (void)esc_.write_buffer(sm_inputs, std::span<const std::uint8_t>(buffer.data(), in_bytes));
}

void drive_slave::step(std::uint32_t elapsed_us) {
  if (esc_.take_al_control_event()) handle_al_control();
  watch_sync_managers();
  serve_mailbox();
  exchange_process_data();
  device_.step(elapsed_us);
  esc_.advance(std::uint64_t{elapsed_us} * 1000);
  if (esc_.take_watchdog_event() && state_ == al_state::operational) {
    // The master stopped sending outputs: SAFE-OP with the watchdog's code, and the drive's
    // fieldbus connection is lost (0x6007).
    error_ = true;
    code_ = al_code::sync_manager_watchdog;
    enter(al_state::safe_operational);
  }
  serve_mailbox();  // a reply (or an emergency) the step produced goes out now
}

}  // namespace cia402::ethercat
