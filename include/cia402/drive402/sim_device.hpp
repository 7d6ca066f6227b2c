// The virtual CiA 402 drive as a fieldbus device (canopen/301/device.hpp): the simulator's virtual
// drive (sim/virtual_drive.hpp), the core state machine and a plant, stepped once per plant cycle of
// the time the fieldbus passes in. It answers the drive's objects (drive_objects.hpp) and takes fault
// injection (0x2001); the CANopen node and the CoE slave mount it unchanged.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "cia402/canopen/301/device.hpp"
#include "cia402/profile.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::drive402 {

class sim_device final : public canopen::device {
 public:
  /// Most cycles one step() runs; a longer gap (a stalled host) is dropped, not replayed.
  static constexpr std::uint32_t max_catch_up_cycles = 1000;

  /// Throws std::invalid_argument for a plant configuration the simulator refuses. The profile
  /// must outlive the device.
  explicit sim_device(const profile& p, const sim::plant_config& config = {});

  sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& value) noexcept override {
    return drive_->read(index, sub, value);
  }
  /// The drive's objects, and 0x2001 (fault injection): an error code raises a fault cause in the
  /// virtual drive, 0 clears every cause.
  sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t value) noexcept override;
  std::uint32_t step(std::uint32_t elapsed_us) noexcept override;
  void set_connection_lost(bool lost) noexcept override { drive_->view().set_connection_lost(lost); }
  void reset() noexcept override;
  /// The status word, then zeros.
  std::array<std::uint8_t, 5> manufacturer_error_field() const noexcept override;

  sim::virtual_drive& drive() noexcept { return *drive_; }

 private:
  const profile* profile_;
  sim::plant_config config_;
  // Reports to the node what the drive changed by itself since the last report.
  void report_changes() noexcept;

  std::unique_ptr<sim::virtual_drive> drive_;
  std::uint32_t pending_us_ = 0;
  // What the node was last told: the objects the drive changes by itself.
  std::uint16_t status_word_ = 0;
  std::uint16_t error_code_ = 0;
  std::int32_t velocity_rpm_ = 0;
  std::int32_t position_ = 0;
  std::int32_t demand_ = 0;
  std::int32_t torque_ = 0;
  std::int8_t mode_ = 0;
};

}  // namespace cia402::drive402
