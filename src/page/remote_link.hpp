// What the page's remote backend (remote_drive.cpp) needs of the master that reaches the drive: its
// state of set-up, the status word as it arrives, the control word sent, SDO transfers with a
// callback, and what it can show about itself. Two links exist: the CANopen 402 master on a CAN bus
// (remote_drive.cpp) and the EtherCAT master on a line (ecat_link.cpp); the page does the same with
// either.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cia402/page/remote_drive.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402::page::detail {

/// Why the link's phase changed.
enum class link_event : std::uint8_t {
  running,    ///< set-up is done; start_values() holds what it read
  failed,     ///< the drive went silent or set-up failed: nothing is known until running again
  restarted,  ///< the drive started afresh (a boot-up): what the page wrote there is gone
};

/// An SDO transfer's end.
struct link_transfer {
  bool ok = false;
  bool cancelled = false;  ///< the link was lost before the transfer ran
  sdo_abort abort = sdo_abort::none;
  std::int64_t value = 0;  ///< an upload's value
};

class remote_link {
 public:
  virtual ~remote_link() = default;

  std::function<void(std::uint16_t status_word)> on_status;
  std::function<void(std::int32_t velocity)> on_velocity;
  std::function<void(std::uint16_t word)> on_sent;
  std::function<void(link_event)> on_phase;

  /// Frames in and out, timers, set-up: `elapsed_us` of the link's time passed.
  virtual void poll(std::uint32_t elapsed_us) = 0;
  virtual bool running() const = 0;
  virtual bool failed() const = 0;
  virtual remote_status status() const = 0;
  /// Why it is not running, in words ("" while all is well).
  virtual std::string phase_text() const = 0;
  /// "node 1", "slave 0": how the page names the drive.
  virtual std::string drive_text() const = 0;

  virtual bool request_pending() const = 0;
  virtual bool read(std::uint16_t index, bool is_signed, std::function<void(const link_transfer&)> done) = 0;
  virtual bool write(std::uint16_t index, std::int64_t value, unsigned bytes,
                     std::function<void(const link_transfer&)> done) = 0;
  /// What set-up read: the page's objects, 0x60FF, 0x6502, where the drive answered.
  virtual const std::map<std::uint16_t, std::int64_t>& start_values() const = 0;

  virtual std::uint16_t last_sent() const = 0;
  /// The word goes out as soon as it can; with `fault_reset_edge`, bit 7 high for a moment first.
  virtual void send_control_word(std::uint16_t word, bool fault_reset_edge = false) = 0;
  virtual bool words_queued() const = 0;

  virtual bool status_known() const = 0;
  virtual std::uint16_t status_word() const = 0;
  virtual std::uint16_t error_code() const = 0;
  virtual std::uint8_t error_register() const = 0;
  /// The drive takes injected faults at 0x2001 (a virtual drive of this project).
  virtual bool fault_injection() const = 0;
  /// An actual value the link carries cyclically (EtherCAT's process data); nothing when it does
  /// not, and the page reads it by SDO instead.
  virtual std::optional<std::int64_t> cyclic(std::uint16_t index) const {
    (void)index;
    return std::nullopt;
  }
  /// The "remote" part of each snapshot (where the drive is, the link's own state).
  virtual nlohmann::ordered_json describe() const = 0;
  /// For /api/info: where the drive is.
  virtual nlohmann::ordered_json where() const = 0;
};

}  // namespace cia402::page::detail
