// The instrument page's second backend: a CiA 402 drive on a CAN bus, reached as a CANopen master
// (a `cia402 bus` node over socketcand, or a real drive). Same interface as the in-process
// instrument, so the server and the page are the same; what the page cannot do on a remote drive it
// learns from `capabilities` and the `remote` part of each snapshot.
//
// The link is the project's one CANopen 402 master (cia402/canopen/402/drive_master.hpp), set up with
// PDOs on change: TPDO1 = 0x6041 + 0x603F with no inhibit time, so every state the drive reports
// arrives; TPDO2 = 0x606C with a 20 ms inhibit time; RPDO1 = 0x6040; the page's objects (option
// codes, ramps) and 0x60FF read at set-up, and 0x6040 so that connecting changes nothing. The master
// finds out whether the node is a `cia402 bus` node that takes injected faults at 0x2001; no other
// drive's 0x2001 is ever written. The page sends a heartbeat of its own (guard_ms) that the drive
// watches, so when the page's server goes away the drive applies its 0x6007 reaction.
//
// Commands go out in RPDO1 (the word from cia402::encode_command, other bits kept; a fault reset is
// bit 7 high for reset_pulse_us, then low); writes of objects and 0x60FF are SDO downloads through
// the master and their refusals carry the drive's abort code; what no TPDO carries is polled every
// poll_us, and the mode display and the actual position, torque and following error every
// actual_poll_us (objects the drive lacks show as null). The transition numbers are inferred from the observed states (transition_inference.hpp)
// and marked "inferred" in the snapshots.
//
// A lost heartbeat or any SDO timeout shows as status "no_answer" with "node N does not answer
// (...)" on the page; the state is then UNKNOWN, commands are refused with 503, and set-up starts
// again after retry_us. A boot-up message starts set-up again at once. A failed channel (the
// socketcand server went away) is "bus_failed", for good.
//
// All CAN traffic happens in step()/process(): HTTP threads only queue requests and wait for them,
// so the channel is used by one thread. The clock is passed in: step() stands for cycle_us (the
// page's own heartbeat may run on a clock of its own: remote_config::heartbeat_clock_us).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "cia402/canopen/can/channel.hpp"
#include "cia402/page/backend.hpp"
#include "cia402/profile.hpp"

namespace cia402::page {

namespace detail {
class remote_link;
}

struct remote_config {
  std::uint8_t node_id = 1;
  std::string bus_name;                   ///< shown on the page, e.g. the URL
  std::uint32_t cycle_us = 1000;          ///< the time one step() stands for
  std::uint32_t sdo_timeout_us = 500000;
  std::uint16_t heartbeat_ms = 100;       ///< written to 0x1017, watched at 3x; 0 = not used
  /// The page's own heartbeat (node-ID 127), written to the drive's 0x1016 to be watched at 3x, so
  /// a drive whose page went away applies 0x6007; 0 = none. A drive that refuses it is run without.
  std::uint16_t guard_ms = 100;
  std::uint32_t retry_us = 1000000;       ///< set-up starts again this long after a failure
  std::uint32_t poll_us = 100000;         ///< SDO polling of what no TPDO carries
  /// The mode display 0x6061 and the actual values 0x6064, 0x6077, 0x60F4 are read by SDO one after
  /// the other, a round this often (0: never). An object the drive lacks is read no more (null).
  std::uint32_t actual_poll_us = 100000;
  std::uint32_t publish_us = 40000;       ///< at most one snapshot this often, only on change
  std::uint32_t settle_quiet_us = 150000; ///< an action settles after this long without change
  std::uint32_t settle_limit_us = 15000000;
  std::uint32_t reset_pulse_us = 20000;   ///< bit 7 high this long for a fault-reset edge
  std::uint16_t velocity_inhibit_100us = 200;  ///< TPDO2 inhibit time (20 ms)
  std::size_t results_kept = 8;
  /// The sign of life (sign_of_life.hpp): a drive left in OPERATION ENABLED is stopped as its 0x6007
  /// says once no client renewed the lease for this long (step() time); 0: no lease.
  std::uint64_t lease_us = 0;
  /// The clock the page's heartbeat runs on, in microseconds from any start; empty: step() time.
  /// `cia402 serve --can` sets the steady clock: the drive watches that heartbeat on wall time, and
  /// a page slowed down by a loaded machine (its runner skips lost cycles, so step() time lags)
  /// must still send it every guard_ms of wall time. Everything else stays on step() time: a page
  /// held up must not find its drive silent from answers that wait, unread, in its socket.
  std::function<std::uint64_t()> heartbeat_clock_us;
  /// Wall time an HTTP request waits for its SDO transfer before it is answered 504 (the transfer
  /// itself ends by its own timeout in bus time).
  std::chrono::milliseconds request_timeout{10000};
};

/// Where the link to the node stands.
enum class remote_status : std::uint8_t {
  configuring,  ///< set-up transfers running
  running,      ///< PDOs flow, commands are obeyed
  no_answer,    ///< SDO timeout or heartbeat lost; set-up starts again after retry_us
  refused,      ///< the node refused a required set-up request, or is not a CiA 402 drive
  bus_failed,   ///< the channel failed (e.g. the socketcand server went away): for good
};
const char* remote_status_name(remote_status s) noexcept;

class remote_drive final : public backend {
 public:
  /// The profile and the channel must outlive the backend. Nothing is sent before the first step.
  remote_drive(const profile& p, canopen::channel& bus, const remote_config& config = {});
  /// A drive reached through another link (EtherCAT: ecat_drive.hpp makes one).
  remote_drive(const profile& p, std::unique_ptr<detail::remote_link> link, const remote_config& config);
  ~remote_drive() override;
  remote_drive(const remote_drive&) = delete;
  remote_drive& operator=(const remote_drive&) = delete;

  /// process(cycle_us).
  void step() override;
  /// Takes every frame waiting on the channel, advances the timers by `elapsed_us`, sends what is
  /// due. process(0) lets answers already received take effect without time passing.
  void process(std::uint32_t elapsed_us);

  reply command(page_command c) override;
  reply toggle_control_bit(int bit) override;
  /// Profile position's set-point handshake in RPDO1: bit 4 up until the drive's status bit 12, then
  /// down (backend.hpp). The mode is checked against 0x6061 as last read.
  reply new_setpoint() override;
  /// Blocks until the drive answered the SDO download (or it timed out).
  reply write_object(std::uint16_t index, std::int64_t value) override;
  /// Target velocity (SDO 0x60FF) or a fault (SDO 0x2001, on a `cia402 bus` node only), one per
  /// request; DC link and STO are refused. Blocks like write_object.
  reply change_plant(const plant_change& change) override;
  /// The lease is renewed; the next process() sees it.
  void renew_lease() override;

  std::string info_json(bool control, bool token_required) const override;
  std::string snapshot_json() const override;
  std::string recording_json(std::uint64_t rows_seen,
                             std::uint64_t transitions_seen) const override;
  std::string recording_file(recording_format format) const override;
  std::optional<published> wait_for_update(std::uint64_t seen,
                                           std::chrono::milliseconds timeout) override;
  published latest() const override;
  void close() override;
  bool closed() const override;

  remote_status status() const;
  /// "node 1 does not answer (SDO timeout reading 0x1000:0)", or "" while all is well.
  std::string status_text() const;
  bool fault_injection_available() const;

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace cia402::page
