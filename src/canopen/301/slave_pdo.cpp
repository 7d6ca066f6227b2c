// The node's PDOs (slave.hpp): the SYNC-driven and event-driven TPDOs with the device's change
// reports, RPDOs, and the CiA 301 rules for their communication and mapping parameters.
#include "cia402/canopen/301/slave.hpp"

namespace cia402::canopen {
namespace {

constexpr std::uint32_t saturating_sub(std::uint32_t a, std::uint32_t b) noexcept {
  return a > b ? a - b : 0;
}

}  // namespace

// ---- PDO runtime --------------------------------------------------------------------------------

void slave::on_sync() {
  for (rpdo_state& r : rpdo_) {
    if (r.cfg.valid && r.pending) {
      r.pending = false;
      apply_rpdo(r, r.buffer.data());
    }
  }
  for (tpdo_state& t : tpdo_) {
    if (!t.cfg.valid || !synchronous_type(t.cfg.transmission_type)) continue;
    std::array<std::uint8_t, 8> data{};
    if (t.cfg.transmission_type == 0) {
      if (sample(t, data) && (!t.sent || data != t.last)) send_tpdo(t, data);
      continue;
    }
    if (++t.sync_count >= t.cfg.transmission_type) {
      t.sync_count = 0;
      if (sample(t, data)) send_tpdo(t, data);
    }
  }
}

void slave::apply_rpdo(rpdo_state& r, const std::uint8_t* data) {
  // `data` holds r.cfg.length bytes (the frame was checked against it); entries at any bit offset
  // after a BOOLEAN dummy.
  unsigned offset = 0;
  for (std::uint8_t i = 0; i < r.cfg.count; ++i) {
    const mapped_object& m = r.cfg.map[i];
    const unsigned at = offset;
    offset += m.bits;
    if (m.slot == nullptr) continue;  // a dummy entry: its bits are skipped
    const std::uint64_t raw = pdo_get_bits(data, r.cfg.length, at, m.bits);
    const std::int64_t v = type_is_signed(m.type) ? pdo_sign_extended(raw, m.bits) : static_cast<std::int64_t>(raw);
    // The slot bound when the mapping was configured, with the rules of an SDO write. A value the
    // object refuses is dropped: a PDO has no answer to carry an abort code.
    (void)write(*m.slot, v);
  }
}

bool slave::sample(const tpdo_state& t, std::array<std::uint8_t, 8>& out) {
  out.fill(0);  // a dummy entry's bits go out as zeros
  unsigned offset = 0;
  for (std::uint8_t i = 0; i < t.cfg.count; ++i) {
    const mapped_object& m = t.cfg.map[i];
    const unsigned at = offset;
    offset += m.bits;
    if (m.slot == nullptr) continue;
    std::int64_t v = 0;
    if (read(*m.slot, v) != sdo_abort::none) return false;
    pdo_put_bits(out.data(), out.size(), at, m.bits, static_cast<std::uint64_t>(v));
  }
  return true;
}

void slave::send_tpdo(tpdo_state& t, const std::array<std::uint8_t, 8>& data) {
  frame f;
  f.id = t.cfg.can_id;
  f.len = t.cfg.length;
  f.data = data;
  (void)out_->send(f);
  t.last = data;
  t.sent = true;
  t.event_pending = false;
  t.inhibit_left_us = t.cfg.inhibit_100us * 100u;
  t.event_left_us = t.cfg.event_timer_ms * 1000u;
}

std::uint32_t slave::process_tpdo_events(std::uint32_t elapsed_us) {
  std::uint32_t next = no_deadline;
  for (tpdo_state& t : tpdo_) {
    if (!t.cfg.valid || !event_type(t.cfg.transmission_type)) continue;
    t.inhibit_left_us = saturating_sub(t.inhibit_left_us, elapsed_us);
    if (t.cfg.event_timer_ms != 0) {
      t.event_left_us = saturating_sub(t.event_left_us, elapsed_us);
      if (t.event_left_us == 0) t.event_pending = true;
    }
    if (t.cfg.event_timer_ms != 0) next = earliest(next, t.event_left_us);
    const bool may_send = t.requested || t.event_pending || !t.sent;
    if (!may_send) continue;  // nothing it maps changed
    // Within the inhibit time nothing is read: the data is sampled when it may go, so the latest
    // values go out once.
    if (t.inhibit_left_us != 0) {
      next = earliest(next, t.inhibit_left_us);
      continue;
    }
    t.requested = false;
    std::array<std::uint8_t, 8> data{};
    if (!sample(t, data)) continue;
    if (t.event_pending || !t.sent || data != t.last) send_tpdo(t, data);
    if (t.cfg.event_timer_ms != 0) next = earliest(next, t.event_left_us);
  }
  return next;
}

// ---- PDO parameters and their rules -------------------------------------------------------------

pdo_config slave::resolve(std::uint16_t comm, std::uint16_t mapping) {
  pdo_config c;
  const auto cob_id = static_cast<std::uint32_t>(od_.number(comm, 1));
  c.valid = (cob_id & pdo_cob_invalid) == 0;
  c.can_id = cob_id & max_base_id;
  c.transmission_type = static_cast<std::uint8_t>(od_.number(comm, 2));
  c.inhibit_100us = static_cast<std::uint16_t>(od_.number(comm, 3));
  c.event_timer_ms = static_cast<std::uint16_t>(od_.number(comm, 5));
  c.count = static_cast<std::uint8_t>(od_.number(mapping, 0));
  unsigned bits = 0;
  for (std::uint8_t i = 0; i < c.count && i < c.map.size(); ++i) {
    const auto entry = static_cast<std::uint32_t>(od_.number(mapping, static_cast<std::uint8_t>(i + 1)));
    const unsigned dummy = pdo_padding_bits(pdo_mapping_entry::of_word(entry), pdo_padding::dummies);
    sdo_abort ignored = sdo_abort::none;
    dictionary::object_dictionary::slot* s =
        dummy != 0 ? nullptr : od_.find(map_index(entry), map_sub(entry), ignored);
    // Cannot happen (entries are checked when written): an entry that names nothing, or more than
    // a frame's 64 bits.
    if ((dummy == 0 && s == nullptr) || bits + map_bits(entry) > 64) {
      c.valid = false;
      c.count = i;
      break;
    }
    c.map[i] = mapped_object{map_index(entry), map_sub(entry), s != nullptr ? s->entry->type : data_type::unsigned8,
                             map_bits(entry), s};
    bits += map_bits(entry);
  }
  c.length = static_cast<std::uint8_t>((bits + 7) / 8);
  return c;
}

void slave::resolve_pdos() {
  for (int n = 0; n < pdo_count; ++n) {
    const auto i = static_cast<std::size_t>(n);
    rpdo_[i].cfg = resolve(static_cast<std::uint16_t>(0x1400 + n), static_cast<std::uint16_t>(0x1600 + n));
    rpdo_[i].pending = false;
    tpdo_[i].cfg = resolve(static_cast<std::uint16_t>(0x1800 + n), static_cast<std::uint16_t>(0x1A00 + n));
  }
}

sdo_abort slave::check_mapping_entry(bool receive, std::uint32_t entry) const {
  // A dummy entry (0x0001..0x0007) maps in either direction, with its type's length only.
  if (is_pdo_padding(map_index(entry), pdo_padding::dummies)) {
    const bool sound = pdo_padding_bits(pdo_mapping_entry::of_word(entry), pdo_padding::dummies) != 0;
    return sound ? sdo_abort::none : sdo_abort::cannot_map_to_pdo;
  }
  sdo_abort a = sdo_abort::none;
  const dictionary::object_dictionary::slot* s =
      const_cast<dictionary::object_dictionary&>(od_).find(map_index(entry), map_sub(entry), a);
  if (s == nullptr) return a;
  const dictionary::sub_entry& e = *s->entry;
  if (!e.pdo_mappable || (receive ? !dictionary::writable(e.acc) : !dictionary::readable(e.acc)) ||
      map_bits(entry) != type_size(e.type) * 8) {
    return sdo_abort::cannot_map_to_pdo;
  }
  return sdo_abort::none;
}

sdo_abort slave::write_pdo_parameter(dictionary::object_dictionary::slot& s, std::int64_t v) {
  const std::uint16_t index = s.object->index;
  const std::uint8_t sub = s.entry->sub;
  const bool receive = index < 0x1800;
  const int n = index & 0x3;
  const auto comm = static_cast<std::uint16_t>((receive ? 0x1400 : 0x1800) + n);
  const auto mapping = static_cast<std::uint16_t>((receive ? 0x1600 : 0x1A00) + n);
  const pdo_config& cfg = receive ? rpdo_[static_cast<std::size_t>(n)].cfg
                                  : tpdo_[static_cast<std::size_t>(n)].cfg;
  const auto u = static_cast<std::uint32_t>(v);

  if (index == comm) {
    switch (sub) {
      case 1: {
        const bool valid = (u & pdo_cob_invalid) == 0;
        const std::uint32_t can_id = u & max_base_id;
        // Bits 11..29 (29-bit identifiers are not offered) must be 0; a valid PDO keeps its
        // CAN-ID; an enabled PDO needs a mapping and an identifier it may use.
        if ((u & 0x3FFFF800u) != 0 || (valid && cfg.valid && can_id != cfg.can_id) ||
            (valid && cob_id_taken(can_id, comm)) || (valid && cfg.count == 0)) {
          return sdo_abort::invalid_value;
        }
        break;
      }
      case 2:
        if (u > 240 && u < 254) return sdo_abort::invalid_value;
        break;
      case 3:
        if (cfg.valid && u != cfg.inhibit_100us) return sdo_abort::invalid_value;
        break;
      default: break;
    }
    s.number = v;
  } else if (sub == 0) {
    if (cfg.valid) return sdo_abort::unsupported_access;
    unsigned bits = 0;
    for (std::uint8_t i = 1; i <= u; ++i) {
      const auto entry = static_cast<std::uint32_t>(od_.number(mapping, i));
      if (entry == 0) return sdo_abort::cannot_map_to_pdo;
      const sdo_abort a = check_mapping_entry(receive, entry);
      if (a != sdo_abort::none) return a;
      bits += map_bits(entry);
      if (bits > 64) return sdo_abort::pdo_length_exceeded;
    }
    s.number = v;
  } else {
    if (cfg.valid || od_.number(mapping, 0) != 0) return sdo_abort::unsupported_access;
    if (u != 0) {
      const sdo_abort a = check_mapping_entry(receive, u);
      if (a != sdo_abort::none) return a;
    }
    s.number = v;
  }

  const auto i = static_cast<std::size_t>(n);
  if (receive) {
    rpdo_[i].cfg = resolve(comm, mapping);
    rpdo_[i].pending = false;
  } else {
    tpdo_state& t = tpdo_[i];
    const bool was_valid = t.cfg.valid;
    t.cfg = resolve(comm, mapping);
    if (t.cfg.valid != was_valid || index != comm || sub != 3) {
      t.sent = false;
      t.sync_count = 0;
      t.event_left_us = t.cfg.event_timer_ms * 1000u;
    }
  }
  return sdo_abort::none;
}

// ---- the device's change reports ----------------------------------------------------------------

void slave::object_changed(std::uint16_t index, std::uint8_t sub) noexcept {
  for (tpdo_state& t : tpdo_) {
    if (!t.cfg.valid || !event_type(t.cfg.transmission_type)) continue;
    for (std::uint8_t i = 0; i < t.cfg.count; ++i) {
      const mapped_object& m = t.cfg.map[i];
      if (m.slot != nullptr && m.index == index && m.sub == sub) t.requested = true;
    }
  }
}

}  // namespace cia402::canopen
