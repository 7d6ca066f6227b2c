// Network management (CiA 301 §7.2.8.3): the NMT states and commands, and heartbeat error control
// (§7.2.8.3.2): a producer that sends the node's state every 0x1017 ms and a consumer that watches
// other nodes' heartbeats against 0x1016's times.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "cia402/canopen/can/channel.hpp"
#include "cia402/canopen/301/timing.hpp"

namespace cia402::canopen {

/// NMT states, valued as the heartbeat sends them.
enum class nmt_state : std::uint8_t {
  initialising = 0x00,  ///< boot-up: sent once on entering PRE-OPERATIONAL
  stopped = 0x04,
  operational = 0x05,
  pre_operational = 0x7F,
};
const char* nmt_state_name(nmt_state s) noexcept;

/// NMT command specifiers (byte 0 of the NMT frame, COB-ID 0; byte 1 is the node-ID, 0 = all).
enum class nmt_command : std::uint8_t {
  start = 0x01,
  stop = 0x02,
  enter_pre_operational = 0x80,
  reset_node = 0x81,
  reset_communication = 0x82,
};

inline frame nmt_frame(nmt_command c, std::uint8_t node_id) noexcept {
  return make_frame(cob::nmt, {static_cast<std::uint8_t>(c), node_id});
}
inline frame heartbeat_frame(std::uint8_t node_id, nmt_state s) noexcept {
  return make_frame(cob::heartbeat + node_id, {static_cast<std::uint8_t>(s)});
}

/// Sends the node's state every `period_ms` (0x1017); 0 = off.
class heartbeat_producer {
 public:
  void configure(std::uint16_t period_ms) noexcept {
    if (period_ms == 0) timer_.stop(); else timer_.start(period_ms * 1000u);
  }
  /// A heartbeat now, and the period counted from here: a consumer watches only from the first one
  /// it hears (CiA 301), so a master sends one before it commands anything.
  void send_now(channel& out, std::uint8_t node_id, nmt_state s) noexcept {
    if (!timer_.running()) return;
    (void)out.send(heartbeat_frame(node_id, s));
    timer_.start(timer_.period());
  }
  /// Returns when the next heartbeat is due.
  std::uint32_t process(std::uint32_t elapsed_us, channel& out, std::uint8_t node_id,
                        nmt_state s) noexcept {
    if (timer_.expired(elapsed_us)) (void)out.send(heartbeat_frame(node_id, s));
    return timer_.left();
  }

 private:
  interval_timer timer_;
};

/// Watches the heartbeats of up to N nodes. Monitoring of a node starts with its first heartbeat
/// (CiA 301): a node that never sent one is not "lost". When no heartbeat arrives for the consumer
/// time the node is lost; its next heartbeat brings it back. Both changes are reported through
/// `on_change(node, lost)`.
class heartbeat_consumer {
 public:
  struct entry {
    std::uint8_t node_id = 0;   ///< 0 = entry unused
    std::uint16_t time_ms = 0;  ///< 0 = entry unused
  };
  std::function<void(std::uint8_t node_id, bool lost)> on_change;

  /// Replaces the watched nodes; every entry starts waiting for its first heartbeat.
  void configure(const std::vector<entry>& entries);
  /// A frame from the bus; returns true if it was a watched heartbeat.
  bool on_frame(const frame& f);
  std::uint32_t process(std::uint32_t elapsed_us);
  bool any_lost() const noexcept;
  bool lost(std::uint8_t node_id) const noexcept;
  /// The NMT state the node last reported, or initialising if none yet.
  nmt_state remote_state(std::uint8_t node_id) const noexcept;

 private:
  struct watch {
    entry e;
    bool active = false;  // a first heartbeat was seen
    bool is_lost = false;
    std::uint32_t left_us = 0;
    nmt_state state = nmt_state::initialising;
  };
  std::vector<watch> watches_;
};

}  // namespace cia402::canopen
