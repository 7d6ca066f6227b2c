#include "cia402/canopen/301/nmt.hpp"

namespace cia402::canopen {

const char* nmt_state_name(nmt_state s) noexcept {
  switch (s) {
    case nmt_state::initialising: return "INITIALISING";
    case nmt_state::stopped: return "STOPPED";
    case nmt_state::operational: return "OPERATIONAL";
    case nmt_state::pre_operational: return "PRE-OPERATIONAL";
  }
  return "UNKNOWN";
}

void heartbeat_consumer::configure(const std::vector<entry>& entries) {
  std::vector<watch> next;
  for (const entry& e : entries) {
    if (e.node_id == 0 || e.time_ms == 0) continue;
    // A node watched before keeps its lost state, so reconfiguring does not hide a loss.
    watch w;
    w.e = e;
    for (const watch& old : watches_) {
      if (old.e.node_id == e.node_id) {
        w.active = old.active;
        w.is_lost = old.is_lost;
        w.state = old.state;
      }
    }
    w.left_us = e.time_ms * 1000u;
    next.push_back(w);
  }
  std::vector<std::uint8_t> recovered;
  for (const watch& old : watches_) {
    bool kept = false;
    for (const watch& w : next) kept = kept || w.e.node_id == old.e.node_id;
    if (!kept && old.is_lost) recovered.push_back(old.e.node_id);
  }
  watches_ = std::move(next);
  // A node no longer watched is no longer lost; report it after the list is in place.
  for (std::uint8_t node : recovered) {
    if (on_change) on_change(node, false);
  }
}

bool heartbeat_consumer::on_frame(const frame& f) {
  if (f.extended || f.rtr || f.len < 1 || (f.id & 0x780) != cob::heartbeat) return false;
  const auto node = static_cast<std::uint8_t>(f.id & 0x7F);
  bool watched = false;
  for (watch& w : watches_) {
    if (w.e.node_id != node) continue;
    watched = true;
    w.active = true;
    w.left_us = w.e.time_ms * 1000u;
    w.state = static_cast<nmt_state>(f.data[0] & 0x7F);
    if (w.is_lost) {
      w.is_lost = false;
      if (on_change) on_change(node, false);
    }
  }
  return watched;
}

std::uint32_t heartbeat_consumer::process(std::uint32_t elapsed_us) {
  std::uint32_t next = no_deadline;
  for (watch& w : watches_) {
    if (!w.active || w.is_lost) continue;
    if (elapsed_us >= w.left_us) {
      w.left_us = 0;
      w.is_lost = true;
      if (on_change) on_change(w.e.node_id, true);
      continue;
    }
    w.left_us -= elapsed_us;
    next = earliest(next, w.left_us);
  }
  return next;
}

bool heartbeat_consumer::any_lost() const noexcept {
  for (const watch& w : watches_) {
    if (w.is_lost) return true;
  }
  return false;
}

bool heartbeat_consumer::lost(std::uint8_t node_id) const noexcept {
  for (const watch& w : watches_) {
    if (w.e.node_id == node_id && w.is_lost) return true;
  }
  return false;
}

nmt_state heartbeat_consumer::remote_state(std::uint8_t node_id) const noexcept {
  for (const watch& w : watches_) {
    if (w.e.node_id == node_id) return w.state;
  }
  return nmt_state::initialising;
}

}  // namespace cia402::canopen
