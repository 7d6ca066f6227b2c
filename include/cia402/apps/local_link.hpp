// The axis session's link to a virtual drive in this process (axis/drive_link.hpp): the simulated
// drive (drive402::sim_device) reached without a fieldbus, so a client of the axis layer (the
// instrument page of `cia402 serve` for a drive of its own) runs the same session as for a drive on
// a bus. What a bus would make a master wait for is there at once:
// - one cycle per cycle of the simulator (1 ms by default): the control word and the cyclic outputs
//   (0x6040, 0x6060, 0x607A, 0x60FF, 0x6071, as EtherCAT's RxPDO 0x1600) go in before the step,
//   and every mappable object the drive can read is a cyclic input of that cycle;
// - a transfer (upload, download) ends at the next poll, even poll(0) (work_now() says one waits),
//   by the dictionary rules both buses apply (dictionary::dictionary_access over
//   drive402::drive_objects()), so a value refused here is refused on a bus with the same abort code;
// - 0x1003, the pre-defined error field (CiA 301 §7.5.2.5), kept as a CiA 301 node keeps it: each new
//   error code the drive raises goes in at sub-index 1, the older ones move down, at most
//   `error_history` kept; sub-index 0 is their number, and writing 0 to it empties the list;
// - an emergency (code, 0x1001, the status word) each time the error code changes.
// The simulator stays reachable (drive()): the plant's inputs (STO, DC link, fault causes) are no
// object of the drive, and the client that owns them sets them there.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cia402/axis/drive_link.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/profile.hpp"
#include "cia402/sim/plant.hpp"

namespace cia402::apps {

/// 0x1003 (CiA 301): the pre-defined error field.
inline constexpr std::uint16_t error_history_index = 0x1003;

class local_link final : public axes::link_base {
 public:
  /// The profile must outlive the link. `error_history`: entries 0x1003 keeps (1..254).
  explicit local_link(const profile& p, const sim::plant_config& plant = {}, std::uint8_t error_history = 8);
  ~local_link() override;
  local_link(const local_link&) = delete;
  local_link& operator=(const local_link&) = delete;

  std::uint32_t poll(std::uint32_t elapsed_us) override;
  /// A transfer queued: the next poll(0) answers it.
  bool work_now() const override { return !closed_ && !transfers_.empty(); }
  axes::link_phase phase() const override;
  std::string phase_text() const override { return closed_ ? "closed" : std::string(); }
  std::string what() const override { return "the virtual drive in this process"; }
  std::string short_name() const override { return "virtual drive"; }

  bool cyclic() const override { return !closed_; }
  void start_cyclic() override {}
  std::uint32_t cycle_us() const override;
  bool status_known() const override { return status_count_ > 0; }
  std::uint16_t status_word() const override;
  std::optional<std::uint16_t> error_code() const override;
  void set_control_word(std::uint16_t word) override;

  std::optional<std::int64_t> cyclic_input(std::uint16_t index, std::uint8_t sub) const override;
  bool set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) override;

  std::optional<axes::value_format> describe(std::uint16_t index, std::uint8_t sub) const override;

  void close() override;

  /// The simulated drive: its views set the plant's inputs (STO, DC link, fault causes).
  sim::virtual_drive& drive() noexcept { return device_->drive(); }
  drive402::sim_device& device() noexcept { return *device_; }
  /// 0x1003's entries, newest first (error code in the low 16 bits).
  const std::deque<std::uint32_t>& error_history() const noexcept { return history_; }

 private:
  class objects;
  using transfer = axes::pending_transfer;

  bool queue_transfer(transfer t) override {
    transfers_.push_back(std::move(t));  // answered at the next poll
    return true;
  }
  void one_cycle();
  void note_error(std::uint16_t code, std::uint8_t reg);

  std::unique_ptr<drive402::sim_device> device_;
  std::unique_ptr<objects> objects_;
  std::optional<std::uint16_t> word_;
  std::uint32_t pending_us_ = 0;
  std::uint16_t last_error_ = 0;
  std::uint8_t history_size_;
  std::deque<std::uint32_t> history_;
  std::deque<transfer> transfers_;
  bool closed_ = false;
};

}  // namespace cia402::apps
