// The in-process CAN bus: many channels, deterministic delivery. A frame sent on one channel is
// queued, in send order, on every other attached channel whose acceptance filter takes it (a CAN
// controller does not receive its own frames). Nothing here reads a clock or blocks; tests and the
// `cia402 bus` server run whole networks on it without the OS.
#pragma once

#include <bitset>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "cia402/canopen/can/channel.hpp"

namespace cia402::canopen {

class virtual_bus;

/// One attachment to a virtual_bus. Owned by whoever attached it; detaches itself when destroyed.
class virtual_channel final : public channel {
 public:
  ~virtual_channel() override;
  virtual_channel(const virtual_channel&) = delete;
  virtual_channel& operator=(const virtual_channel&) = delete;

  std::error_code send(const frame& f) noexcept override;
  bool receive(frame& f) noexcept override;

  /// Acceptance filter for 11-bit identifiers, like a CAN controller's: by default every frame.
  /// Extended frames pass only with accept_extended.
  void accept_none() noexcept { filter_.reset(); accept_extended_ = false; }
  void accept_all() noexcept { filter_.set(); accept_extended_ = true; }
  void accept(std::uint32_t id, bool on = true) noexcept {
    if (id <= max_base_id) filter_.set(id, on);
  }
  void accept_extended(bool on) noexcept { accept_extended_ = on; }
  bool accepts(const frame& f) const noexcept {
    return f.extended ? accept_extended_ : filter_.test(f.id & max_base_id);
  }

  std::size_t pending() const noexcept { return count_; }
  /// Frames dropped because this channel's queue was full (a receive overrun).
  std::uint64_t overruns() const noexcept { return overruns_; }

 private:
  friend class virtual_bus;
  virtual_channel(virtual_bus& bus, std::size_t capacity);
  void push(const frame& f) noexcept;

  virtual_bus* bus_;
  std::vector<frame> ring_;
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::uint64_t overruns_ = 0;
  std::bitset<max_base_id + 1> filter_;
  bool accept_extended_ = true;
};

class virtual_bus {
 public:
  /// Each channel queues at most `capacity` frames; more are dropped and counted as overruns.
  explicit virtual_bus(std::size_t capacity = 4096) : capacity_(capacity) {}
  virtual_bus(const virtual_bus&) = delete;
  virtual_bus& operator=(const virtual_bus&) = delete;
  /// Channels that outlive their bus stay safe: they then refuse to send (not_connected).
  ~virtual_bus();

  std::unique_ptr<virtual_channel> attach();

  /// Called with every frame the bus carries, once, after the channels have it queued: a tap for a
  /// log (`cia402 bus --log`), which sees the frames no channel's filter takes as well. Empty: none.
  void observe(std::function<void(const frame&)> observer) { observer_ = std::move(observer); }

  /// Frames sent on the bus so far (each counted once, however many channels receive it).
  std::uint64_t frames() const noexcept { return frames_; }
  std::size_t channels() const noexcept { return channels_.size(); }

 private:
  friend class virtual_channel;
  void deliver(const frame& f, const virtual_channel* from) noexcept;
  void detach(virtual_channel* c) noexcept;

  std::size_t capacity_;
  std::vector<virtual_channel*> channels_;
  std::uint64_t frames_ = 0;
  std::function<void(const frame&)> observer_;
};

}  // namespace cia402::canopen
