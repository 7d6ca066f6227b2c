// A CANopen master for one CiA 402 drive: it configures the drive over SDO, starts it with NMT, then
// runs the core's master step (cia402::master, master.hpp) over PDOs, one SYNC per cycle.
//
// Configuration, in order (each an SDO transfer; the first that fails ends it with a clear error):
//   1. read 0x1000 and require device profile 402 (low word 0x0192): a missing node shows here as an
//      SDO timeout;
//   2. read the option codes 0x605A..0x605E and 0x6007 (absent ones keep the profile's default), so
//      the master's command paths are planned with the drive's own codes;
//   3. 0x1017 = drive heartbeat time (the master watches it: 3 x that time without one = lost);
//   4. with a master heartbeat: 0x1016 sub 1 = this master's node-ID and 3 x its period, so the drive
//      applies 0x6007 when the master goes silent;
//   5. TPDO1 = 0x6041 + 0x603F (0x6041 alone if the drive cannot map 0x603F), synchronous (type 1);
//      RPDO1 = 0x6040, event-driven (type 255): disable, clear, map, count, type, enable;
//   6. NMT start.
// Then each cycle: SYNC; the drive answers with TPDO1; the master step turns the status word into the
// next control word, sent at once in RPDO1. Nothing is sent in RPDO1 until a target or a command is
// set, so watching a drive never commands it; the configuration above (PDO mapping, 0x1017, NMT
// start) is still written. The clock is passed in (process(elapsed)).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "cia402/canopen/channel.hpp"
#include "cia402/canopen/nmt.hpp"
#include "cia402/canopen/sdo_client.hpp"
#include "cia402/canopen/timing.hpp"
#include "cia402/master.hpp"
#include "cia402/profile.hpp"

namespace cia402::canopen {

struct drive_master_config {
  std::uint8_t node_id = 1;
  std::uint8_t master_node_id = 127;     ///< the master's own heartbeat identifier, 0x700 + this
  std::uint32_t cycle_us = 10000;        ///< SYNC period
  std::uint16_t drive_heartbeat_ms = 100;   ///< written to the drive's 0x1017; 0 = not watched
  std::uint16_t master_heartbeat_ms = 0;    ///< produced, and watched by the drive; 0 = off
  std::uint32_t sdo_timeout_us = 500000;
  std::uint64_t transition_timeout_us = 3000000;  ///< per transition, 0 = none
  const profile* drive_profile = nullptr;  ///< the drive's profile; nullptr = the standard one
};

enum class master_phase : std::uint8_t { configuring, running, failed };

enum class master_failure : std::uint8_t {
  none,
  no_answer,       ///< an SDO request timed out: the node is missing or silent
  sdo_refused,     ///< the drive refused a configuration request (abort code in failed_abort())
  not_a_drive,     ///< 0x1000 does not name device profile 402
  heartbeat_lost,  ///< the drive's heartbeat stopped
};
const char* master_failure_name(master_failure f) noexcept;

class drive_master {
 public:
  drive_master(channel& out, const drive_master_config& config);
  drive_master(const drive_master&) = delete;
  drive_master& operator=(const drive_master&) = delete;

  void on_frame(const frame& f);
  std::uint32_t process(std::uint32_t elapsed_us);
  /// Every frame waiting on `in`, then process(elapsed).
  std::uint32_t poll(channel& in, std::uint32_t elapsed_us);

  /// Drive towards a state with the core's master step (once running; before, it waits).
  void set_target(state target);
  /// Send one fixed command every cycle instead (e.g. Quick stop), encoded for the profile.
  void set_command(command c);
  /// Stop steering: RPDO1 is no longer sent.
  void clear_target();

  master_phase phase() const noexcept { return phase_; }
  master_failure failure() const noexcept { return failure_; }
  /// For sdo_refused / no_answer: the object and the abort code.
  sdo_abort failed_abort() const noexcept { return failed_abort_; }
  std::uint16_t failed_index() const noexcept { return failed_index_; }
  std::uint8_t failed_sub() const noexcept { return failed_sub_; }
  /// A one-line English description of the failure.
  std::string failure_text() const;

  /// The last status word and error code from TPDO1; false before the first one.
  bool status_known() const noexcept { return status_known_; }
  std::uint16_t status_word() const noexcept { return status_word_; }
  std::uint16_t error_code() const noexcept { return error_code_; }
  /// The state the last status word shows (start if none or unreadable).
  state observed() const noexcept { return observed_; }
  master_outcome outcome() const noexcept { return master_.outcome(); }
  bool steering() const noexcept { return mode_ != mode::idle; }
  const cia402::master& core_master() const noexcept { return master_; }
  std::uint64_t now_us() const noexcept { return now_us_; }
  /// The drive's option code as read during configuration (or the profile's default).
  std::int8_t option_code(option o) const noexcept { return options_.options[static_cast<int>(o)]; }

  /// Called for each EMCY of the drive: error code, error register, the 5 manufacturer bytes.
  std::function<void(std::uint16_t code, std::uint8_t reg, const std::uint8_t* bytes)> on_emcy;
  /// Called when the observed state changes.
  std::function<void(state from, state to, std::uint16_t status_word)> on_state;

 private:
  struct sdo_step {
    bool write = false;
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    std::function<std::int64_t()> value;
    unsigned bytes = 0;
    bool optional = false;
    std::function<void(const sdo_client&)> then;  // after it finished (done or optional abort)
  };
  enum class mode : std::uint8_t { idle, target, command };

  void build_script();
  void start_step();
  void fail(master_failure f, sdo_abort a, std::uint16_t index, std::uint8_t sub);
  void on_status(std::uint16_t sw, std::uint16_t err);
  void send_control_word(std::uint16_t cw);

  channel* out_;
  drive_master_config config_;
  const profile* profile_;
  sdo_client sdo_;
  heartbeat_producer producer_;
  heartbeat_consumer consumer_;
  interval_timer sync_timer_;
  master_phase phase_ = master_phase::configuring;
  master_failure failure_ = master_failure::none;
  sdo_abort failed_abort_ = sdo_abort::none;
  std::uint16_t failed_index_ = 0;
  std::uint8_t failed_sub_ = 0;
  std::vector<sdo_step> script_;
  std::size_t step_ = 0;
  bool step_started_ = false;
  bool error_code_mapped_ = false;
  axis options_;  // the drive's option codes, read in step 2
  master_policy policy_{};
  cia402::master master_;
  mode mode_ = mode::idle;
  state pending_target_ = state::switch_on_disabled;
  command command_ = command::disable_voltage;
  bool status_known_ = false;
  std::uint16_t status_word_ = 0;
  std::uint16_t error_code_ = 0;
  state observed_ = state::start;
  std::uint64_t now_us_ = 0;
};

}  // namespace cia402::canopen
