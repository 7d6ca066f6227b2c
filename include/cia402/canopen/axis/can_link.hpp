// The axis session's link to a CiA 402 drive on a CAN bus (axis/drive_link.hpp): a CANopen node
// reached by SDO, and from start_cyclic() on by PDOs with SYNC through the project's CANopen 402
// master (canopen/master/drive_master.hpp).
//
// Stages:
// - acyclic, from the start: SDO transfers only (its own client), nothing set up, the node's NMT
//   state untouched: what `state`, `sdo` and a reset of a drive that is not in FAULT need;
// - start_cyclic(): first every object the master's set-up will write is read and recorded (PDO
//   communication and mapping parameters, 0x1017, 0x1016 entries), then the set-up runs (heartbeat,
//   TPDO1 = 0x6041 + 0x603F and TPDO2 = 0x606C, RPDO1 = 0x6040, with `map_position` RPDO3 = 0x6040 +
//   0x607A and TPDO3 = 0x6041 + 0x6064, NMT start) and the SYNC cycle runs;
// - close(): the recorded objects are written back in reverse order, each PDO invalid while its
//   mapping is put back (CiA 301's rule), then its own COB-ID as it was; what could not be written
//   is said in the report. The NMT state the master started the node into stays (it cannot know
//   the one before: the node's heartbeat was off), and the report says so. Every transfer still
//   queued in the link ends then, cancelled, with the reason.
//
// NMT through send_nmt(): the link knows what it asked of the node. After NMT stop the node serves
// no SDO (CiA 301 §7.3.2.2.4): a transfer under way goes again, and every transfer waits, until NMT
// start or preop (one that waits longer than the SDO timeout ends with that reason; the link does
// not count the node lost). After stop or preop the node sends no PDO: the status word known is
// old, and the link says it does not know it until the first one after NMT start. After a reset
// before the cyclic stage, transfers wait for the boot-up message; a node that boots up after the
// link talked to it is a restart (link_event::restarted, transfers queued cancelled), as in the
// cyclic stage, where the 402 master sets it up again.
//
// Types for describe(): an EDS or DCF given by the user first, then the project's CANopen drive
// dictionary for CiA 301's objects 0x1000..0x1FFF, and for a node that calls itself "cia402 virtual
// drive" (0x1008) its manufacturer objects too (0x2000 label, 0x2001 fault injection).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cia402/axis/drive_link.hpp"
#include "cia402/canopen/301/nmt.hpp"
#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/canopen/301/sdo_client.hpp"
#include "cia402/canopen/master/drive_master.hpp"
#include "cia402/canopen/can/channel.hpp"
#include "cia402/profile.hpp"

namespace cia402::canopen {

struct can_link_config {
  std::uint8_t node_id = 1;
  std::string bus_name;                    ///< what() names it: "socketcand://127.0.0.1:29536/can0"
  std::uint32_t cycle_us = 10000;          ///< the SYNC period
  std::uint16_t drive_heartbeat_ms = 100;  ///< 0x1017, watched at 3x
  std::uint16_t master_heartbeat_ms = 0;   ///< the master's own, watched by the drive (0x1016)
  std::uint32_t sdo_timeout_us = 500000;
  /// Set-up starts again this long after the node stopped answering (drive_master_config::retry_us);
  /// 0: the link stays failed.
  std::uint32_t retry_us = 0;
  const profile* drive_profile = nullptr;
  bool map_position = false;               ///< PDO 3 for a csp stream
  /// The node's objects as an EDS describes them (read_eds), if the user gave one.
  std::vector<dictionary::object_entry> eds;
  /// Without an EDS: the objects of the project's virtual drive as a node serves them (the caller's,
  /// e.g. canopen::node_objects(apps::drive_node_config(n))): their CiA 301 objects (0x1000..0x1FFF)
  /// are taken as any node's, their manufacturer objects (0x2000..0x5FFF) only on a node whose 0x1008
  /// names the virtual drive.
  std::vector<dictionary::object_entry> known_objects;
  /// The clock the master's heartbeat runs on (drive_master_config::heartbeat_clock_us).
  std::function<std::uint64_t()> heartbeat_clock_us;
};

class can_link final : public axes::link_base {
 public:
  /// `bus` must outlive the link; the link reads every frame it receives.
  can_link(channel& bus, can_link_config config);
  ~can_link() override;

  std::uint32_t poll(std::uint32_t elapsed_us) override;
  axes::link_phase phase() const override;
  std::string phase_text() const override;
  std::string what() const override;
  std::string short_name() const override;

  bool cyclic() const override;
  void start_cyclic() override;
  std::uint32_t cycle_us() const override { return config_.cycle_us; }
  bool status_known() const override;
  std::uint16_t status_word() const override;
  std::optional<std::uint16_t> error_code() const override;
  void set_control_word(std::uint16_t word) override;

  std::optional<std::int64_t> cyclic_input(std::uint16_t index, std::uint8_t sub) const override;
  bool set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) override;

  std::optional<axes::value_format> describe(std::uint16_t index, std::uint8_t sub) const override;
  /// The most bytes the entry holds as the EDS or the known objects say (0: not known).
  std::size_t most_bytes(std::uint16_t index, std::uint8_t sub) const;

  void close() override;

  /// CAN only: one NMT command to the node.
  std::error_code send_nmt(nmt_command c);
  /// The master once the cyclic exchange was asked for (nullptr before).
  const drive_master* master() const noexcept { return master_.get(); }

 private:
  enum class stage : std::uint8_t { acyclic, recording, setting_up, cyclic, restoring, closed };
  using transfer = axes::pending_transfer;
  struct recorded {
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    std::vector<std::uint8_t> bytes;  // empty: the node has no such object (nothing to put back)
  };

  void on_frame(const frame& f);
  void run_own_transfers(std::uint32_t elapsed_us);
  void make_master();
  void record_next();
  void note_name(std::uint16_t index, std::uint8_t sub, const std::vector<std::uint8_t>& data);
  void fail_own(std::string text);
  bool queue_transfer(transfer t) override;
  bool forward(transfer t);
  void hold_own_transfer();
  void run_held();
  void end_held();
  void on_boot_up();
  void learn_cyclic();
  // can_restore.cpp
  std::vector<recorded> restore_order() const;
  void restore_next();
  void finish_close();

  channel* bus_;
  can_link_config config_;
  stage stage_ = stage::acyclic;
  std::string failure_;  // the acyclic stage's own failure (no answer, bus gone)
  sdo_client sdo_;
  std::deque<transfer> own_;      // transfers through sdo_ (acyclic, recording), or held while STOPPED
  bool own_busy_ = false;
  std::vector<std::pair<std::uint16_t, std::uint8_t>> to_record_;
  std::vector<recorded> recorded_;
  std::unique_ptr<drive_master> master_;
  std::vector<transfer> finished_;  // transfers done, said at the next poll
  std::vector<std::pair<transfer, axes::transfer_result>> results_;

  // What this link's own NMT commands did to the node (send_nmt), until the node shows otherwise.
  bool sdo_held_ = false;    // NMT stop sent: no SDO until NMT start or preop
  bool booting_ = false;     // NMT reset sent before the cyclic stage: SDO waits for the boot-up
  bool pdos_quiet_ = false;  // NMT stop or preop sent: the status word known is old
  bool start_sent_ = false;  // NMT start sent since: the next status word is new
  bool talked_ = false;      // a transfer went to the node: a boot-up from now on is a restart
  std::uint64_t now_us_ = 0;
  std::uint64_t held_since_us_ = 0;

  std::optional<std::uint16_t> word_;
  std::string device_name_;

  std::vector<recorded> restoring_;
  std::size_t restore_at_ = 0;
  bool restore_busy_ = false;
};

}  // namespace cia402::canopen
