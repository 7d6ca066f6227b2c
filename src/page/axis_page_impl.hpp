// The page's drive inside: shared by axis_page.cpp (the session's cycle, what the drive shows, the
// snapshots) and axis_page_actions.cpp (the page's requests, each handed to the session).
#pragma once

#include "cia402/page/axis_page.hpp"

#include <nlohmann/json.hpp>

#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>

#include "action_log.hpp"
#include "cia402/axis/session.hpp"
#include "local_plant.hpp"
#include "mode_view.hpp"
#include "recorder.hpp"
#include "sample_ring.hpp"
#include "snapshot_board.hpp"
#include "word_change.hpp"

namespace cia402::page {

struct axis_page::impl {
  using json = nlohmann::ordered_json;

  impl(const profile& p, connection_factory f, axis_page_config c);
  ~impl();

  // --- the drive --------------------------------------------------------------------------------
  const profile* table;  // the profile in use; select_profile() changes it with the drive
  connection_factory connect;
  axis_page_config config;
  drive_connection drive;
  /// The drive's simulator beside the session: a drive in this process only (local_plant.hpp).
  std::optional<detail::local_plant> plant;
  std::unique_ptr<axes::session> session;

  mutable std::mutex mutex;          // guards all here but the board, which has a lock of its own
  std::condition_variable answered;  // a request's answer came (or the page closed)

  std::uint64_t now_us = 0;
  std::uint64_t cycles = 0;
  std::uint64_t next_publish_us = 0;

  // What the drive showed.
  std::optional<state> observed;  // none: the status word is not known
  struct transition_seen {
    std::optional<int> number;
    state from = state::start;
    state to = state::start;
    bool inferred = false;
  };
  std::optional<transition_seen> last_transition;
  bool reset_sent_since_change = false;  // for the inference (a fault-reset edge went out)
  std::map<std::uint16_t, std::int64_t> objects;  // a bus drive's objects as read at start or written
  std::uint16_t injected_fault = 0;               // what the page wrote to 0x2001 (a bus node)
  /// The lease runs from the first renewal on: before any client came, no sign of life was lost.
  bool lease_armed = false;
  std::optional<std::uint16_t> last_emergency;    // the newest emergency's error code
  // Each error code 0x603F took, newest first, with the page's time it was first seen: the history
  // the page shows (the drive's own is 0x1003, without times).
  struct error_seen {
    std::uint64_t time_us = 0;
    std::uint16_t code = 0;
    std::optional<std::uint64_t> wall_us;  // the time of day, where the page has a clock for it
  };
  std::deque<error_seen> errors_seen;
  std::uint16_t error_shown = 0;
  static constexpr std::size_t errors_kept = 16;
  void note_error_code(std::uint16_t code);

  // What the page asked for.
  std::optional<std::uint16_t> requested_word;  // a word given to the session, not yet sent
  detail::action_log log;
  detail::snapshot_board board;
  detail::recorder recording;
  // The scope's per-cycle samples (axis_page_samples.cpp): each cycle of the link, once.
  detail::sample_ring samples;
  detail::cycle_sample open_sample;                // a drive in this process: the cycle under way
  std::optional<int> transition_for_sample;        // a bus: noted since the last sample
  std::optional<int> transition_for_row;           // a bus: noted in this cycle, for its row

  // Profile position's handshake (backend::new_setpoint), the session's offer_set_point: its id
  // while it runs; reset when another request supersedes it (its end is then no news).
  std::optional<std::uint64_t> offering;
  // One-click Enable and Stop, and the jog: at most one of each, the session runs them.
  struct operation {
    std::uint64_t id = 0;
    std::string action;
    std::vector<int> transitions;
  };
  std::optional<operation> enabling, stopping;
  struct jog_run {
    std::uint64_t id = 0;
    std::uint64_t session_id = 0;
    std::string action;
    std::int64_t velocity_rpm = 0;
    std::uint64_t time_to_live_us = 0;
    std::uint64_t started_us = 0;
    /// The page's own reckoning of the dead-man (the session's counts from when the drive turns, so
    /// it is never earlier): a keep-alive after it starts the jog anew rather than renew an ending one.
    std::uint64_t expires_us = 0;
    std::string why_ended;  // released, Stop, another velocity; empty while it runs
    bool turning = false;   // the session switched to profile velocity and set 0x60FF
  };
  std::optional<jog_run> jogging;
  // A homing run the page started (POST /api/homing with start): the session's home.
  std::optional<operation> homing_run;

  // What a drive on a bus does not show cyclically and the homing panel needs: 0x6099 sub 1 and 2,
  // read once the link runs and kept as written (a drive in this process is read directly).
  std::optional<std::int64_t> switch_speed_read, zero_speed_read;
  bool homing_read_asked = false;
  // The drive's own pre-defined error field 0x1003 (CiA 301 §7.5.2.5), read through the session's
  // object jobs (an SDO on a bus) when the error code changes and on request.
  struct error_field_read {
    bool stale = true;     // to be read again
    bool reading = false;  // a read runs
    std::optional<std::uint64_t> read_at_us;
    std::vector<std::uint32_t> entries;  // newest first, as sub 1..n
    std::string error;                   // why the last read failed (0x1003 absent, no answer, ...)
    std::vector<std::function<void()>> waiting;  // told when the running read ends
  };
  error_field_read error_field;

  // --- axis_page.cpp ------------------------------------------------------------------------------
  void start_session(const profile& p);  // the session over the connection `drive`
  void advance(std::uint32_t elapsed_us);
  void on_state(state from, state to, std::uint16_t status_word);
  void note_transition(std::optional<int> number, state from, state to, bool inferred,
                       std::uint16_t status_word,
                       std::optional<std::uint64_t> at_us = std::nullopt);
  void on_cycle();
  void close_row();
  void record_bus_row();
  // --- axis_page_samples.cpp ----------------------------------------------------------------------
  void open_plant_sample(const sim::trace_row& row);
  void push_plant_sample(const drive_outputs& out);
  void push_bus_sample();
  std::vector<std::string> polled_signals() const;
  json set_point_json() const;
  void check_enable_walk();
  bool busy_now() const;
  std::optional<std::int64_t> value_of(std::uint16_t index) const;
  std::uint16_t word_shown() const;
  std::uint16_t word_base() const { return requested_word.value_or(word_shown()); }
  bool running() const {
    return session->link().phase() == axes::link_phase::running && session->prepared() && session->link().cyclic();
  }
  std::string link_text() const;
  std::string conditions() const;
  detail::action_log::standing how_it_stands() const;
  json capabilities() const;
  json remote_json() const;
  json snapshot(bool with_time) const;
  json bus_snapshot(json j) const;

  // --- axis_page_actions.cpp ----------------------------------------------------------------------
  std::optional<refused> not_running() const;
  std::uint64_t change_word(const detail::word_change& w);
  void send_word(std::uint16_t word, bool reset_edge);
  std::string enable_blocker(state s) const;
  void end_operation(std::optional<operation>& op, const axes::result& r, const std::string& done_text);
  void end_jog(const axes::result& r);
  /// Runs `start` (a session request whose completion calls the given callback) and waits for its
  /// result: the session is polled here without time passing first (a drive in this process answers
  /// at once), then the cycle thread brings it. Nothing when the page closed or the time ran out.
  std::optional<axes::result> await(std::unique_lock<std::mutex>& lock,
                                    const std::function<void(axes::completion)>& start);
  /// The reply to an object write; `tracked`: the action was tracked from before it was sent (a
  /// plant input whose transitions the page reports), and is refused if the write failed.
  reply write_reply(const std::optional<axes::result>& r, const std::string& action,
                    std::optional<std::uint64_t> tracked = std::nullopt);
  reply change_bus_plant(std::unique_lock<std::mutex>& lock, const plant_change& change);

  // --- axis_page_homing.cpp -----------------------------------------------------------------------
  /// Starts the reads the views need (0x6099 on a bus, 0x1003 once stale); called each cycle.
  void keep_views_read();
  void read_error_field(std::size_t sub, std::vector<std::uint32_t> so_far);
  void end_error_field_read(std::string error);
  /// An object's value as the panels show it: the simulator's own, else what the session last had.
  std::optional<std::int64_t> shown_value(std::uint16_t index, std::uint8_t sub) const;
  detail::mode_reading mode_reading_now() const;
  json homing_json() const;
  json drive_errors_json() const;
  void end_homing(const axes::result& r);
  // --- axis_page_parameters.cpp -------------------------------------------------------------------
  struct entry_values {
    std::vector<parameter_entry> entries;
    std::vector<std::optional<axes::result>> results;  // none: not read (write-only, or no answer)
  };
  std::vector<std::optional<axes::result>> read_entries(std::unique_lock<std::mutex>& lock,
                                                        const std::vector<parameter_entry>& entries);
  entry_values entries_read(std::unique_lock<std::mutex>& lock);
  std::string not_loaded(const parameter_entry& e) const;
};

}  // namespace cia402::page
