// The virtual CiA 402 drive as a fieldbus device (dictionary/device.hpp): the simulator's virtual
// drive (sim/virtual_drive.hpp), the core state machine and a plant, stepped once per plant cycle of
// the time the fieldbus passes in. It answers the drive's objects (drive_objects.hpp) and takes fault
// injection (0x2001); the CANopen node and the CoE slave mount it unchanged.
//
// A lost fieldbus connection (device::set_connection_lost) acts through 0x6007 (CiA 402-2 §6.2.1,
// S10) only on a drive that has something to protect: one that is enabled when the loss comes, or
// becomes enabled while it lasts, that is in OPERATION ENABLED or QUICK STOP ACTIVE or with torque
// on in any state (the PROFIBUS profiles' SWITCHED ON). From then on the loss acts until the
// fieldbus reports the connection back, so a quick stop or a fault it started is not undone by the
// control word still held. A drive that is not enabled (SWITCH ON DISABLED, READY TO SWITCH ON,
// SWITCHED ON without torque, FAULT) stays as it is: a master that disabled the drive and then
// left (EtherCAT: out of OP; CANopen: NMT stop) leaves no fault behind. Both fieldbuses share this
// rule because it lives here, in the device; the core keeps S10 as a level (`cia402 replay`'s
// `link lost`).
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "cia402/dictionary/device.hpp"
#include "cia402/profile.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::drive402 {

class sim_device final : public dictionary::device {
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
  /// The fieldbus's word; whether the drive acts on it is the rule at the top of this file.
  void set_connection_lost(bool lost) noexcept override;
  /// What the fieldbus last said, and whether the loss acts on the drive (0x6007).
  bool connection_lost() const noexcept { return fieldbus_lost_; }
  bool loss_acting() const noexcept { return loss_acting_; }
  void reset() noexcept override;
  /// The status word, then zeros.
  std::array<std::uint8_t, 5> manufacturer_error_field() const noexcept override;

  sim::virtual_drive& drive() noexcept { return *drive_; }

 private:
  const profile* profile_;
  sim::plant_config config_;
  // Reports to the node what the drive changed by itself since the last report.
  void report_changes() noexcept;
  // The fieldbus's loss passed on to the drive when it has something to protect (top of the file).
  void apply_connection() noexcept;

  std::unique_ptr<sim::virtual_drive> drive_;
  std::uint32_t pending_us_ = 0;
  bool fieldbus_lost_ = false;
  bool loss_acting_ = false;
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
