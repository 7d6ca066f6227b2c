// The decoder's dispatch by COB-ID (CiA 301 §7.3.5, the predefined connection set) and the
// services that fit in one frame: NMT, SYNC, TIME, EMCY, heartbeat.
#include "cia402/canopen/monitor/decoder.hpp"

#include <cstdio>

#include "cia402/canopen/301/nmt.hpp"
#include "cia402/error_codes.hpp"
#include "node_state.hpp"

namespace cia402::canopen::monitor {
namespace {

constexpr std::uint32_t cob_time = 0x100;

void unknown(decoded_frame& d, std::string why) {
  d.kind = frame_kind::unknown;
  d.event.clear();
  d.text = std::move(why);
}

std::string bytes_of(const frame& f) { return std::to_string(f.len) + (f.len == 1 ? " byte" : " bytes"); }

}  // namespace

const char* kind_name(frame_kind k) noexcept {
  switch (k) {
    case frame_kind::nmt: return "nmt";
    case frame_kind::sync: return "sync";
    case frame_kind::time: return "time";
    case frame_kind::emcy: return "emcy";
    case frame_kind::heartbeat: return "heartbeat";
    case frame_kind::sdo: return "sdo";
    case frame_kind::pdo: return "pdo";
    case frame_kind::unknown: return "unknown";
  }
  return "unknown";
}

decoder::decoder() = default;
decoder::~decoder() = default;

void decoder::describe_node(std::uint8_t node_id, std::vector<dictionary::object_entry> objects) {
  if (!valid_node_id(node_id)) return;
  described_[node_id] = std::make_shared<const std::vector<dictionary::object_entry>>(std::move(objects));
  reset_node(node(node_id), node_id);
}

void decoder::describe_other_nodes(std::vector<dictionary::object_entry> objects) {
  others_ = std::make_shared<const std::vector<dictionary::object_entry>>(std::move(objects));
  for (auto& [id, n] : nodes_) {
    if (described_.count(id) == 0) reset_node(*n, id);
  }
}

decoder::node_state& decoder::node(std::uint8_t id) {
  auto& slot = nodes_[id];
  if (!slot) {
    slot = std::make_unique<node_state>();
    reset_node(*slot, id);
  }
  return *slot;
}

void decoder::reset_node(node_state& n, std::uint8_t id) {
  const auto it = described_.find(id);
  n.table = it != described_.end() ? it->second : others_;
  load_pdos(n, id);
  n.sdo.restart(sdo_follow::phase::idle, 0, 0);
}

decoded_frame decoder::decode(const frame& f, std::uint64_t time_us) {
  decoded_frame d;
  d.time_us = time_us;
  d.raw = f;
  if (f.len > 8) {
    d.raw.len = 8;
    unknown(d, "a length of " + std::to_string(f.len) + " bytes: classic CAN carries at most 8");
    return d;
  }
  if (f.extended) {
    unknown(d, "a 29-bit identifier " + hex(f.id, 8) + ": CANopen uses 11-bit identifiers");
    return d;
  }
  const std::uint32_t id = f.id & max_base_id;
  const auto low = static_cast<std::uint8_t>(id & 0x7F);
  if (id == cob::nmt) {
    decode_nmt(d);
  } else if (id == cob::sync) {
    d.kind = frame_kind::sync;
    if (f.rtr || f.len > 1) unknown(d, "SYNC of " + bytes_of(f) + (f.rtr ? ", a remote request" : ""));
    else d.text = f.len == 0 ? "SYNC" : "SYNC counter " + std::to_string(f.data[0]);
  } else if (id > cob::emcy && id <= cob::emcy + max_node_id) {
    d.node = low;
    if (f.rtr || f.len < 3) {
      unknown(d, "EMCY of " + bytes_of(f) + ": CiA 301 sends 8");
      return d;
    }
    d.kind = frame_kind::emcy;
    d.code = static_cast<std::uint32_t>(get_le(f.data.data(), 2));
    d.code_text = error_code_text(static_cast<std::uint16_t>(d.code));
    d.event = d.code == 0 ? "reset" : "error";
    d.text = "EMCY " + hex(d.code, 4) + " " + d.code_text + ", error register " + hex(f.data[2], 2);
    bool specific = false;
    for (std::uint8_t i = 3; i < f.len; ++i) specific |= f.data[i] != 0;
    if (specific) d.text += ", manufacturer " + hex_bytes({f.data.data() + 3, f.len - 3u});
  } else if (id == cob_time) {
    if (f.rtr || f.len != 6) {
      unknown(d, "TIME of " + bytes_of(f) + ": CiA 301 sends 6");
      return d;
    }
    d.kind = frame_kind::time;
    const auto ms = static_cast<std::uint32_t>(get_le(f.data.data(), 4) & 0x0FFFFFFF);
    const auto days = static_cast<unsigned>(get_le(f.data.data() + 4, 2));
    char text[64];
    std::snprintf(text, sizeof text, "TIME %02u:%02u:%02u.%03u, day %u since 1984-01-01", ms / 3600000,
                  ms / 60000 % 60, ms / 1000 % 60, ms % 1000, days);
    d.text = text;
  } else if (id > cob::sdo_tx && id <= cob::sdo_tx + max_node_id) {
    decode_sdo(d, true);
  } else if (id > cob::sdo_rx && id <= cob::sdo_rx + max_node_id) {
    decode_sdo(d, false);
  } else if (id > cob::heartbeat && id <= cob::heartbeat + max_node_id) {
    decode_heartbeat(d);
  } else if (id == 0x7E4 || id == 0x7E5) {
    unknown(d, "LSS (CiA 305), not decoded");
  } else if (!decode_pdo(d)) {
    unknown(d, "no service or PDO known on " + hex(id, 3));
  }
  return d;
}

void decoder::decode_nmt(decoded_frame& d) {
  const frame& f = d.raw;
  if (f.rtr || f.len != 2) return unknown(d, "NMT of " + bytes_of(f) + ": CiA 301 sends 2");
  const std::uint8_t target = f.data[1];
  if (target > max_node_id) return unknown(d, "NMT for node " + std::to_string(target) + ", not 0..127");
  const char* what = nullptr;
  switch (static_cast<nmt_command>(f.data[0])) {
    case nmt_command::start: what = "start"; break;
    case nmt_command::stop: what = "stop"; break;
    case nmt_command::enter_pre_operational: what = "pre-operational"; break;
    case nmt_command::reset_node: what = "reset-node"; break;
    case nmt_command::reset_communication: what = "reset-communication"; break;
  }
  if (what == nullptr) return unknown(d, "NMT command " + hex(f.data[0], 2) + " is none of CiA 301's");
  d.kind = frame_kind::nmt;
  d.node = target;
  d.code = f.data[0];
  d.event = what;
  d.text = std::string("NMT ") + what + (target == 0 ? ", every node" : "");
  const bool reset = f.data[0] == static_cast<std::uint8_t>(nmt_command::reset_node) ||
                     f.data[0] == static_cast<std::uint8_t>(nmt_command::reset_communication);
  if (!reset) return;
  // Both resets bring the communication objects, and so the PDO maps, back to their defaults.
  if (target != 0) return reset_node(node(target), target);
  for (auto& [id, n] : nodes_) reset_node(*n, id);
}

void decoder::decode_heartbeat(decoded_frame& d) {
  const frame& f = d.raw;
  const auto id = static_cast<std::uint8_t>(f.id & 0x7F);
  d.node = id;
  if (f.rtr) {
    d.kind = frame_kind::heartbeat;
    d.event = "guarding-request";
    d.text = "node guarding request";
    return;
  }
  if (f.len != 1) return unknown(d, "heartbeat of " + bytes_of(f) + ": CiA 301 sends 1");
  const auto state = static_cast<std::uint8_t>(f.data[0] & 0x7F);  // bit 7: node guarding's toggle
  const char* event = nullptr;
  switch (static_cast<nmt_state>(state)) {
    case nmt_state::initialising: event = "boot-up"; break;
    case nmt_state::stopped: event = "stopped"; break;
    case nmt_state::operational: event = "operational"; break;
    case nmt_state::pre_operational: event = "pre-operational"; break;
  }
  if (event == nullptr) return unknown(d, "heartbeat with state " + hex(f.data[0], 2) + ", no NMT state");
  d.kind = frame_kind::heartbeat;
  d.code = state;
  d.code_text = nmt_state_name(static_cast<nmt_state>(state));
  d.event = event;
  if (state == 0) {
    d.text = "boot-up";
    reset_node(node(id), id);  // a node that boots has its defaults again
    return;
  }
  d.text = std::string("heartbeat ") + d.code_text;
}

}  // namespace cia402::canopen::monitor
