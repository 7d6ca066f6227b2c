// A test double for dictionary::device: the core drive (cia402::drive) on an ideal plant (always at
// standstill, every ramp done at once), stepping once per millisecond. It counts what the node asks
// of it, so tests can see the node's calls, and it does not depend on the simulator.
#pragma once

#include <array>
#include <cstdint>

#include "cia402/dictionary/device.hpp"
#include "cia402/drive.hpp"

namespace cia402::canopen::test {

class test_device final : public dictionary::device {
 public:
  explicit test_device(const profile& p = standard_profile()) : profile_(&p), drive_(p) {}

  sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& v) noexcept override {
    ++reads;
    if (sub != 0) return sdo_abort::sub_index_does_not_exist;
    switch (index) {
      case 0x1001: v = out_.error_register; return sdo_abort::none;
      case 0x603F: v = out_.error_code; return sdo_abort::none;
      case 0x6040: v = control_word_; return sdo_abort::none;
      case 0x6041: v = out_.status_word; return sdo_abort::none;
      case 0x6060:
      case 0x6061: v = 3; return sdo_abort::none;
      case 0x606C: v = out_.torque ? target_velocity_ : 0; return sdo_abort::none;
      case 0x60FF: v = target_velocity_; return sdo_abort::none;
      case 0x6083: case 0x6084: case 0x6085: v = ramps_[index - 0x6083]; return sdo_abort::none;
      default: {
        std::int32_t value = 0;
        const sdo_abort a = drive_.read(index, value);
        v = value;
        return a;
      }
    }
  }

  sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t v) noexcept override {
    ++writes;
    if (sub != 0) return sdo_abort::sub_index_does_not_exist;
    switch (index) {
      case 0x6040: control_word_ = static_cast<std::uint16_t>(v); return sdo_abort::none;
      case 0x6060: return v == 3 ? sdo_abort::none : sdo_abort::invalid_value;
      case 0x60FF:
        target_velocity_ = static_cast<std::int32_t>(v);
        report_changes();  // 0x606C follows it at once
        return sdo_abort::none;
      case 0x6083: case 0x6084: case 0x6085:
        if (v < 1) return sdo_abort::value_too_low;
        ramps_[index - 0x6083] = static_cast<std::uint32_t>(v);
        return sdo_abort::none;
      case 0x1001: case 0x603F: case 0x6041: case 0x6061: case 0x606C:
        return sdo_abort::read_only_object;
      case 0x2001:  // fault injection: a cause with this code, 0 clears it
        if (v < 0 || v > 0xFFFF) return sdo_abort::value_too_high;
        fault_ = static_cast<std::uint16_t>(v);
        return sdo_abort::none;
      default: return drive_.write(index, static_cast<std::int32_t>(v));
    }
  }

  std::uint32_t step(std::uint32_t elapsed_us) noexcept override {
    pending_us_ += elapsed_us;
    while (pending_us_ >= cycle_us) {
      pending_us_ -= cycle_us;
      drive_inputs in;
      in.control_word = control_word_;
      in.fault_code = fault_;
      in.connection_lost = connection_lost;
      out_ = drive_.step(in);
      ++steps;
    }
    report_changes();
    return cycle_us - pending_us_;
  }

  std::array<std::uint8_t, 5> manufacturer_error_field() const noexcept override {
    return {static_cast<std::uint8_t>(out_.status_word), static_cast<std::uint8_t>(out_.status_word >> 8),
            0, 0, 0};
  }

  void set_connection_lost(bool lost) noexcept override { connection_lost = lost; }
  void reset() noexcept override {
    drive_ = cia402::drive(*profile_);
    out_ = {};
    control_word_ = 0;
    ++resets;
    report_changes();
  }

  state current() const noexcept { return drive_.current(); }
  std::uint16_t status_word() const noexcept { return out_.status_word; }
  std::uint16_t control_word() const noexcept { return control_word_; }
  std::int32_t target_velocity() const noexcept { return target_velocity_; }

  static constexpr std::uint32_t cycle_us = 1000;
  bool connection_lost = false;
  int reads = 0;
  int writes = 0;
  int steps = 0;
  int resets = 0;

 private:
  // Tells the node what changed by the device's own doing, as a device must (device.hpp).
  void report_changes() noexcept {
    const std::int64_t velocity = out_.torque ? target_velocity_ : 0;
    if (out_.status_word != reported_status_) {
      reported_status_ = out_.status_word;
      changed(0x6041, 0);
    }
    if (out_.error_code != reported_error_) {
      reported_error_ = out_.error_code;
      changed(0x603F, 0);
      changed(0x1001, 0);
      error_changed(out_.error_code);
    }
    if (velocity != reported_velocity_) {
      reported_velocity_ = velocity;
      changed(0x606C, 0);
    }
  }

  std::uint16_t reported_status_ = 0;
  std::uint16_t reported_error_ = 0;
  std::int64_t reported_velocity_ = 0;
  const profile* profile_;
  cia402::drive drive_;
  drive_outputs out_{};
  std::uint16_t control_word_ = 0;
  std::uint16_t fault_ = 0;
  std::int32_t target_velocity_ = 0;
  std::uint32_t ramps_[3] = {1000, 1000, 10000};
  std::uint32_t pending_us_ = 0;
};

}  // namespace cia402::canopen::test
