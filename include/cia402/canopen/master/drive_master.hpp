// The CANopen bus master for one CiA 402 drive: it sets the drive up over SDO, starts it with NMT,
// then carries words over PDOs. It does not steer: the axis session (cia402/axis/session.hpp) is the
// one master, and its CAN link (cia402/canopen/axis/can_link.hpp) hands this class the session's
// control words (send_control_word) and reads the status word back, for `cia402 master --can` and
// `cia402 serve --can` alike.
//
// Set-up, in order (each an SDO transfer; the first required one that fails ends it with a clear
// error: "does not answer" for a timeout, "refused" with the abort code otherwise):
//   1. read 0x1000 and require device profile 402 (low word 0x0192);
//   2. read 0x1008, the device name (optional); on a node of `cia402 bus` ("cia402 virtual drive")
//      read 0x2001 too: "write-only" (0x06010001) says faults may be injected by writing it. No
//      other drive's 0x2001 is touched: there it is some manufacturer object of unknown meaning;
//   3. read the option codes 0x605A..0x605E and 0x6007 (absent ones keep the profile's default;
//      option_code() and start_values() say them), then `read_at_start` (optional reads);
//   4. 0x1017 = drive heartbeat time (the master watches it at 3x; optional unless
//      `heartbeat_required`: without it a silent node is found by SDO polling);
//   5. with a master heartbeat: 0x1016 sub 1 = this master's node-ID and 3 x its period, so the drive
//      applies 0x6007 when the master goes silent; without one, an entry for this master's node-ID
//      that an earlier run left in 0x1016 sub 1 is cleared (another node's is left alone);
//   6. TPDO1 = 0x6041 + 0x603F (0x6041 alone if the drive cannot map 0x603F): synchronous (type 1)
//      with `pdo_timing::sync`, else on change (255) with no inhibit time, so every state arrives;
//      TPDO2 = 0x606C on change with `map_velocity` (optional as a whole); RPDO1 = 0x6040 on receipt;
//      with `map_position` (a cyclic synchronous position master, pdo_timing::sync): RPDO3 = 0x6040 +
//      0x607A taken at the next SYNC and TPDO3 = 0x6041 + 0x6064 on every SYNC (both type 1, the
//      drive's defaults, written all the same: required); each PDO: disable, clear, map, count, type,
//      enable;
//   7. on change only: the present 0x6040, 0x6041, 0x603F, 0x606C, so the master starts from them;
//   8. NMT start.
// Running: with `pdo_timing::sync` one SYNC per cycle; the drive answers with TPDO1 (on_status). With `map_position` and a
// set-point given (set_position_set_point), RPDO3 (the last control word sent and the set-point) goes
// out just before each SYNC, after `before_sync` has had the chance to move the set-point on; TPDO3's
// position is kept (position()) and reported (on_position); a control word given while the set-point
// has changed since the last RPDO3 goes in the next RPDO3 instead of RPDO1, so a pp handshake's
// bit 4 and its target take effect at the same SYNC. Words set with
// `send_control_word` go out when given (a fault-reset edge as bit 7 high for `reset_pulse_us`).
// Nothing is sent in RPDO1 until a word is given, so watching a drive never commands it. Requests (`read`, `write`) run one at a time between polls of what no PDO carries
// (0x1001, and 0x606C / 0x603F / 0x6041 when not mapped or watched) every `poll_us`.
//
// Any SDO timeout or a lost heartbeat is "does not answer"; with `retry_us` set-up starts again that
// long after a failure, and a boot-up message starts it again at once. A failed channel ends it for
// good. The clock is passed in (process(elapsed)); nothing here blocks or starts a thread.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cia402/canopen/can/channel.hpp"
#include "cia402/canopen/301/nmt.hpp"
#include "cia402/canopen/301/sdo_client.hpp"
#include "cia402/canopen/301/timing.hpp"
#include "cia402/drive.hpp"
#include "cia402/profile.hpp"

namespace cia402::canopen {

/// When the drive sends its status word: at each SYNC of the master, or whenever it changes.
enum class pdo_timing : std::uint8_t { sync, on_change };

struct drive_master_config {
  std::uint8_t node_id = 1;
  std::uint8_t master_node_id = 127;     ///< the master's own heartbeat identifier, 0x700 + this
  std::uint32_t cycle_us = 10000;        ///< SYNC period (pdo_timing::sync)
  std::uint16_t drive_heartbeat_ms = 100;   ///< written to the drive's 0x1017; 0 = not watched
  bool heartbeat_required = true;           ///< false: a refused 0x1017 or 0x1016 is run without
  std::uint16_t master_heartbeat_ms = 0;    ///< produced, and watched by the drive; 0 = off
  /// The clock the master's own heartbeat runs on, in microseconds from any start; empty: the time
  /// given to process(). The drive watches that heartbeat on its own (wall) time, which a master
  /// whose process() time lags the wall (a held-up host skipping cycles) would otherwise miss.
  std::function<std::uint64_t()> heartbeat_clock_us;
  std::uint32_t sdo_timeout_us = 500000;
  const profile* drive_profile = nullptr;  ///< the drive's profile; nullptr = the standard one
  pdo_timing timing = pdo_timing::sync;
  bool map_velocity = false;               ///< TPDO2 = 0x606C, on change
  std::uint16_t velocity_inhibit_100us = 200;  ///< TPDO2's inhibit time
  bool map_position = false;               ///< RPDO3 = 0x6040 + 0x607A, TPDO3 = 0x6041 + 0x6064, on SYNC
  std::vector<std::uint16_t> read_at_start;    ///< sub 0 of each, read during set-up (optional)
  std::uint32_t poll_us = 0;               ///< SDO polling of what no PDO carries; 0 = none
  std::uint32_t retry_us = 0;              ///< set-up starts again this long after a failure; 0 = never
  std::uint32_t reset_pulse_us = 20000;    ///< bit 7 high this long for a fault-reset edge
};

enum class master_phase : std::uint8_t { configuring, running, failed };

enum class master_failure : std::uint8_t {
  none,
  no_answer,       ///< an SDO request timed out: the node is missing or silent
  sdo_refused,     ///< the drive refused a configuration request (abort code in failed_abort())
  not_a_drive,     ///< 0x1000 does not name device profile 402
  heartbeat_lost,  ///< the drive's heartbeat stopped
  bus_failed,      ///< the channel failed (e.g. the socketcand server went away): for good
};
const char* master_failure_name(master_failure f) noexcept;

/// How a request ended. `cancelled`: the link was lost (or set-up restarted) before it ran.
struct sdo_result {
  bool cancelled = false;
  sdo_abort abort = sdo_abort::none;
  std::int64_t value = 0;  ///< after a done read: the value, sign-extended when asked
  std::vector<std::uint8_t> data;  ///< after a done read: its bytes
  bool ok() const noexcept { return !cancelled && abort == sdo_abort::none; }
};

/// Why the phase changed, for on_phase.
enum class phase_reason : std::uint8_t { started, running, failed, retrying, node_restarted };

class drive_master {
 public:
  drive_master(channel& out, const drive_master_config& config);
  drive_master(const drive_master&) = delete;
  drive_master& operator=(const drive_master&) = delete;

  void on_frame(const frame& f);
  std::uint32_t process(std::uint32_t elapsed_us);
  /// Every frame waiting on `in`, then process(elapsed).
  std::uint32_t poll(channel& in, std::uint32_t elapsed_us);

  /// Send this word in RPDO1 now (once running; given before, it waits for the running phase, and
  /// a failure or a restart of the set-up drops it). With `fault_reset_edge`, bit 7 rises and falls: the word without bit 7 first if the last one
  /// had it, then with it, then without, each held `reset_pulse_us`, so the drive steps on both
  /// levels. Words of an earlier call not yet sent are dropped.
  void send_control_word(std::uint16_t word, bool fault_reset_edge = false);
  /// Stop carrying words: words still queued are dropped, none goes out until the next
  /// send_control_word. (The name is can_link's; there is no target here.)
  void clear_target();
  /// With `map_position`: the target position RPDO3 carries before every SYNC (with the last control
  /// word sent), once a control word has been sent; nullopt stops RPDO3.
  void set_position_set_point(std::optional<std::int32_t> position) noexcept {
    if (position != position_set_point_) set_point_unsent_ = true;
    position_set_point_ = position;
  }
  std::optional<std::int32_t> position_set_point() const noexcept { return position_set_point_; }

  /// Queue an SDO transfer for when the master is running; `done` is called in process() or
  /// on_frame() when it ends (or is cancelled). False, and nothing queued, while not running.
  bool read(std::uint16_t index, std::uint8_t sub, bool is_signed,
            std::function<void(const sdo_result&)> done);
  bool write(std::uint16_t index, std::uint8_t sub, std::int64_t value, unsigned bytes,
             std::function<void(const sdo_result&)> done);
  /// The same with the object's bytes as they travel (a text, a domain, a number of any size):
  /// expedited up to 4 bytes, segmented beyond.
  bool upload(std::uint16_t index, std::uint8_t sub, std::function<void(const sdo_result&)> done);
  bool download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes,
                std::function<void(const sdo_result&)> done);
  /// A request queued or in flight.
  bool request_pending() const noexcept;
  /// Every object the set-up may write, in the order it writes them first (each once): what a
  /// caller reads beforehand to put the node back as it was.
  std::vector<std::pair<std::uint16_t, std::uint8_t>> objects_written() const;

  master_phase phase() const noexcept { return phase_; }
  master_failure failure() const noexcept { return failure_; }
  /// For sdo_refused / no_answer: the object and the abort code.
  sdo_abort failed_abort() const noexcept { return failed_abort_; }
  std::uint16_t failed_index() const noexcept { return failed_index_; }
  std::uint8_t failed_sub() const noexcept { return failed_sub_; }
  /// A one-line English description of the failure.
  std::string failure_text() const { return failure_ == master_failure::none ? "no failure" : text_; }
  /// Where the link stands in one line: why it is configuring or failed; empty while running.
  const std::string& phase_text() const noexcept { return text_; }

  /// The last status word and error code from TPDO1; false before the first one.
  bool status_known() const noexcept { return status_known_; }
  std::uint16_t status_word() const noexcept { return status_word_; }
  std::uint16_t error_code() const noexcept { return error_code_; }
  std::uint8_t error_register() const noexcept { return error_register_; }
  std::optional<std::int32_t> velocity() const noexcept { return velocity_; }
  /// 0x6064 from the last TPDO3 (with `map_position`); nullopt before the first.
  std::optional<std::int32_t> position() const noexcept { return position_; }
  std::optional<std::uint16_t> last_emcy() const noexcept { return last_emcy_; }
  /// The NMT state of the drive's last heartbeat.
  std::optional<std::uint8_t> nmt_seen() const noexcept { return nmt_seen_; }
  /// The state the last status word shows (start if none or unreadable).
  state observed() const noexcept { return observed_; }
  std::uint64_t now_us() const noexcept { return now_us_; }
  /// The drive's option code as read during configuration (or the profile's default).
  std::int8_t option_code(option o) const noexcept { return options_.options[static_cast<int>(o)]; }
  /// The last word sent in RPDO1 (or the drive's 0x6040 as read at set-up).
  std::uint16_t last_sent() const noexcept { return last_sent_; }
  /// Words set with send_control_word not yet sent.
  bool words_queued() const noexcept { return !outbox_.empty(); }

  // What set-up found out.
  const std::string& device_name() const noexcept { return device_name_; }
  bool fault_injection() const noexcept { return fault_injection_; }
  bool heartbeat_watched() const noexcept { return heartbeat_watched_; }
  bool error_code_mapped() const noexcept { return error_code_mapped_; }
  bool velocity_mapped() const noexcept { return velocity_mapped_; }
  bool position_mapped() const noexcept { return position_mapped_; }
  /// What set-up read (the option codes and `read_at_start`): only what the drive answered.
  const std::map<std::uint16_t, std::int64_t>& start_values() const noexcept { return start_values_; }

  /// Called for each EMCY of the drive: error code, error register, the 5 manufacturer bytes.
  std::function<void(std::uint16_t code, std::uint8_t reg, const std::uint8_t* bytes)> on_emcy;
  /// Called when the observed state changes.
  std::function<void(state from, state to, std::uint16_t status_word)> on_state;
  /// Called for every status word received (TPDO1 or an SDO read), before on_state.
  std::function<void(std::uint16_t status_word)> on_status;
  /// Called for every velocity received.
  std::function<void(std::int32_t velocity)> on_velocity;
  /// Called for every position received (TPDO3, with `map_position`).
  std::function<void(std::int32_t position)> on_position;
  /// Called just before each SYNC goes out (and RPDO3 before it): the moment to set the next cyclic
  /// set-point.
  std::function<void()> before_sync;
  /// Called for every word sent in RPDO1.
  std::function<void(std::uint16_t word)> on_sent;
  /// Called when the phase changes, with why; phase_text() says it in words.
  std::function<void(master_phase phase, phase_reason why)> on_phase;

 private:
  struct sdo_job {
    bool write = false;
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    std::function<std::int64_t()> value;
    unsigned bytes = 0;
    std::optional<std::vector<std::uint8_t>> raw;  // a download of these bytes as they are
    bool is_signed = false;
    bool optional = false;  // set-up: a refusal does not end it (a timeout does)
    int group = 0;          // set-up: a refusal skips the rest of the group
    std::function<bool()> wanted;  // set-up: runs only if this says so
    std::function<void(const sdo_client&)> then;  // after a done transfer (or an optional refusal)
    std::function<void(const sdo_result&)> done;  // a request's own callback
    bool nmt_start = false;  // not a transfer: NMT start, then running
  };
  /// The set-up script (build_script), in the order drive_master.hpp gives: who the drive is,
  /// the values read at start, error control, the PDOs, the present values, NMT start.
  void build_script();
  void script_identity();
  void script_start_values();
  void script_error_control();
  void script_pdos();
  void script_present_values();
  void restart(phase_reason why, std::string text);
  void go_running();
  void fail(master_failure f, sdo_abort a, std::uint16_t index, std::uint8_t sub, std::string text);
  void drop_requests();
  /// A request for object `index`:`sub` whose result goes to `done`; `j` says the rest (a read, or
  /// a download of its bytes). False, nothing queued, unless running.
  bool queue_request(std::uint16_t index, std::uint8_t sub, sdo_job j,
                     std::function<void(const sdo_result&)> done);
  void start_transfer(const sdo_job& j);
  bool start_next_job();
  void complete_current();
  void drive_jobs();
  sdo_job next_poll();
  void note_status(std::uint16_t sw);
  void note_velocity(std::int32_t v);
  void send_word(std::uint16_t cw);
  void send_sync();
  void set_phase(master_phase p, phase_reason why);
  std::string node_text() const;

  channel* out_;
  drive_master_config config_;
  const profile* profile_;
  sdo_client sdo_;
  heartbeat_producer producer_;
  std::optional<std::uint64_t> heartbeat_clock_before_;  // heartbeat_clock_us at the last process()
  heartbeat_consumer consumer_;
  bool heartbeat_lost_ = false;
  interval_timer sync_timer_;
  master_phase phase_ = master_phase::configuring;
  master_failure failure_ = master_failure::none;
  sdo_abort failed_abort_ = sdo_abort::none;
  std::uint16_t failed_index_ = 0;
  std::uint8_t failed_sub_ = 0;
  std::string text_;
  bool started_ = false;  // the first process() call starts set-up

  std::vector<sdo_job> script_;
  std::size_t step_ = 0;
  int skipped_group_ = 0;
  std::optional<sdo_job> current_;
  std::deque<sdo_job> requests_;
  std::uint64_t next_poll_us_ = 0;
  std::size_t poll_index_ = 0;
  std::uint64_t retry_at_us_ = 0;

  std::string device_name_;
  bool fault_injection_ = false;
  bool heartbeat_watched_ = false;
  bool error_code_mapped_ = false;
  bool velocity_mapped_ = false;
  bool position_mapped_ = false;
  bool stale_guard_ = false;  // 0x1016 watches this master's node-ID, left by an earlier run
  std::map<std::uint16_t, std::int64_t> start_values_;

  axis options_;  // the drive's option codes, read at set-up
  std::deque<std::pair<std::uint16_t, std::uint64_t>> outbox_;  // word, not before (us)
  std::uint16_t last_sent_ = 0;
  bool word_sent_ = false;  // a control word went out since running: RPDO3 may carry it
  std::optional<std::int32_t> position_set_point_;
  // A set-point newer than the last RPDO3: a control word given now waits for that RPDO3, so the
  // drive takes both at one SYNC (a new-set-point bit never meets the old target).
  bool set_point_unsent_ = false;

  bool status_known_ = false;
  std::uint16_t status_word_ = 0;
  std::uint16_t error_code_ = 0;
  std::uint8_t error_register_ = 0;
  std::optional<std::int32_t> velocity_;
  std::optional<std::int32_t> position_;
  std::optional<std::uint16_t> last_emcy_;
  std::optional<std::uint8_t> nmt_seen_;
  state observed_ = state::start;
  std::uint64_t now_us_ = 0;
};

}  // namespace cia402::canopen
