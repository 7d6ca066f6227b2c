// A whole CAN network in one process for tests: a virtual bus, slave nodes on test devices (or any
// device), a "tester" channel that plays a raw client (sends frames, keeps everything it receives),
// and a clock the test advances. Deterministic: the same calls give the same frames in the same order.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/301/nmt.hpp"
#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "test_device.hpp"

namespace cia402::canopen::test {

struct node {
  std::unique_ptr<dictionary::device> dev;
  std::unique_ptr<virtual_channel> ch;
  std::unique_ptr<slave> sl;
};

class network {
 public:
  network() : tester_(bus_.attach()) {}

  /// A slave on a test_device (or on `dev`), node-ID `id`.
  slave& add(std::uint8_t id, std::unique_ptr<dictionary::device> dev = nullptr, std::uint16_t heartbeat_ms = 0,
             std::uint32_t sdo_timeout_us = 1000000) {
    node n;
    n.dev = dev ? std::move(dev) : std::make_unique<test_device>();
    n.ch = bus_.attach();
    const slave_config c = apps::drive_node_config(id, sdo_timeout_us, heartbeat_ms);
    n.sl = std::make_unique<slave>(*n.dev, *n.ch, c);
    nodes_.push_back(std::move(n));
    return *nodes_.back().sl;
  }
  slave& at(std::size_t i) { return *nodes_[i].sl; }
  test_device& device_at(std::size_t i) { return static_cast<test_device&>(*nodes_[i].dev); }
  void remove_last() { nodes_.pop_back(); }

  /// The tester sends a frame.
  void send(const frame& f) { ASSERT_FALSE(tester_->send(f)); }
  /// Every slave takes its frames and `step_us` of time, `us / step_us` times; the tester keeps
  /// what it receives.
  void run(std::uint32_t us, std::uint32_t step_us = 100) {
    for (std::uint32_t t = 0; t < us; t += step_us) tick(step_us);
  }
  void tick(std::uint32_t step_us) {
    for (node& n : nodes_) n.sl->poll(*n.ch, step_us);
    drain();
  }
  /// Lets frames settle without time passing.
  void settle() {
    for (int i = 0; i < 4; ++i) {
      for (node& n : nodes_) n.sl->poll(*n.ch, 0);
    }
    drain();
  }
  void drain() {
    frame f;
    while (tester_->receive(f)) received.push_back(f);
  }
  /// Frames the tester received with this identifier.
  std::vector<frame> with_id(std::uint32_t id) const {
    std::vector<frame> out;
    for (const frame& f : received) {
      if (f.id == id) out.push_back(f);
    }
    return out;
  }

  virtual_bus& bus() { return bus_; }
  std::vector<frame> received;

 private:
  virtual_bus bus_;
  std::unique_ptr<virtual_channel> tester_;
  std::vector<node> nodes_;
};

/// An SDO request frame to `node`: command byte, index, sub, 4 data bytes.
inline frame sdo_request(std::uint8_t node, std::uint8_t command, std::uint16_t index, std::uint8_t sub,
                         std::uint32_t data = 0) {
  frame f;
  f.id = cob::sdo_rx + node;
  f.len = 8;
  f.data = {command, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub,
            static_cast<std::uint8_t>(data), static_cast<std::uint8_t>(data >> 8),
            static_cast<std::uint8_t>(data >> 16), static_cast<std::uint8_t>(data >> 24)};
  return f;
}

/// The abort code of an SDO abort frame, or 0 if it is not one.
inline std::uint32_t abort_code_of(const frame& f) {
  if (f.len != 8 || f.data[0] != 0x80) return 0;
  return static_cast<std::uint32_t>(get_le(&f.data[4], 4));
}

/// An expedited SDO download of `bytes` (1..4) bytes of `value` to `node`.
inline frame sdo_download(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                          unsigned bytes) {
  static constexpr std::uint8_t commands[5] = {0, 0x2F, 0x2B, 0x27, 0x23};
  return sdo_request(node, commands[bytes], index, sub, value);
}

/// The tester sends an SDO request to `node` and lets it settle: the abort code of the node's last
/// answer (0 when that is no abort), 0xFFFFFFFF when it gave none. `net.received` holds what came.
inline std::uint32_t sdo_answer(network& net, std::uint8_t node, const frame& request) {
  net.received.clear();
  net.send(request);
  net.settle();
  const auto r = net.with_id(cob::sdo_tx + node);
  return r.empty() ? 0xFFFFFFFFu : abort_code_of(r.back());
}

}  // namespace cia402::canopen::test
