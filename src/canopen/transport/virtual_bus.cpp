#include "cia402/canopen/transport/virtual_bus.hpp"

#include <algorithm>

namespace cia402::canopen {

virtual_channel::virtual_channel(virtual_bus& bus, std::size_t capacity)
    : bus_(&bus), ring_(capacity == 0 ? 1 : capacity) {
  filter_.set();
}

virtual_channel::~virtual_channel() {
  if (bus_ != nullptr) bus_->detach(this);
}

std::error_code virtual_channel::send(const frame& f) noexcept {
  if (bus_ == nullptr) return std::make_error_code(std::errc::not_connected);
  if (f.len > 8 || (!f.extended && f.id > max_base_id) || f.id > max_extended_id) {
    return std::make_error_code(std::errc::invalid_argument);
  }
  bus_->deliver(f, this);
  return {};
}

bool virtual_channel::receive(frame& f) noexcept {
  if (count_ == 0) return false;
  f = ring_[head_];
  head_ = head_ + 1 == ring_.size() ? 0 : head_ + 1;
  --count_;
  return true;
}

void virtual_channel::push(const frame& f) noexcept {
  if (count_ == ring_.size()) {
    ++overruns_;
    return;
  }
  std::size_t tail = head_ + count_;
  if (tail >= ring_.size()) tail -= ring_.size();
  ring_[tail] = f;
  ++count_;
}

std::unique_ptr<virtual_channel> virtual_bus::attach() {
  std::unique_ptr<virtual_channel> c(new virtual_channel(*this, capacity_));
  channels_.push_back(c.get());
  return c;
}

virtual_bus::~virtual_bus() {
  for (virtual_channel* c : channels_) c->bus_ = nullptr;
}

void virtual_bus::deliver(const frame& f, const virtual_channel* from) noexcept {
  ++frames_;
  for (virtual_channel* c : channels_) {
    if (c != from && c->accepts(f)) c->push(f);
  }
  if (observer_) observer_(f);
}

void virtual_bus::detach(virtual_channel* c) noexcept {
  channels_.erase(std::remove(channels_.begin(), channels_.end(), c), channels_.end());
}

}  // namespace cia402::canopen
