// The page's drive: an axis session (axis/session.hpp) over the link the composition gives it, and
// what is the page's own around it. Every drive is reached the same way: a virtual drive in this
// process (apps::local_link), a node on a CAN bus (canopen::can_link), a slave on an EtherCAT line
// (ethercat::ecat_link); `cia402 serve` builds the link, the page holds no fieldbus code.
//
// The session's: the control word (the buttons' and bit toggles' words go out as given, through
// session::send_word; Enable is its walk to OPERATION ENABLED through the core's planner, Stop its
// quick stop then Disable voltage, the jog its profile-velocity jog with the dead-man), object reads
// and writes, polling, and the lease that stops the drive as 0x6007 says when no page renews it.
// The page's: what became of each action (results), the snapshots, the recorder, and for a drive in
// this process the plant's inputs (STO, DC link, fault causes) through the simulator's view, with
// the exact transition numbers its steps report (a drive on a bus reports states: the numbers are
// inferred, transition_inference.hpp).
//
// Thread-safe: the cycle thread calls step(), HTTP threads the rest; a request that needs the
// drive's answer (an object write) waits for it (a drive in this process answers at once).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cia402/axis/drive_link.hpp"
#include "cia402/page/backend.hpp"
#include "cia402/page/parameters.hpp"
#include "cia402/profile.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::page {

/// The drive behind an axis, as the composition builds it.
struct drive_connection {
  std::unique_ptr<axes::drive_link> link;
  /// A drive in this process: its simulator, whose plant inputs the page sets (the link keeps it
  /// alive). nullptr for a drive on a bus.
  sim::virtual_drive* plant = nullptr;
};

/// Builds the drive's connection under a profile: once at start, and again (a drive in this
/// process) when the page picks another profile.
using connection_factory = std::function<drive_connection(const profile&)>;

struct axis_page_config {
  std::uint32_t cycle_us = 1000;  ///< the time one step() stands for
  /// The sign of life: the session stops a drive left enabled (as 0x6007 says) when no client
  /// renewed the lease for this long (step() time); 0: no lease.
  std::uint64_t lease_us = 0;
  std::uint32_t publish_us = 40'000;       ///< at most one snapshot this often, only on change
  std::uint32_t settle_quiet_us = 50'000;  ///< an action settles after this long without change
  std::uint32_t settle_limit_us = 15'000'000;
  /// Each word of a fault-reset edge is held this long (0: one cycle, cycle_us).
  std::uint32_t reset_pulse_us = 0;
  std::uint32_t poll_us = 100'000;  ///< what the cyclic data lacks, each at most this often
  std::size_t results_kept = 8;
  /// Wall time an HTTP request waits for the drive's answer before it is answered 504.
  std::chrono::milliseconds request_timeout{10000};
  /// A drive in this process: the profiles the page may switch to (each must outlive the page);
  /// empty: the built-in ones and its own.
  std::vector<const profile*> selectable;
  /// A drive on a bus, as the page names it: its node-ID or position, the bus ("socketcand://...",
  /// "EtherCAT eth1"), and where that is not enough, where it is ("slave 0 on EtherCAT eth1").
  int node = 0;
  std::string bus;
  std::string where;
  /// Entries the composition knows beyond the CiA 402 object table (a CAN node's communication and
  /// identity objects from its dictionary or EDS); the table's entry wins where both have one.
  std::vector<parameter_entry> parameters;
  /// The parameter files (CiA 306 DCF from `cia402 serve`); empty: none offered.
  parameter_file_format parameter_file;
  /// The time of day (microseconds since the Unix epoch) an error seen is stamped with beside the
  /// drive's time, so the history says when it happened; none: the drive's time alone.
  std::function<std::uint64_t()> wall_clock_us;
};

class axis_page : public backend {
 public:
  /// The profile must outlive the page. Throws std::invalid_argument when the factory gives no link.
  axis_page(const profile& p, connection_factory connect, axis_page_config config = {});
  ~axis_page() override;
  axis_page(const axis_page&) = delete;
  axis_page& operator=(const axis_page&) = delete;

  /// advance(cycle_us).
  void step() override;
  /// `elapsed_us` of time for the session and its link (0 lets answers received take effect).
  void advance(std::uint32_t elapsed_us);

  reply command(page_command c) override;
  reply toggle_control_bit(int bit) override;
  reply new_setpoint() override;
  reply enable() override;
  reply stop() override;
  reply jog(std::int64_t velocity_rpm, std::uint64_t time_to_live_us) override;
  reply write_object(std::uint16_t index, std::int64_t value) override;
  reply write_entry(std::uint16_t index, std::uint8_t sub, std::string_view value) override;
  document parameters() override;
  document parameter_file() override;
  document load_parameter_file(std::string_view text) override;
  reply change_plant(const plant_change& change) override;
  reply home(const homing_request& r) override;
  reply read_error_field() override;
  reply clear_error_field() override;
  reply select_profile(std::string_view name) override;
  void renew_lease() override;

  std::string info_json(bool control, bool token_required) const override;
  std::string snapshot_json() const override;
  std::string recording_json(std::uint64_t rows_seen, std::uint64_t transitions_seen) const override;
  std::string recording_file(recording_format format) const override;
  std::uint64_t samples_end() const override;
  std::string samples_json(std::uint64_t from, std::size_t max, std::uint64_t& next) const override;
  std::optional<published> wait_for_update(std::uint64_t seen, std::chrono::milliseconds timeout) override;
  published latest() const override;
  void close() override;
  bool closed() const override;

  /// The end, once the cycle thread stopped: the session stops a drive left enabled as its 0x6007
  /// says, then the link puts back what it changed on the node (PDO mappings, heartbeats; an
  /// EtherCAT line leaves OP), polled on the steady clock for at most `wait`. Then close().
  void shut_down(std::chrono::milliseconds wait);
  /// Cycles stepped so far.
  std::uint64_t cycle() const;
  /// Where the link stands, in words ("" while it runs): "node 1 does not answer (...)".
  std::string link_text() const;
  /// The drive on the bus takes injected faults (a `cia402 bus` node, 0x1008 and 0x2001).
  bool fault_injection_available() const;

  struct impl;

 private:
  std::unique_ptr<impl> impl_;
};

}  // namespace cia402::page
