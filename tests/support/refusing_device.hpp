// A device in front of a virtual drive's that refuses writes of chosen objects, for the failure
// matrix's runs over the real links (tests/canopen and tests/ethercat): a drive that answers an SDO
// download with an abort, as one that changed its mind.
#pragma once

#include <array>
#include <cstdint>
#include <set>

#include "cia402/dictionary/device.hpp"
#include "cia402/drive402/sim_device.hpp"

namespace cia402::failure_matrix {

// Refuses writes of the objects in `refused` with 0x06090030 (invalid value for parameter);
// everything else, the drive's reports too, passes through.
class refusing_device final : public dictionary::device {
 public:
  explicit refusing_device(drive402::sim_device& inner) : inner_(&inner), relay_{this} { inner.attach(&relay_); }
  ~refusing_device() override { inner_->attach(nullptr); }

  sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& value) noexcept override {
    return inner_->read(index, sub, value);
  }
  sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t value) noexcept override {
    if (refused.count(index) != 0) return sdo_abort::invalid_value;
    return inner_->write(index, sub, value);
  }
  std::uint32_t step(std::uint32_t elapsed_us) noexcept override { return inner_->step(elapsed_us); }
  void set_connection_lost(bool lost) noexcept override { inner_->set_connection_lost(lost); }
  void reset() noexcept override { inner_->reset(); }
  std::array<std::uint8_t, 5> manufacturer_error_field() const noexcept override {
    return inner_->manufacturer_error_field();
  }

  std::set<std::uint16_t> refused;

 private:
  struct relay final : dictionary::device_events {
    explicit relay(refusing_device* d) : owner(d) {}
    void object_changed(std::uint16_t index, std::uint8_t sub) noexcept override { owner->changed(index, sub); }
    void error_changed(std::uint16_t code) noexcept override { owner->device::error_changed(code); }
    refusing_device* owner;
  };
  drive402::sim_device* inner_;
  relay relay_;
};

}  // namespace cia402::failure_matrix
