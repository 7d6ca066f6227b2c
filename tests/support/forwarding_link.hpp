// A drive_link that hands every call to the link it holds, for the tests' wrapper links: a wrapper
// overrides only what it changes (the polls it counts, the name it garbles) and everything else,
// the inner link's events, emergencies and cycles included, passes through unchanged. One place
// for the whole drive_link interface, so a wrapper is as short as what it changes.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cia402/axis/drive_link.hpp"

namespace cia402::test {

template <typename Inner>
class forwarding_link : public axes::drive_link {
 public:
  template <typename... Args>
  explicit forwarding_link(Args&&... args) : inner(std::forward<Args>(args)...) {
    inner.on_event = [this](axes::link_event e, const std::string& text) {
      if (on_event) on_event(e, text);
    };
    inner.on_emergency = [this](std::uint16_t code, std::uint8_t reg, std::span<const std::uint8_t> bytes) {
      if (on_emergency) on_emergency(code, reg, bytes);
    };
    inner.before_cycle = [this] {
      if (before_cycle) before_cycle();
    };
  }
  // The callbacks above hold `this`: a copy would call into the original.
  forwarding_link(const forwarding_link&) = delete;
  forwarding_link& operator=(const forwarding_link&) = delete;

  std::uint32_t poll(std::uint32_t elapsed_us) override { return inner.poll(elapsed_us); }
  bool work_now() const override { return inner.work_now(); }
  axes::link_phase phase() const override { return inner.phase(); }
  std::string phase_text() const override { return inner.phase_text(); }
  std::string what() const override { return inner.what(); }
  std::string short_name() const override { return inner.short_name(); }
  bool cyclic() const override { return inner.cyclic(); }
  void start_cyclic() override { inner.start_cyclic(); }
  std::uint32_t cycle_us() const override { return inner.cycle_us(); }
  bool status_known() const override { return inner.status_known(); }
  std::uint16_t status_word() const override { return inner.status_word(); }
  std::uint64_t status_count() const override { return inner.status_count(); }
  std::optional<std::uint16_t> error_code() const override { return inner.error_code(); }
  void set_control_word(std::uint16_t word) override { inner.set_control_word(word); }
  const std::vector<axes::cyclic_object>& cyclic_inputs() const override { return inner.cyclic_inputs(); }
  const std::vector<axes::cyclic_object>& cyclic_outputs() const override { return inner.cyclic_outputs(); }
  std::optional<std::int64_t> cyclic_input(std::uint16_t index, std::uint8_t sub) const override {
    return inner.cyclic_input(index, sub);
  }
  bool set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) override {
    return inner.set_cyclic_output(index, sub, value);
  }
  bool upload(std::uint16_t index, std::uint8_t sub, axes::transfer_done done) override {
    return inner.upload(index, sub, std::move(done));
  }
  bool download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes,
                axes::transfer_done done) override {
    return inner.download(index, sub, std::move(bytes), std::move(done));
  }
  std::optional<axes::value_format> describe(std::uint16_t index, std::uint8_t sub) const override {
    return inner.describe(index, sub);
  }
  void close() override { inner.close(); }
  const axes::close_report& closing() const override { return inner.closing(); }

  Inner inner;
};

}  // namespace cia402::test
