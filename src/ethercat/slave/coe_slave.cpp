// The CoE slave's application: the AL state machine, the mailboxes, the dictionary's rules for the
// process data configuration, and the cycle. The process data itself: process_data.cpp.
#include "cia402/ethercat/slave/coe_slave.hpp"

#include <algorithm>

#include "cia402/dictionary/error_history.hpp"

namespace cia402::ethercat {
namespace {

bool mapping_object(std::uint16_t index) noexcept {
  return (index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF);
}
bool assignment_object(std::uint16_t index) noexcept { return index == 0x1C12 || index == 0x1C13; }

constexpr std::uint8_t al_error_flag = 0x10;
constexpr std::uint8_t al_acknowledge = 0x10;
constexpr int sm_outputs = 2;
constexpr int sm_inputs = 3;

}  // namespace

coe_slave::coe_slave(dictionary::device& d, const coe_slave_config& c)
    : dictionary_access(od_),
      device_(&d),
      od_(coe_objects(c), 0),
      description_(coe_slave_description(c)),
      esc_(sii_image(description_)),
      coe_(*this, od_, mailbox_size) {
  device_->attach(this);
  esc_.set_al_status(static_cast<std::uint8_t>(al_state::init), al_code::none);
  // The most entries two assigned PDOs can hold: bound on the way to SAFE-OP without allocating.
  outputs_.reserve(2 * max_pdo_entries);
  inputs_.reserve(2 * max_pdo_entries);
  mailbox_.reserve(mailbox_size);
}

coe_slave::~coe_slave() { device_->attach(nullptr); }

// ---- the dictionary's rules -------------------------------------------------------------------

sdo_abort coe_slave::read_value(const dictionary::object_dictionary::slot& s, std::int64_t& v) {
  if (s.entry->where == dictionary::backing::device) return device_->read(s.object->index, s.entry->sub, v);
  v = s.number;
  return sdo_abort::none;
}

bool coe_slave::entry_mappable(std::uint16_t mapping, std::uint32_t m) const {
  // Padding (an index-0 gap of 1..64 bits or a CiA 301 dummy of its type's length) maps either way.
  if (is_pdo_padding(static_cast<std::uint16_t>(m >> 16), pdo_padding::dummies_and_gaps)) {
    return pdo_padding_bits(pdo_mapping_entry::of_word(m), pdo_padding::dummies_and_gaps) != 0;
  }
  // Else an entry names an object of the dictionary, mappable in this direction, of its own size.
  const dictionary::object_dictionary::slot* target = od_.find(static_cast<std::uint16_t>(m >> 16),
                                                              static_cast<std::uint8_t>(m >> 8));
  const bool rx = mapping < 0x1A00;
  return target != nullptr && target->entry->pdo_mappable &&
         (rx ? dictionary::writable(target->entry->acc) : !dictionary::writable(target->entry->acc)) &&
         type_size(target->entry->type) * 8 == (m & 0xFFu) && (m & 0xFFu) != 0;
}

sdo_abort coe_slave::write_pdo_configuration(dictionary::object_dictionary::slot& s, std::int64_t v) {
  const std::uint16_t index = s.object->index;
  const std::uint8_t sub = s.entry->sub;
  // The process data are configured in PRE-OP only.
  if (state_ != al_state::pre_operational) return sdo_abort::cannot_store_in_present_state;
  if (mapping_object(index) && sub != 0 && v != 0 && !entry_mappable(index, static_cast<std::uint32_t>(v))) {
    return sdo_abort::cannot_map_to_pdo;
  }
  if (mapping_object(index) && sub == 0) {
    // The entries it counts in are checked again: one left 0 (or never written) maps nothing of no
    // length, which the process data cannot carry.
    unsigned bits = 0;
    for (std::int64_t k = 1; k <= v; ++k) {
      const auto m = static_cast<std::uint32_t>(od_.number(index, static_cast<std::uint8_t>(k)));
      if (!entry_mappable(index, m)) return sdo_abort::cannot_map_to_pdo;
      bits += m & 0xFFu;
    }
    if ((bits + 7) / 8 > max_process_data) return sdo_abort::pdo_length_exceeded;
  }
  if (assignment_object(index) && sub != 0 && v != 0) {
    // A PDO this slave has, of the assignment's direction.
    const std::uint16_t first = index == 0x1C12 ? 0x1600 : 0x1A00;
    if (v != first && v != first + 1) return sdo_abort::invalid_value;
  }
  s.number = v;
  return sdo_abort::none;
}

sdo_abort coe_slave::write_sync_mode(dictionary::object_dictionary::slot& s, std::int64_t v) {
  // The synchronisation is chosen in PRE-OP, as the process data are.
  if (state_ != al_state::pre_operational) return sdo_abort::cannot_store_in_present_state;
  if (s.entry->sub == sync_parameter::mode) {
    const bool outputs = s.object->index == sync_parameter::outputs;
    const bool offered = v == sync_mode::free_run || v == sync_mode::sm_synchronous || v == sync_mode::dc_sync0 ||
                         (!outputs && v == sync_mode::sm2_synchronous);
    if (!offered) return sdo_abort::invalid_value;
  }
  s.number = v;
  return sdo_abort::none;
}

sdo_abort coe_slave::write_value(dictionary::object_dictionary::slot& s, std::int64_t v) {
  const std::uint16_t index = s.object->index;
  if (s.entry->where == dictionary::backing::device) return device_->write(index, s.entry->sub, v);
  if (index == sync_parameter::outputs || index == sync_parameter::inputs) return write_sync_mode(s, v);
  if (mapping_object(index) || assignment_object(index)) return write_pdo_configuration(s, v);
  if (index == dictionary::error_history_index) return dictionary::write_error_history(od_, s.entry->sub, v);
  s.number = v;
  return sdo_abort::none;
}

void coe_slave::error_changed(std::uint16_t code) noexcept {
  std::int64_t reg = 0;
  (void)read(0x1001, 0, reg);
  const std::array<std::uint8_t, 5> field = device_->manufacturer_error_field();
  // 0x1003 keeps what the emergencies said, as the CANopen node does (dictionary/error_history.hpp).
  dictionary::record_error(od_, code, static_cast<std::uint16_t>(field[0] | (field[1] << 8)));
  coe_.emergency(code, static_cast<std::uint8_t>(reg), field);
}

// ---- the AL state machine ---------------------------------------------------------------------

void coe_slave::refuse(std::uint16_t code) {
  error_ = true;
  code_ = code;
  esc_.set_al_status(static_cast<std::uint8_t>(static_cast<std::uint8_t>(state_) | al_error_flag), code_);
}

void coe_slave::enter(al_state s) {
  const al_state before = state_;
  state_ = s;
  if (s == al_state::init) {
    coe_.reset();
    in_send_mailbox_.clear();
    last_read_.clear();
    withdrawn_.clear();
    repeat_in_send_mailbox_ = false;
    last_read_in_send_mailbox_ = false;
  }
  // Leaving OP the master no longer commands the device; entering it, it does again (a CiA 402
  // drive's 0x6007, S10).
  if (before == al_state::operational && s != al_state::operational) device_->set_connection_lost(true);
  if (s == al_state::operational) device_->set_connection_lost(false);
  esc_.set_al_status(static_cast<std::uint8_t>(static_cast<std::uint8_t>(state_) | (error_ ? al_error_flag : 0)),
                     error_ ? code_ : al_code::none);
}

bool coe_slave::mailbox_sync_managers_sound() const {
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

bool coe_slave::process_data_sync_manager_sound(int n, std::uint16_t bytes, bool outputs) const {
  const esc::sync_manager sm = esc_.sm(n);
  if (bytes == 0) return !sm.enabled || sm.length == 0;
  return sm.enabled && !sm.mailbox() && sm.ecat_writes() == outputs && sm.length == bytes &&
         std::uint32_t{sm.start} + sm.length <= esc::memory_size && sm.start >= reg::process_ram;
}

bool coe_slave::to_safe_operational() {
  // Every assigned entry bound to its object, then the sync managers as long as the PDOs they carry.
  if (!bind(0x1C12, outputs_, output_bits_)) {
    refuse(al_code::invalid_output_mapping);
    return false;
  }
  if (!bind(0x1C13, inputs_, input_bits_)) {
    refuse(al_code::invalid_input_mapping);
    return false;
  }
  if (!process_data_sync_manager_sound(sm_outputs, static_cast<std::uint16_t>((output_bits_ + 7) / 8), true)) {
    refuse(al_code::invalid_output_configuration);
    return false;
  }
  if (!process_data_sync_manager_sound(sm_inputs, static_cast<std::uint16_t>((input_bits_ + 7) / 8), false)) {
    refuse(al_code::invalid_input_configuration);
    return false;
  }
  if (!choose_sync_mode()) return false;
  outputs_checked_ = esc_.sm(sm_outputs);
  inputs_checked_ = esc_.sm(sm_inputs);
  return true;
}

bool coe_slave::choose_sync_mode() {
  using namespace sync_parameter;
  const bool dc_asked = od_.number(outputs, mode) == sync_mode::dc_sync0 ||
                        od_.number(inputs, mode) == sync_mode::dc_sync0;
  const std::uint32_t cycle = esc_.read32(reg::dc_sync0_cycle_time);
  if (!esc_.sync0_active()) {
    // DC SYNC0 asked for by CoE, but the master did not start SYNC0.
    if (dc_asked) {
      refuse(al_code::invalid_dc_sync_configuration);
      return false;
    }
    dc_sync0_ = false;
  } else {
    // SYNC0 activated by the master (as SOEM's ec_dcsync0 does, writing no CoE object): DC mode.
    if (cycle == 0) {
      refuse(al_code::invalid_dc_sync_configuration);  // one pulse is not a cycle to run on
      return false;
    }
    if (cycle < od_.number(outputs, minimum_cycle_time)) {
      refuse(al_code::invalid_dc_sync_cycle_time);
      return false;
    }
    dc_sync0_ = true;
  }
  for (const std::uint16_t index : {outputs, inputs}) {
    if (dc_sync0_) {
      od_.set_number(index, mode, sync_mode::dc_sync0);
      od_.set_number(index, cycle_time, cycle);
    }
    od_.set_number(index, sync0_cycle_time, dc_sync0_ ? cycle : 0);
    od_.set_number(index, sync_error_count, 0);
  }
  outputs_waiting_ = false;
  pulse_seen_ = false;
  return true;
}

void coe_slave::handle_al_control() {
  const std::uint16_t control = esc_.read16(reg::al_control);
  const unsigned wanted = control & 0x0Fu;
  if (error_) {
    // ETG.1000.6 §6.4.1.4, as the ETG's slave code does it: while the error flag is up, a request
    // without the acknowledge (0x0120 bit 4) changes nothing, but INIT, which acknowledges by itself.
    if (!(control & al_acknowledge) && wanted != 1) return;
    error_ = false;
    code_ = al_code::none;
  }
  const auto current = static_cast<unsigned>(state_);
  op_waits_for_pulse_ = false;  // a new request replaces one that waited
  switch (wanted) {
    case 1: enter(al_state::init); return;
    case 3: refuse(al_code::bootstrap_not_supported); return;
    case 2:
      if (state_ == al_state::init && !mailbox_sync_managers_sound()) return refuse(al_code::invalid_mailbox_configuration);
      enter(al_state::pre_operational);
      return;
    case 4:
      if (state_ == al_state::init) return refuse(al_code::invalid_state_change);
      if (state_ == al_state::pre_operational && !to_safe_operational()) return;
      enter(al_state::safe_operational);
      return;
    case 8:
      if (current < static_cast<unsigned>(al_state::safe_operational)) return refuse(al_code::invalid_state_change);
      if (state_ == al_state::safe_operational && dc_sync0_ && !pulse_seen_) {
        op_waits_for_pulse_ = true;  // outputs_in() enters OP on the pulse
        op_wait_us_ = 0;
        return;
      }
      enter(al_state::operational);
      return;
    default: refuse(al_code::unknown_state); return;
  }
}

void coe_slave::watch_sync_managers() {
  // A sync manager the master changes after the state that checked it takes the slave back to where
  // it is checked again, with the code that says which (as the ETG's slave code does): the mailbox
  // to INIT, the process data to PRE-OP. Until then nothing is read from it or written to it.
  const auto same = [](const esc::sync_manager& a, const esc::sync_manager& b) {
    return a.start == b.start && a.length == b.length && a.control == b.control && a.enabled == b.enabled;
  };
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

void coe_slave::send_reply(std::vector<std::uint8_t>& reply) {
  if (esc_.write_mailbox(1, reply)) {
    in_send_mailbox_.swap(reply);
    repeat_in_send_mailbox_ = false;
    last_read_in_send_mailbox_ = false;
  }
  reply.clear();
}

void coe_slave::repeat_last_reply() {
  if (state_ != al_state::init && esc_.mailbox_full(1) && last_read_in_send_mailbox_) {
    esc_.acknowledge_repeat(1);  // what a repeat puts back is there already
    return;
  }
  if (state_ != al_state::init && esc_.mailbox_full(1)) {
    // A newer reply waits unread: taken back (SM1 deactivated and activated again by its PDI
    // control, which empties it) to go out after the one the master lost.
    const auto pdi_control = static_cast<std::uint16_t>(reg::sync_manager0 + 8 + reg::sm_pdi_control);
    const std::uint8_t control = esc_.read8(pdi_control);
    esc_.write8(pdi_control, static_cast<std::uint8_t>(control | 1u));
    esc_.write8(pdi_control, control);
    withdrawn_.swap(in_send_mailbox_);
    in_send_mailbox_.clear();
  }
  if (state_ != al_state::init && !last_read_.empty() && esc_.write_mailbox(1, last_read_)) {
    in_send_mailbox_ = last_read_;
    repeat_in_send_mailbox_ = true;
  }
  esc_.acknowledge_repeat(1);
}

void coe_slave::send_next_as_last_read() {
  std::vector<std::uint8_t> next;
  if (!withdrawn_.empty()) {
    next.swap(withdrawn_);
  } else if (coe_.has_reply()) {
    next = coe_.take_reply();
  } else {
    return;
  }
  if (!esc_.write_mailbox(1, next)) {
    withdrawn_.swap(next);  // goes out when SM1 takes it
    return;
  }
  last_read_ = next;
  in_send_mailbox_.swap(next);
  last_read_in_send_mailbox_ = true;
}

void coe_slave::serve_mailbox() {
  // The master read SM1 whole: what it held is what a repeat request puts back.
  if (esc_.take_sync_manager_event(1) && !esc_.mailbox_full(1) && !in_send_mailbox_.empty()) {
    const bool read_a_repeat = repeat_in_send_mailbox_;
    repeat_in_send_mailbox_ = false;
    last_read_in_send_mailbox_ = false;
    last_read_.swap(in_send_mailbox_);
    in_send_mailbox_.clear();
    // As SOES does: once a repeated reply is read, the reply waiting behind it goes out at once and
    // is what a further repeat request puts back. SOEM 1.4.0 asks for a repeat after every emergency
    // it reads; without this each repeat put the emergency back and the reply never left.
    if (read_a_repeat && state_ != al_state::init) send_next_as_last_read();
  }
  if (esc_.repeat_requested(1)) repeat_last_reply();
  if (state_ == al_state::init) return;
  if (esc_.read_mailbox(0, mailbox_)) coe_.on_mailbox(mailbox_);
  if (esc_.mailbox_full(1)) return;
  if (!withdrawn_.empty()) {
    send_reply(withdrawn_);
  } else if (coe_.has_reply()) {
    std::vector<std::uint8_t> reply = coe_.take_reply();
    send_reply(reply);
  }
}

void coe_slave::step(std::uint32_t elapsed_us) {
  if (esc_.take_al_control_event()) handle_al_control();
  watch_sync_managers();
  serve_mailbox();
  // As SOES runs its application: the outputs in, the device's step on them, then the inputs out,
  // so the inputs a master reads next answer the outputs it wrote before this step (no cycle more).
  outputs_in();
  if (op_waits_for_pulse_) {
    op_wait_us_ = op_wait_us_ + elapsed_us;
    if (op_wait_us_ >= first_pulse_wait_us) {
      op_waits_for_pulse_ = false;
      refuse(al_code::no_sync);
    }
  }
  device_->step(elapsed_us);
  inputs_out();
  if (!clock_outside_) esc_.advance(std::uint64_t{elapsed_us} * 1000);
  if (esc_.take_watchdog_event() && state_ == al_state::operational) {
    // The master stopped sending outputs: SAFE-OP with the watchdog's code, and the device's
    // fieldbus connection is lost.
    error_ = true;
    code_ = al_code::sync_manager_watchdog;
    enter(al_state::safe_operational);
  }
  serve_mailbox();  // a reply (or an emergency) the step produced goes out now
}

}  // namespace cia402::ethercat
