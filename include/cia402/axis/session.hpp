// One axis session: everything CiA 402 a master does for one drive that is not fieldbus, over any
// drive_link (drive_link.hpp). Poll-driven, no threads, no clock: time comes in through
// poll(elapsed). One instance per drive.
//
// It owns:
// - start-up reads, once the link runs: the option codes 0x605A..0x605E and 0x6007 (so the core's
//   planner plans with the drive's own codes), 0x6502 (the modes the drive announces), 0x6061, and
//   0x1008 (the device name) where present;
// - state targets through the core's `cia402::master` (the planner: S17, never through OPERATION
//   ENABLED to reach another state), and the fault-reset edge (`cia402::fault_reset_edge`, each word
//   held `reset_pulse_us` and until the drive has answered it: a drive that steps once between two
//   words of the edge would never see bit 7 rise);
// - the object job queue: FIFO, one transfer at a time; an object the link carries in its cyclic
//   outputs is written there instead (an SDO would be undone by the next cycle);
// - polling of what the cyclic data does not carry (0x6061, 0x6064, 0x606C, 0x6077, 0x603F, ...),
//   each object at most every `poll_us`, only while something needs it, after the queued jobs;
// - operations: mode switches confirmed by 0x6061, the pp set-point handshake, homing, profile
//   velocity and torque, csp / csv / cst streaming, jog, halt, quick stop, stop. One operation runs
//   at a time: a new one supersedes the last, which ends `superseded`. Object jobs queue beside it.
//   A request that cannot work says why at once (the mode the drive shows and the one needed, no DC
//   link, FAULT with 0x603F and its text, remote off, the drive's SDO abort); a motion command
//   switches the mode itself first where that is its meaning (move -> pp, velocity -> pv, torque ->
//   tq, home -> hm, jog -> pv);
// - limits before motion (S20): a motion command reads the drive's own limits first (0x607F and
//   0x6080 for a velocity, 0x6072 for a torque, 0x607D for a position, 0x60E3 for a homing method,
//   0x6502 for the mode) and refuses a target beyond them at once (bad_input), naming the object,
//   its value and the target, before anything is sent;
// - the failure path (S20): a motion command that fails once it commanded the drive (a time-out,
//   a fault, a lost link, a refused SDO, a blocker, cancel()) stops what it set moving: halt as
//   0x605D says, then quick stop, then Disable voltage, each within stop_timeout_us. Its completion
//   comes once the shaft stands, and its error says the cause and what was done;
// - the lease: with `lease_us` set, a client that stops calling renew() gets the drive stopped as
//   0x6007 says (docs/master.md, "The lease"): within lease_us plus one cycle of the link.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cia402/axis/drive_link.hpp"
#include "cia402/axis/object_value.hpp"
#include "cia402/master.hpp"
#include "cia402/profile.hpp"

namespace cia402::axes {

struct session_config {
  const profile* drive_profile = nullptr;            ///< nullptr: the standard profile
  std::uint64_t transition_timeout_us = 3'000'000;   ///< each state-machine transition
  std::uint64_t mode_timeout_us = 1'000'000;         ///< 0x6061 showing what 0x6060 was given
  std::uint64_t acknowledge_timeout_us = 1'000'000;  ///< pp: status bit 12 after control bit 4
  std::uint64_t reset_timeout_us = 1'000'000;        ///< FAULT left after a fault-reset edge
  std::uint32_t poll_us = 20'000;                    ///< each polled object at most this often
  /// Each word of a fault-reset edge held at least this long, and until two status words came after it.
  std::uint32_t reset_pulse_us = 20'000;
  /// A status word counts as the answer to a control word once the link brought two after it, or
  /// this long after it (a link that sends on change only).
  std::uint32_t settle_us = 50'000;
  std::uint64_t lease_us = 0;                        ///< 0: no lease
  /// Each stage of a stop (halt, then quick stop, then Disable voltage) waits this long for the
  /// drive to show standstill before the next; every wait for a stop ends.
  std::uint64_t stop_timeout_us = 10'000'000;
};

enum class outcome : std::uint8_t {
  done,
  failed,      ///< `error` says why
  superseded,  ///< a newer operation took over (or the lease lapsed, or the session closed)
};

/// How a request ended, with what it found.
struct result {
  std::uint64_t id = 0;
  outcome end = outcome::done;
  bool bad_input = false;  ///< refused for what was asked, before anything was sent
  std::string error;       ///< why it failed, in words
  std::string note;        ///< a remark on a done request ("not in FAULT, nothing to reset")
  /// An object read or write the drive (or the core's object table) refused: its CiA 301 SDO abort
  /// code; none for any other failure.
  sdo_abort abort = sdo_abort::none;
  std::optional<state> shown;  ///< the state the drive showed at the end
  std::uint16_t status_word = 0;
  std::uint16_t error_code = 0;
  std::optional<std::int8_t> mode;
  std::optional<std::int64_t> position;  ///< 0x6064
  std::optional<std::int64_t> velocity;  ///< 0x606C
  std::optional<std::int64_t> torque;    ///< 0x6077
  // Objects.
  std::optional<object_value> value;
  std::optional<value_format> format;  ///< the type it was read or written as; none: not known
  unsigned size = 0;                   ///< bytes a number of unknown type was written as
  // Streams.
  std::int64_t stream_from = 0;
  std::int64_t stream_to = 0;
  std::uint64_t set_points = 0;
  std::int64_t max_following_error = 0;

  bool ok() const noexcept { return end == outcome::done; }
};
using completion = std::function<void(const result&)>;

/// What an operation reports on its way (on_progress), with the result so far.
enum class progress_kind : std::uint8_t {
  mode_confirmed,   ///< 0x6061 shows the mode (`mode`)
  set_point,        ///< pp: the set-point offered with control bit 4 (`position`)
  target_velocity,  ///< 0x60FF written (`velocity`)
  target_torque,    ///< 0x6071 written (`torque`)
  homing_started,   ///< control bit 4 raised in homing mode
  stream_started,   ///< the drive follows (status bit 12): the stream runs (`stream_from`, `stream_to`)
  jog_started,      ///< turning at the jog velocity (`velocity`)
};

struct move_request {
  std::int32_t target = 0;                 ///< 0x607A
  bool relative = false;                   ///< control bit 6
  std::optional<std::uint32_t> velocity;   ///< 0x6081, rpm
};
struct home_request {
  std::optional<std::int8_t> method;       ///< 0x6098
  std::optional<std::int32_t> offset;      ///< 0x607C
};
/// A set-point source for cyclic synchronous modes: called once each cycle before the outputs go;
/// the next set-point, or nothing when the stream has ended.
using setpoint_source = std::function<std::optional<std::int64_t>()>;

class session {
 public:
  /// The link and the profile (config.drive_profile) must outlive the session.
  explicit session(drive_link& link, const session_config& config = {});
  session(const session&) = delete;
  session& operator=(const session&) = delete;
  ~session();

  /// The session's work for `elapsed_us`: the link's poll, then the jobs, the operation, the lease
  /// and the control word. Returns the microseconds until it next wants to run.
  std::uint32_t poll(std::uint32_t elapsed_us);
  /// Does what needs no time: poll(0), and poll(0) again while a completion waits to be said or
  /// the link has work_now() (a drive in this process answers a chain of transfers this way, one
  /// a round), at most `max_zero_time_polls` rounds. True once nothing is left that needs no time
  /// (an operation may still wait for time: a state change takes the drive's cycles); false at the
  /// bound, with the rest left to the timed polls. On a bus it polls once.
  bool poll_until_idle();
  /// The bound of poll_until_idle(), so a link whose work never ends (a fault of the link) cannot
  /// hold its caller. Each round answers a transfer; the longest chains a client runs without time,
  /// 0x1003 (sub 0, then up to 254 entries) and the page's parameter panel (a read per object), are
  /// far below it. Past it nothing is lost: what is left runs in the timed polls, as on a bus.
  static constexpr int max_zero_time_polls = 4096;

  // --- requests: each returns its id; `done` is called from a later poll() ---------------------
  /// The state, status word and error code (over SDO when the link has no cyclic status yet).
  std::uint64_t read_state(completion done);
  /// A state through the core's planner: OPERATION ENABLED (enable), SWITCH ON DISABLED (disable),
  /// or any other state the profile can hold.
  std::uint64_t go_to(state target, completion done);
  /// Quick stop, done when the stop has ended as 0x605A says.
  std::uint64_t quick_stop(completion done);
  /// A fault-reset edge on a drive in FAULT, done in SWITCH ON DISABLED; on a drive that is not in
  /// FAULT nothing is sent (the result's note says so).
  std::uint64_t reset(completion done);
  /// Control bit 8 set or cleared (in profiles that have a halt, 0x605D).
  std::uint64_t halt(bool on, completion done);
  /// Ends the motion operation and stops the shaft: halt (quick stop where the profile has none),
  /// done at standstill; halt stays set until the next motion command or halt(false).
  std::uint64_t stop(completion done);
  /// 0x6060, done when 0x6061 shows it.
  std::uint64_t set_mode(std::int8_t mode, completion done);
  std::uint64_t move(const move_request& r, completion done);
  std::uint64_t velocity(std::int32_t rpm, completion done);
  std::uint64_t torque(std::int16_t permille, completion done);
  std::uint64_t home(const home_request& r, completion done);
  /// Profile velocity at `rpm` for `hold_us` (renew_jog extends it), then to standstill.
  std::uint64_t jog(std::int32_t rpm, std::uint64_t hold_us, completion done);
  /// The running jog goes on for `hold_us` from now (a button still held).
  void renew_jog(std::uint64_t hold_us);
  /// csp: a ramp of 0x607A from where the drive stands to `to` at `rpm`, exact in integers, one
  /// set-point a cycle; done when 0x6064 shows `to`. 0x607A and 0x6064 must be cyclic.
  std::uint64_t csp_stream(std::int32_t to, std::uint32_t rpm, completion done);
  /// csp (8), csv (9) or cst (10) with set-points from `source`; the mode's set-point object
  /// (0x607A, 0x60FF, 0x6071) must be cyclic.
  std::uint64_t stream(std::int8_t mode, setpoint_source source, completion done);
  /// The running request fails with `why` (a client's own time-out, an interrupt); what it set
  /// moving is stopped first as for any failure (S20). A stop the session runs is not cancelled.
  void cancel(std::string why);
  /// The cyclic exchange, never commanding the drive: done once it runs.
  std::uint64_t watch(completion done);
  /// The client's own control word, every bit as given (the instrument page's command buttons and
  /// bit toggles, seed 003's screen page): held from now on, the planner does not steer it, the
  /// running operation is superseded. With `reset_edge` a fault-reset edge goes first
  /// (cia402::fault_reset_edge: bit 7 low if it was high, then high, then `word` with it low), each
  /// word held reset_pulse_us. Done once the drive has had the last word; a drive in FAULT takes it
  /// too (it is how a client resets one by hand).
  std::uint64_t send_word(std::uint16_t word, bool reset_edge, completion done);
  /// Profile position's set-point offer (the page's "new set-point"): `word` with control bit 4
  /// rising (down first if it was up), held until status bit 12 acknowledges it, then bit 4 down
  /// again, all on the session's cycle. Bit 4 comes down also when no acknowledge came within
  /// acknowledge_timeout_us: then the result failed and says so. Another request supersedes it.
  std::uint64_t offer_set_point(std::uint16_t word, completion done);
  /// An object with its type (the core's table, then the link's describe()); without one, an
  /// upload gives its bytes.
  std::uint64_t read_object(std::uint16_t index, std::uint8_t sub, completion done);
  /// An object with its type; a cyclic output is written there. A number of unknown type goes as
  /// the fewest bytes that hold it, then the next size while the drive says 0x06070012 / 0x06070013.
  std::uint64_t write_object(std::uint16_t index, std::uint8_t sub, const object_value& v, completion done);
  /// What the session knows of an object's type.
  std::optional<value_format> format_of(std::uint16_t index, std::uint8_t sub) const;

  // --- the lease ----------------------------------------------------------------------------------
  /// The client is alive; a lapsed lease is armed again.
  void renew(std::string_view client = {});
  void set_lease(std::uint64_t lease_us);
  bool lease_lapsed() const noexcept { return lapsed_; }
  std::uint64_t lease_us() const noexcept { return lease_us_; }

  // --- the end ------------------------------------------------------------------------------------
  /// Ends every request (superseded), stops the drive first as 0x6007 says when `stop_first` and it
  /// is enabled, then closes the link (which puts back what it changed). Go on polling until closed().
  void close(bool stop_first);
  bool closed() const;
  const close_report& closing() const { return link_->closing(); }

  // --- what the session knows ---------------------------------------------------------------------
  drive_link& link() noexcept { return *link_; }
  const drive_link& link() const noexcept { return *link_; }
  const profile& drive_profile() const noexcept { return *profile_; }
  bool status_known() const noexcept { return link_->cyclic() && link_->status_known(); }
  std::uint16_t status_word() const noexcept { return link_->status_word(); }
  state observed() const noexcept { return observed_; }
  /// 0x603F as last carried or read.
  std::uint16_t error_code() const noexcept;
  /// An actual value: the cyclic input, else the last polled one.
  std::optional<std::int64_t> actual(std::uint16_t index) const;
  /// The value this session last put into the link's cyclic outputs for `index` (sub-index 0): a
  /// set-point as the drive is sent it (a stream's, a write carried cyclically); none before one.
  std::optional<std::int64_t> output(std::uint16_t index) const;
  /// Keeps `index` polled while the link does not carry it (for watching), or stops.
  void keep_polled(std::uint16_t index, bool on);
  bool prepared() const noexcept { return prepared_; }
  std::optional<std::uint32_t> supported_modes() const noexcept { return supported_modes_; }
  const std::string& device_name() const noexcept { return device_name_; }
  /// The drive's option code as read at start (the profile's default where the drive has none).
  std::int8_t option_code(option o) const noexcept { return options_.options[static_cast<int>(o)]; }
  std::uint64_t now_us() const noexcept { return now_us_; }
  /// The control word handed to the link last; none before the session first commanded the drive.
  std::optional<std::uint16_t> control_word() const noexcept { return sent_; }
  bool busy() const noexcept { return op_ != nullptr; }

  // --- events -------------------------------------------------------------------------------------
  /// The state the cyclic status word shows changed (the first one counts).
  std::function<void(state from, state to, std::uint16_t status_word)> on_state;
  std::function<void(std::uint16_t code, std::uint8_t reg, std::span<const std::uint8_t> bytes)> on_emergency;
  std::function<void(link_event event, const std::string& text)> on_link;
  std::function<void(progress_kind kind, const result& so_far)> on_progress;
  /// The lease lapsed: what the session does about it, in words.
  std::function<void(const std::string& action)> on_lease_lapsed;
  /// Once per cycle of the link, just before its outputs go (after a stream's next set-point): the
  /// cyclic inputs are the last cycle's. A client samples the drive's cycles here, each once.
  std::function<void()> on_cycle;

 private:
  struct operation;
  struct job;
  enum class step_state : std::uint8_t { running, done, failed };
  struct step {
    std::function<void()> start;
    std::function<step_state()> poll;
  };
  enum class control : std::uint8_t { none, target, command, words };
  /// A point in the session's time and in the link's count of status words.
  struct moment {
    std::uint64_t us = 0;
    std::uint64_t count = 0;
  };

  // session.cpp
  void on_link_event(link_event e, const std::string& text);
  void note_status();
  void run_operation();
  void finish(outcome end, std::string error);
  /// A failed motion command's drive is stopped: true if a stop began (it then completes `op`).
  bool stop_after_failure(std::unique_ptr<operation>& op);
  /// Halt, then quick stop, then Disable voltage, each stage within stop_timeout_us; `said` gets
  /// what was done.
  step failure_stop(std::shared_ptr<std::string> said);
  void drive_control_word();
  void check_lease();
  std::string stop_as_0x6007(const std::string& why);
  std::uint32_t next_deadline() const;
  /// set_cyclic_output, remembering the value (output()).
  bool put_output(std::uint16_t index, std::uint8_t sub, std::int64_t value);
  std::uint64_t begin(std::string name, std::vector<step> steps, completion done, bool motion);
  void fill_result(result& r) const;
  std::uint64_t refuse_now(std::string error, completion done, bool bad_input = false);
  // A job that ends operation `id` done: `done` gets the state as it stands when the job runs.
  std::function<void()> answer_with_state(std::uint64_t id, completion done);
  // session_jobs.cpp
  void queue_upload(std::uint16_t index, std::uint8_t sub, transfer_done done, bool front = false);
  void queue_download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes, transfer_done done);
  void run_jobs();
  void start_up_reads();
  bool poll_due();
  void write_object_sized(std::uint16_t index, std::uint8_t sub, std::int64_t value, unsigned size,
                          std::shared_ptr<result> r, completion done);
  // session_steps.cpp
  step need_cyclic();
  step need_prepared();
  step check(bool motion);
  step write_step(std::uint16_t index, std::uint8_t sub, std::int64_t value);
  step read_step(std::uint16_t index, std::uint8_t sub, std::function<void(std::int64_t)> use, bool optional);
  /// Switches to `mode` (nothing written when 0x6061 shows it); reports it when it switched or
  /// `report_always`.
  step mode_step(std::int8_t mode, bool report_always = false);
  step target_step(state target);
  step command_step(command c);
  step bits_step(std::uint16_t bits);
  step wait_step(std::function<bool()> done, std::uint64_t timeout_us, std::function<std::string()> why);
  step call_step(std::function<void()> f);
  step wait_settled();
  /// Waits for the words of control::words to have gone out and been answered (reset_timeout_us at most).
  step edge_sent();
  step wait_stopped(bool halted);
  /// Motion commands' limits (S20): each reads what it needs from the drive and refuses beyond it.
  step mode_supported(std::int8_t mode);
  std::vector<step> velocity_limits(std::int64_t rpm, const char* what);
  step torque_limit(std::int64_t permille);
  std::vector<step> position_limits(std::int64_t target, bool relative);
  step homing_method_supported(std::int8_t method);
  /// Reads `index:sub` (absent: no limit) and refuses the request with `judge`'s words, if any.
  step limit_step(std::uint16_t index, std::uint8_t sub,
                  std::function<std::optional<std::string>(std::int64_t)> judge);
  std::optional<std::string> cannot_command(bool motion) const;
  std::string fault_text() const;
  std::string state_text() const;
  bool settled() const;
  /// The drive has had the control word last sent: two status words after it on a cyclic link,
  /// settled() on one that sends on change only.
  bool word_taken() const;
  void set_target(state target);
  void set_command(command c);
  void set_mode_bits(std::uint16_t bits);
  void need(std::uint16_t index);
  /// An actual value known to come from after `m`: a cyclic input two status words later, a polled
  /// one read after it.
  std::optional<std::int64_t> fresh(std::uint16_t index, moment m) const;
  moment now_moment() const noexcept { return {now_us_, link_->status_count()}; }
  step_state fail_step(std::string error);
  void progress(progress_kind kind);
  /// An integer object of the core's table: into the cyclic outputs when the link carries it, else
  /// by a transfer; `done` gets "" or the reason it failed.
  void write_integer(std::uint16_t index, std::uint8_t sub, std::int64_t value, std::function<void(std::string)> done);
  // session_ops.cpp
  /// need_prepared, need_cyclic, check, `limits`, then the mode and OPERATION ENABLED.
  std::vector<step> motion_start(std::int8_t mode, std::vector<step> limits = {});
  std::uint64_t reach(const char* name, std::int8_t mode, std::uint16_t set_point, std::uint16_t actual_index,
                      std::int64_t target, progress_kind kind, std::optional<std::int64_t> result::*field,
                      std::vector<step> limits, completion done);
  step progress_step(progress_kind kind);
  step read_position_step();
  // session_stream.cpp
  void stream_tick();
  std::vector<step> stream_steps(std::int8_t mode, setpoint_source source, std::vector<step> limits, std::vector<step> before_mode,
                                 std::function<void(result&)> describe);

  drive_link* link_;
  session_config config_;
  const profile* profile_;
  std::uint64_t now_us_ = 0;
  std::uint64_t next_id_ = 1;

  // What start-up read.
  bool prepared_ = false;
  bool start_up_queued_ = false;
  axis options_;
  std::optional<std::uint32_t> supported_modes_;
  std::string device_name_;

  // The status word.
  state observed_ = state::start;
  bool state_announced_ = false;
  std::uint64_t status_seen_ = 0;  // link status_count() at the last poll

  // The control word.
  control control_ = control::none;
  master_policy policy_{};
  cia402::master master_;
  command command_ = command::disable_voltage;
  std::deque<std::pair<std::uint16_t, std::uint32_t>> words_;  // word, held at least (us) once sent
  std::uint16_t mode_bits_ = 0;
  bool halt_by_user_ = false;
  bool halt_by_stop_ = false;
  std::optional<std::uint16_t> sent_;
  std::uint64_t word_changed_us_ = 0;      // when the control word last changed
  std::uint64_t word_changed_count_ = 0;   // the link's status_count() then
  std::uint64_t mode_written_us_ = 0;      // when 0x6060 was last written

  // Jobs and polls.
  std::deque<std::unique_ptr<job>> jobs_;
  bool transfer_busy_ = false;
  struct polled {
    std::optional<std::int64_t> value;
    std::uint64_t read_us = 0;
    bool absent = false;  // the drive refused: not asked again
    int wanted = 0;       // operations and watchers that need it
    std::uint64_t next_us = 0;
  };
  std::map<std::uint16_t, polled> polled_;

  // The operation, and completions said at the next poll.
  std::unique_ptr<operation> op_;
  std::vector<std::function<void()>> deferred_;
  std::vector<std::function<void()>> after_settled_;  // said once the drive has had the last word

  // Streams.
  setpoint_source source_;
  std::uint16_t stream_object_ = 0;
  std::uint16_t stream_actual_ = 0;
  std::optional<std::int64_t> last_set_point_, set_point_before_;
  bool stream_ended_ = false;
  std::uint64_t set_points_ = 0;
  std::int64_t max_following_error_ = 0;

  // Jog.
  std::uint64_t jog_until_us_ = 0;

  std::map<std::uint16_t, std::int64_t> outputs_;  // what put_output() gave the link, by index

  // The lease.
  std::uint64_t lease_us_ = 0;
  std::uint64_t lease_renewed_us_ = 0;
  bool lapsed_ = false;
  std::string client_;

  bool closing_ = false;
  bool link_closed_ = false;
};

/// The exact integer ramp a csp stream follows: from `from` to `to` at `rpm`, one set-point a
/// cycle of `cycle_us`, with `increments` per `revolutions` (0x608F): set-point k is from +
/// direction x k cycles of travel, no drift however long.
class position_ramp {
 public:
  position_ramp(std::int64_t from, std::int64_t to, std::uint32_t rpm, std::uint32_t cycle_us,
                std::uint64_t increments = 10000, std::uint64_t revolutions = 1) noexcept;
  /// Set-point k (k = 1 the first); `to` from the last on.
  std::int64_t at(std::uint64_t k) const noexcept;

 private:
  std::int64_t from_, to_;
  std::uint64_t per_cycle_, divisor_;
};

}  // namespace cia402::axes
