#include "cia402/canopen/301/slave.hpp"

#include <algorithm>

#include "cia402/dictionary/error_history.hpp"


namespace cia402::canopen {
namespace {

bool is_pdo_parameter(std::uint16_t index) noexcept {
  const std::uint16_t base = index & 0xFFFC;
  return base == 0x1400 || base == 0x1600 || base == 0x1800 || base == 0x1A00;
}

}  // namespace

slave::slave(dictionary::device& d, channel& out, const slave_config& config)
    : dictionary::dictionary_access(od_),
      device_(&d),
      out_(&out),
      config_(config),
      od_(node_objects(config), config.node_id),
      sdo_(*this, out, config.node_id, config.sdo_timeout_us) {
  device_->attach(this);
  consumer_.on_change = [this](std::uint8_t, bool) {
    tell_connection();
    set_node_error(node_error::heartbeat_lost, consumer_.any_lost());
  };
  boot();
}

slave::~slave() { device_->attach(nullptr); }

// ---- NMT ------------------------------------------------------------------------------------

void slave::boot() {
  sdo_.reset();
  sync_id_ = static_cast<std::uint32_t>(od_.number(0x1005, 0)) & max_base_id;
  resolve_pdos();
  configure_consumer();
  producer_.configure(static_cast<std::uint16_t>(od_.number(0x1017, 0)));
  state_ = nmt_state::initialising;
  (void)out_->send(heartbeat_frame(config_.node_id, nmt_state::initialising));
  enter(nmt_state::pre_operational);
}

void slave::enter(nmt_state s) {
  if (s != nmt_state::operational) {
    for (rpdo_state& r : rpdo_) r.pending = false;
  }
  if (s != state_) {
    for (tpdo_state& t : tpdo_) {
      t.sent = false;  // an event TPDO sends its data on entering OPERATIONAL
      t.sync_count = 0;
      t.inhibit_left_us = 0;
      t.event_left_us = t.cfg.event_timer_ms * 1000u;
    }
  }
  if (s == nmt_state::stopped) sdo_.reset();
  state_ = s;
  tell_connection();
}

void slave::tell_connection() {
  // CiA 402-2 §6.2.1 (0x6007): a heartbeat or guarding loss and the NMT state STOPPED are the
  // fieldbus going away; PRE-OPERATIONAL is not (SDO still works, the master is there). The device
  // decides what a loss does to it (drive402::sim_device: only to an enabled drive).
  device_->set_connection_lost(consumer_.any_lost() || state_ == nmt_state::stopped);
}

void slave::on_nmt(const frame& f) {
  if (f.len < 2) return;
  if (f.data[1] != 0 && f.data[1] != config_.node_id) return;
  switch (static_cast<nmt_command>(f.data[0])) {
    case nmt_command::start: enter(nmt_state::operational); break;
    case nmt_command::stop: enter(nmt_state::stopped); break;
    case nmt_command::enter_pre_operational: enter(nmt_state::pre_operational); break;
    case nmt_command::reset_node:
      device_->reset();
      od_.reset(0x0000, 0xFFFF);
      drive_error_ = 0;
      pdo_length_error_ = false;
      boot();
      break;
    case nmt_command::reset_communication:
      od_.reset(0x1000, 0x1FFF);
      pdo_length_error_ = false;
      boot();
      break;
  }
}

// ---- frames and time -------------------------------------------------------------------------

void slave::on_frame(const frame& f) {
  if (f.extended || f.rtr) return;  // no 29-bit COB-IDs, no RTR (node guarding is not offered)
  if (f.id == cob::nmt) return on_nmt(f);
  if (consumer_.on_frame(f)) return;
  if (state_ == nmt_state::stopped) return;
  if (f.id == sync_id_) {
    if (state_ == nmt_state::operational) on_sync();
    return;
  }
  if (f.id == cob::sdo_rx + config_.node_id) return sdo_.on_request(f);
  if (state_ != nmt_state::operational) return;
  for (rpdo_state& r : rpdo_) {
    if (!r.cfg.valid || r.cfg.can_id != f.id) continue;
    if (f.len < r.cfg.length) {
      set_node_error(node_error::pdo_length, true);
      return;
    }
    set_node_error(node_error::pdo_length, false);
    if (synchronous_type(r.cfg.transmission_type)) {
      r.buffer = f.data;
      r.pending = true;
    } else {
      apply_rpdo(r, f.data.data());
    }
  }
}

std::uint32_t slave::poll(channel& in, std::uint32_t elapsed_us) {
  frame f;
  while (in.receive(f)) on_frame(f);
  return process(elapsed_us);
}

std::uint32_t slave::process(std::uint32_t elapsed_us) {
  std::uint32_t next = device_->step(elapsed_us);
  next = earliest(next, producer_.process(elapsed_us, *out_, config_.node_id, state_));
  next = earliest(next, consumer_.process(elapsed_us));
  if (state_ != nmt_state::stopped) next = earliest(next, sdo_.process(elapsed_us));
  if (state_ == nmt_state::operational) next = earliest(next, process_tpdo_events(elapsed_us));
  return next;
}

// ---- object access -----------------------------------------------------------------------------

void slave::configure_consumer() {
  std::vector<heartbeat_consumer::entry> entries;
  for (int i = 1; i <= heartbeat_consumers; ++i) {
    const auto v = static_cast<std::uint32_t>(od_.number(0x1016, static_cast<std::uint8_t>(i)));
    entries.push_back({static_cast<std::uint8_t>((v >> 16) & 0x7F), static_cast<std::uint16_t>(v)});
  }
  consumer_.configure(entries);
}

sdo_abort slave::upload(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t>& data) noexcept {
  if (index == 0x1021 && sub == 0 && config_.store_eds && config_.eds_text) {
    if (eds_.empty()) eds_ = config_.eds_text();
    data.assign(eds_.begin(), eds_.end());
    return sdo_abort::none;
  }
  return dictionary::dictionary_access::upload(index, sub, data);
}

sdo_abort slave::read_value(const dictionary::object_dictionary::slot& s, std::int64_t& v) {
  if (s.entry->where == dictionary::backing::device) {
    const sdo_abort a = device_->read(s.object->index, s.entry->sub, v);
    if (a == sdo_abort::none && s.object->index == 0x1001 && (heartbeat_error_ || pdo_length_error_)) {
      v |= 0x11;  // generic + communication error (CiA 301 §7.5.2.2)
    }
    return a;
  }
  v = s.number;
  return sdo_abort::none;
}

sdo_abort slave::write_value(dictionary::object_dictionary::slot& s, std::int64_t v) {
  const std::uint16_t index = s.object->index;
  const std::uint8_t sub = s.entry->sub;
  if (s.entry->where == dictionary::backing::device) {
    const sdo_abort a = device_->write(index, sub, v);
    if (a == sdo_abort::none) object_changed(index, sub);  // a TPDO mapping it sends it
    return a;
  }
  if (is_pdo_parameter(index)) return write_pdo_parameter(s, v);
  const auto u = static_cast<std::uint32_t>(v);
  switch (index) {
    case dictionary::error_history_index: return dictionary::write_error_history(od_, sub, v);
    case 0x1005:
      // This node consumes SYNC only (bit 30 would make it the producer); 11-bit identifiers; an
      // identifier of its own services taken as SYNC would silence them.
      if ((u & 0x7FFFF800u) != 0 || cob_id_taken(u & max_base_id, 0x1005)) {
        return sdo_abort::invalid_value;
      }
      s.number = v;
      sync_id_ = u & max_base_id;
      return sdo_abort::none;
    case 0x1016: {
      const std::uint32_t node = (u >> 16) & 0xFF;
      const std::uint32_t time = u & 0xFFFF;
      if ((u >> 24) != 0 || (time != 0 && (node == 0 || node > max_node_id))) {
        return sdo_abort::invalid_value;
      }
      // Two entries watching one node cannot both hold: CiA 301 answers 0x06040043.
      for (int i = 1; i <= heartbeat_consumers; ++i) {
        if (i == sub) continue;
        const auto other = static_cast<std::uint32_t>(od_.number(0x1016, static_cast<std::uint8_t>(i)));
        if (time != 0 && (other & 0xFFFF) != 0 && ((other >> 16) & 0xFF) == node) {
          return sdo_abort::general_parameter_incompatibility;
        }
      }
      s.number = v;
      configure_consumer();
      return sdo_abort::none;
    }
    case 0x1017:
      s.number = v;
      producer_.configure(static_cast<std::uint16_t>(u));
      return sdo_abort::none;
    default:
      s.number = v;
      return sdo_abort::none;
  }
}

bool slave::cob_id_taken(std::uint32_t id, std::uint16_t writing) const {
  // NMT, SDO, heartbeat, LSS and the other identifiers CiA 301 §7.3.5 keeps from configuration.
  if (restricted_can_id(id)) return true;
  if (writing != 0x1005 && id == sync_id_) return true;
  if (writing != 0x1014 && od_.find(0x1014, 0) != nullptr &&
      id == (static_cast<std::uint32_t>(od_.number(0x1014, 0)) & max_base_id)) {
    return true;
  }
  // Every PDO in use, receive or transmit, but the one being written.
  for (const std::uint16_t base : {std::uint16_t{0x1400}, std::uint16_t{0x1800}}) {
    for (std::uint16_t n = 0; n < 4; ++n) {
      const auto comm = static_cast<std::uint16_t>(base + n);
      if (comm == writing || od_.find(comm, 1) == nullptr) continue;
      const auto other = static_cast<std::uint32_t>(od_.number(comm, 1));
      if ((other & pdo_cob_invalid) == 0 && (other & max_base_id) == id) return true;
    }
  }
  return false;
}

// ---- EMCY (the device reports its error, device.hpp) -------------------------------------------------------------------------------------

void slave::error_changed(std::uint16_t code) noexcept {
  if (code == drive_error_) return;
  drive_error_ = code;
  if (code != 0) {
    note_error(code);
    send_emcy(code);
  } else if (!heartbeat_error_ && !pdo_length_error_) {
    send_emcy(0);
  }
}

void slave::set_node_error(std::uint16_t code, bool active) {
  bool& flag = code == node_error::heartbeat_lost ? heartbeat_error_ : pdo_length_error_;
  if (flag == active) return;
  flag = active;
  if (active) {
    note_error(code);
    send_emcy(code);
  } else if (drive_error_ == 0 && !heartbeat_error_ && !pdo_length_error_) {
    send_emcy(0);
  }
}

void slave::note_error(std::uint16_t code) noexcept {
  // 0x1003 keeps every error the node signals, also one that arises in STOPPED where no EMCY goes:
  // the code, and the first two bytes of the EMCY's manufacturer field (a drive: its status word).
  const std::array<std::uint8_t, 5> field = device_->manufacturer_error_field();
  dictionary::record_error(od_, code, static_cast<std::uint16_t>(field[0] | (field[1] << 8)));
}

void slave::send_emcy(std::uint16_t code) {
  if (state_ == nmt_state::stopped || state_ == nmt_state::initialising) return;
  if (code == 0 && !any_error_reported_) return;  // nothing to reset
  any_error_reported_ = code != 0;
  std::int64_t reg = 0;
  std::array<std::uint8_t, 5> field{};
  if (code != 0) {
    (void)read(0x1001, 0, reg);
    field = device_->manufacturer_error_field();
  }
  frame f;
  f.id = static_cast<std::uint32_t>(od_.number(0x1014, 0)) & max_base_id;
  f.len = 8;
  put_le(&f.data[0], code, 2);
  f.data[2] = static_cast<std::uint8_t>(reg);
  for (std::size_t i = 0; i < field.size(); ++i) f.data[3 + i] = field[i];
  (void)out_->send(f);
}

}  // namespace cia402::canopen
