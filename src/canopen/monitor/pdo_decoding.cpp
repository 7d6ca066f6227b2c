// PDOs: the maps of each node (from its description, then from the SDO traffic), and a PDO frame
// read by the map of the PDO whose COB-ID it carries (CiA 301 §7.2.2).
#include <algorithm>
#include <optional>

#include "node_state.hpp"

namespace cia402::canopen::monitor {
namespace {

bool communication_index(std::uint16_t index) {
  return (index >= 0x1400 && index <= 0x15FF) || (index >= 0x1800 && index <= 0x19FF);
}
bool mapping_index(std::uint16_t index) {
  return (index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF);
}
bool transmit(std::uint16_t communication) { return communication >= 0x1800; }

// The predefined connection set's COB-IDs (CiA 301 §7.3.5): PDOs 1..4 of a node; others have none.
std::uint32_t predefined_cob_id(std::uint16_t communication, std::uint8_t node_id) {
  const unsigned number = communication & 0x1FFu;
  if (number > 3) return pdo_cob_invalid;
  return (transmit(communication) ? cob::tpdo1 : cob::rpdo1) + 0x100u * number + node_id;
}

pdo_map& map_of(decoder::node_state& n, std::uint8_t node_id, std::uint16_t communication) {
  auto [it, fresh] = n.pdos.try_emplace(communication);
  if (fresh) it->second.cob_id = predefined_cob_id(communication, node_id);
  return it->second;
}

const dictionary::sub_entry* sub_of(const dictionary::object_entry& o, std::uint8_t sub) {
  for (const dictionary::sub_entry& e : o.subs) {
    if (e.sub == sub) return &e;
  }
  return nullptr;
}

// A COB-ID entry's value on node `node_id`: "$NODEID+X" summed with the overflow checked; nothing
// when the sum overflows or leaves the entry's type (a description written for another node, or a
// hostile one), so no PDO is taken to be on an identifier its description never meant.
std::optional<std::uint32_t> cob_id_of(const dictionary::sub_entry& e, std::uint8_t node_id) {
  std::int64_t v = e.default_value;
  if (e.plus_node_id && __builtin_add_overflow(v, std::int64_t{node_id}, &v)) return std::nullopt;
  if (v < type_min(e.type) || v > type_max(e.type) || v < 0 || v > 0xFFFFFFFF) return std::nullopt;
  return static_cast<std::uint32_t>(v);
}

std::string pdo_name(std::uint16_t communication) {
  return std::string(transmit(communication) ? "TPDO" : "RPDO") +
         std::to_string((communication & 0x1FFu) + 1);
}

}  // namespace

void load_pdos(decoder::node_state& n, std::uint8_t node_id) {
  n.pdos.clear();
  if (!n.table) return;
  for (const dictionary::object_entry& o : *n.table) {
    if (!communication_index(o.index)) continue;
    pdo_map m;
    if (const dictionary::sub_entry* e = sub_of(o, 1)) m.cob_id = cob_id_of(*e, node_id).value_or(pdo_cob_invalid);
    for (const dictionary::object_entry& map : *n.table) {
      if (map.index != o.index + 0x200) continue;
      if (const dictionary::sub_entry* count = sub_of(map, 0)) {
        m.count = static_cast<std::uint8_t>(std::clamp<std::int64_t>(count->default_value, 0, max_mapped_entries));
      }
      for (const dictionary::sub_entry& e : map.subs) {
        if (e.sub >= 1 && e.sub <= max_mapped_entries) {
          m.entries[e.sub - 1u] = static_cast<std::uint32_t>(e.default_value);
        }
      }
    }
    n.pdos[o.index] = m;
  }
}

void learn(decoder::node_state& n, std::uint8_t node_id, std::uint16_t index, std::uint8_t sub,
           std::span<const std::uint8_t> bytes) {
  if (bytes.empty() || bytes.size() > 8) return;
  const auto value = static_cast<std::uint32_t>(get_le(bytes.data(), static_cast<unsigned>(std::min<std::size_t>(bytes.size(), 4))));
  if (communication_index(index) && sub == 1) {
    map_of(n, node_id, index).cob_id = value;
  } else if (mapping_index(index)) {
    pdo_map& m = map_of(n, node_id, static_cast<std::uint16_t>(index - 0x200));
    if (sub == 0) {
      m.count = static_cast<std::uint8_t>(std::min<std::uint32_t>(value, max_mapped_entries));
    } else if (sub <= max_mapped_entries) {
      m.entries[sub - 1u] = value;
    }
  }
}

bool decoder::decode_pdo(decoded_frame& d) {
  const frame& f = d.raw;
  // The PDO whose COB-ID this is: among the nodes known so far, else the predefined connection
  // set's owner (function code 0x180..0x500, node-ID in the low 7 bits).
  node_state* owner = nullptr;
  std::uint8_t owner_id = 0;
  std::uint16_t communication = 0;
  const auto find_in = [&](std::uint8_t id, node_state& n) {
    for (const auto& [index, m] : n.pdos) {
      if ((m.cob_id & pdo_cob_invalid) == 0 && (m.cob_id & 0x20000000u) == 0 && (m.cob_id & 0x7FFu) == f.id) {
        owner = &n;
        owner_id = id;
        communication = index;
        return true;
      }
    }
    return false;
  };
  for (auto& [id, n] : nodes_) {
    if (find_in(id, *n)) break;
  }
  const auto predefined_node = static_cast<std::uint8_t>(f.id & 0x7Fu);
  if (owner == nullptr && f.id >= cob::tpdo1 && f.id <= 0x57F && valid_node_id(predefined_node) &&
      nodes_.count(predefined_node) == 0) {
    (void)find_in(predefined_node, node(predefined_node));
  }
  if (owner == nullptr) return false;

  const pdo_map& m = owner->pdos.at(communication);
  d.kind = frame_kind::pdo;
  d.node = owner_id;
  d.event = pdo_name(communication);
  if (m.count == 0) {
    d.text = d.event + " (nothing mapped) " + hex_bytes({f.data.data(), f.len});
    return true;
  }
  unsigned bits = 0;
  for (unsigned i = 0; i < m.count; ++i) bits += map_bits(m.entries[i]);
  if (bits > 64) {
    d.kind = frame_kind::unknown;
    d.text = d.event + ": its mapping as seen is longer than 64 bits";
    return true;
  }
  if (f.rtr || f.len * 8u < bits) {
    d.kind = frame_kind::unknown;
    d.text = d.event + " of " + std::to_string(f.len) + " bytes" + (f.rtr ? " (a remote request)" : "") +
             ", shorter than its mapping (" + std::to_string(bits) + " bits)";
    return true;
  }
  const std::uint64_t all = get_le(f.data.data(), f.len);
  unsigned offset = 0;
  std::string text = d.event;
  for (unsigned i = 0; i < m.count; ++i) {
    const std::uint32_t e = m.entries[i];
    const unsigned width = map_bits(e);
    const std::uint64_t raw = width == 0 ? 0 : (all >> offset) & (width == 64 ? ~0ull : (1ull << width) - 1);
    offset += width;
    // Entries 0x0001..0x0007 are dummies (CiA 301 §7.4.7.2): bits that carry nothing.
    if (map_index(e) < 0x0008 || width == 0) continue;
    std::uint8_t bytes[8]{};
    put_le(bytes, raw, 8);
    object_value v = read_value(owner->table.get(), map_index(e), map_sub(e),
                                std::span<const std::uint8_t>(bytes, (width + 7) / 8));
    text += (d.values.empty() ? " " : ", ") + describe(v);
    d.values.push_back(std::move(v));
  }
  d.text = std::move(text);
  return true;
}

}  // namespace cia402::canopen::monitor
