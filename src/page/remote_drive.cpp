#include "cia402/page/remote_drive.hpp"

#include <array>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "cia402/canopen/402/drive_master.hpp"
#include "cia402/error_codes.hpp"
#include "cia402/manufacturer_objects.hpp"
#include "cia402/canopen/301/nmt.hpp"
#include "cia402/objects.hpp"
#include "cia402/page/transition_inference.hpp"
#include "cia402/words.hpp"
#include "action_log.hpp"
#include "page_json.hpp"
#include "page_names.hpp"
#include "remote_link.hpp"
#include "recorder.hpp"
#include "sign_of_life.hpp"
#include "snapshot_board.hpp"
#include "word_change.hpp"

namespace cia402::page {
namespace {

namespace co = cia402::canopen;
using json = nlohmann::ordered_json;
using detail::abort_text;
using detail::hex;

constexpr std::uint16_t bit7 = control_bit::fault_reset;
constexpr const char* not_remote = "not available on a remote drive";

// The objects the page writes on a remote drive: the writable ones of the one object table, but
// the control word, which commands and bit toggles set. The CANopen download needs their sizes, and
// a value outside the type is refused here rather than cut to fit.
const object_description* type_of(std::uint16_t index) {
  const object_description* o = find_drive_object(index);
  if (o == nullptr || o->access != object_access::read_write || index == 0x6040) return nullptr;
  return o;
}

// Nothing if the value fits the object's type, else the abort code the drive would give.
std::optional<sdo_abort> out_of_type(const object_description& t, std::int64_t v) {
  if (v < type_low(t.type)) return sdo_abort::value_too_low;
  if (v > type_high(t.type)) return sdo_abort::value_too_high;
  return std::nullopt;
}

// An HTTP request waiting for its SDO transfer.
struct user_wait {
  bool done = false;
  bool cancelled = false;  // the link was lost before the transfer ran
  sdo_abort abort = sdo_abort::none;
  // A plant change is tracked from the moment the drive accepted it (in the cycle thread), so the
  // transitions it causes are its own even when they arrive in the same batch of frames.
  std::optional<std::string> track_action;
  std::uint64_t id = 0;
};

struct transition_seen {
  std::optional<int> number;  // none: no chain of rows connects the two states
  state from = state::start;
  state to = state::start;
};

// The CANopen 402 master's settings for the page: PDOs on change (every state the drive reports
// arrives), the velocity mapped, the heartbeat watched where the drive takes it, the page's objects
// read at set-up.
co::drive_master_config master_config(const profile& p, const remote_config& c) {
  co::drive_master_config m;
  m.node_id = c.node_id;
  m.cycle_us = c.cycle_us;
  m.drive_heartbeat_ms = c.heartbeat_ms;
  m.master_heartbeat_ms = c.guard_ms;
  m.heartbeat_clock_us = c.heartbeat_clock_us;
  m.heartbeat_required = false;
  m.sdo_timeout_us = c.sdo_timeout_us;
  m.drive_profile = &p;
  m.timing = co::pdo_timing::on_change;
  m.map_velocity = true;
  m.velocity_inhibit_100us = c.velocity_inhibit_100us;
  // The set-points of the position and torque modes are not read at start (each read is a round
  // trip before the page runs): they show once written. The mode is, for the mode select.
  for (const object_name& o : object_names(p)) {
    const std::uint16_t i = o.index;
    const bool setpoint = i == object_index::target_position || i == object_index::target_torque ||
                          i == object_index::profile_velocity || i == object_index::homing_method ||
                          i == object_index::home_offset;
    if (!setpoint) m.read_at_start.push_back(i);
  }
  m.read_at_start.push_back(0x60FF);
  m.read_at_start.push_back(object_index::supported_drive_modes);  // the mode select's choices
  m.poll_us = c.poll_us;
  m.retry_us = c.retry_us;
  m.reset_pulse_us = c.reset_pulse_us;
  return m;
}

// The link over CAN: the project's one CANopen 402 master, set up as master_config says.
class canopen_link final : public detail::remote_link {
 public:
  canopen_link(const profile& p, co::channel& bus, const remote_config& c)
      : bus_(bus), config_(c), m_(bus, master_config(p, c)) {
    m_.on_status = [this](std::uint16_t sw) {
      if (on_status) on_status(sw);
    };
    m_.on_velocity = [this](std::int32_t v) {
      if (on_velocity) on_velocity(v);
    };
    m_.on_sent = [this](std::uint16_t w) {
      if (on_sent) on_sent(w);
    };
    m_.on_phase = [this](co::master_phase, co::phase_reason why) {
      if (!on_phase) return;
      switch (why) {
        case co::phase_reason::node_restarted: on_phase(detail::link_event::restarted); break;
        case co::phase_reason::failed: on_phase(detail::link_event::failed); break;
        case co::phase_reason::running: on_phase(detail::link_event::running); break;
        default: break;
      }
    };
  }

  void poll(std::uint32_t elapsed_us) override { (void)m_.poll(bus_, elapsed_us); }
  bool running() const override { return m_.phase() == co::master_phase::running; }
  bool failed() const override { return m_.phase() == co::master_phase::failed; }
  remote_status status() const override {
    switch (m_.phase()) {
      case co::master_phase::configuring: return remote_status::configuring;
      case co::master_phase::running: return remote_status::running;
      case co::master_phase::failed: break;
    }
    switch (m_.failure()) {
      case co::master_failure::bus_failed: return remote_status::bus_failed;
      case co::master_failure::sdo_refused:
      case co::master_failure::not_a_drive: return remote_status::refused;
      default: return remote_status::no_answer;
    }
  }
  std::string phase_text() const override { return m_.phase_text(); }
  std::string drive_text() const override { return "node " + std::to_string(config_.node_id); }
  bool request_pending() const override { return m_.request_pending(); }
  bool read(std::uint16_t index, bool is_signed, std::function<void(const detail::link_transfer&)> done) override {
    return m_.read(index, 0, is_signed, [done](const co::sdo_result& r) { done(transfer(r)); });
  }
  bool write(std::uint16_t index, std::int64_t value, unsigned bytes,
             std::function<void(const detail::link_transfer&)> done) override {
    return m_.write(index, 0, value, bytes, [done](const co::sdo_result& r) { done(transfer(r)); });
  }
  const std::map<std::uint16_t, std::int64_t>& start_values() const override { return m_.start_values(); }
  std::uint16_t last_sent() const override { return m_.last_sent(); }
  void send_control_word(std::uint16_t word, bool fault_reset_edge) override {
    m_.send_control_word(word, fault_reset_edge);
  }
  bool words_queued() const override { return m_.words_queued(); }
  bool status_known() const override { return m_.status_known(); }
  std::uint16_t status_word() const override { return m_.status_word(); }
  std::uint16_t error_code() const override { return m_.error_code(); }
  std::uint8_t error_register() const override { return m_.error_register(); }
  bool fault_injection() const override { return m_.fault_injection(); }
  json describe() const override {
    json r;
    r["node"] = config_.node_id;
    r["bus"] = config_.bus_name;
    r["status"] = remote_status_name(status());
    r["text"] = m_.phase_text();
    const auto nmt_seen = m_.nmt_seen();
    r["nmt"] = nmt_seen ? json(co::nmt_state_name(static_cast<co::nmt_state>(*nmt_seen))) : json(nullptr);
    r["device_name"] = m_.device_name();
    r["heartbeat_watched"] = m_.heartbeat_watched();
    r["error_code_in_pdo"] = m_.error_code_mapped();
    r["velocity_in_pdo"] = m_.velocity_mapped();
    const auto last_emcy = m_.last_emcy();
    r["last_emcy"] = last_emcy ? json(hex(*last_emcy, 4)) : json(nullptr);
    return r;
  }
  json where() const override { return {{"node", config_.node_id}, {"bus", config_.bus_name}}; }

 private:
  static detail::link_transfer transfer(const co::sdo_result& r) { return {r.ok(), r.cancelled, r.abort, r.value}; }
  co::channel& bus_;
  remote_config config_;
  co::drive_master m_;
};
}  // namespace

const char* remote_status_name(remote_status s) noexcept {
  switch (s) {
    case remote_status::configuring: return "configuring";
    case remote_status::running: return "running";
    case remote_status::no_answer: return "no_answer";
    case remote_status::refused: return "refused";
    case remote_status::bus_failed: return "bus_failed";
  }
  return "unknown";
}

struct remote_drive::impl {
  impl(const profile& p, std::unique_ptr<detail::remote_link> l, const remote_config& c)
      : table(p),
        config(c),
        link(std::move(l)),
        remote(*link),
        log({c.results_kept, c.settle_quiet_us, c.settle_limit_us,
             "still busy when the page stopped waiting", " (numbers inferred)"},
            [this] { return how_it_stands(); }),
        sign(c.lease_us) {
    if (config.cycle_us == 0) config.cycle_us = 1000;
    if (config.publish_us == 0) config.publish_us = config.cycle_us;
    remote.on_status = [this](std::uint16_t sw) { on_status(sw); };
    remote.on_velocity = [this](std::int32_t v) { on_velocity(v); };
    remote.on_sent = [this](std::uint16_t w) {
      if ((w & bit7) != 0 && (sent_before & bit7) == 0) reset_sent_since_change = true;
      sent_before = w;
    };
    remote.on_phase = [this](detail::link_event why) { on_phase(why); };
  }

  const profile& table;
  remote_config config;

  mutable std::mutex mutex;  // guards all here but the board, which has a lock of its own
  std::condition_variable job_done;

  // The master that reaches the drive (CANopen or EtherCAT): set-up, the status word as it comes,
  // the control word, SDO requests, retry.
  std::unique_ptr<detail::remote_link> link;
  detail::remote_link& remote;
  std::uint64_t now_us = 0;
  std::uint64_t next_publish_us = 0;

  // What the drive reports, as the page shows it.
  bool state_known = false;
  state observed = state::start;
  std::optional<std::int32_t> velocity;
  std::int32_t target_velocity = 0;
  std::uint16_t injected_fault = 0;  // what the page wrote to 0x2001 (0: none)
  std::map<std::uint16_t, std::int64_t> objects;
  std::optional<transition_seen> last_transition;

  // What the page sends.
  std::uint16_t control_word = 0;
  std::uint16_t sent_before = 0;
  bool reset_sent_since_change = false;

  detail::action_log log;
  detail::snapshot_board board;
  detail::recorder recording;
  detail::sign_of_life sign;
  std::uint8_t transition_this_poll = no_transition;  // for the recorder's row

  // The mode display and actual values no PDO of the page carries, read by SDO in rounds.
  struct actual_value {
    std::uint16_t index;
    std::optional<std::int64_t> value;
    bool absent = false;  // the drive refused the read: not asked again until set-up runs again
  };
  std::array<actual_value, 4> actuals{{{object_index::modes_of_operation_display, {}, false},
                                       {object_index::position_actual_value, {}, false},
                                       {object_index::torque_actual_value, {}, false},
                                       {object_index::following_error_actual_value, {}, false}}};
  std::size_t next_actual = 0;
  bool actual_in_flight = false;
  std::uint64_t next_round_us = 0;
  int user_transfers = 0;  // the page's own SDO requests queued or running

  // The set-point handshake: bit 4 goes up at raise_at_us (after a cycle low if it was up), and
  // down with the first status word showing bit 12 after that, or at give_up_us.
  struct handshake_run {
    bool raised = false;
    std::uint64_t raise_at_us = 0;
    std::uint64_t give_up_us = 0;
    bool acknowledged = false;
  };
  std::optional<handshake_run> handshake;

  std::optional<std::int64_t> actual(std::uint16_t index) const {
    if (const auto v = remote.cyclic(index)) return v;
    for (const actual_value& a : actuals) {
      if (a.index == index) return a.value;
    }
    return std::nullopt;
  }

  void forget_actuals() {
    for (actual_value& a : actuals) {
      a.value.reset();
      a.absent = false;
    }
    next_actual = 0;
    next_round_us = now_us;
  }

  // One read at a time, and none while the page's own requests wait: they go first.
  void read_actuals() {
    if (config.actual_poll_us == 0 || actual_in_flight || user_transfers > 0 ||
        !remote.running() || remote.request_pending() ||
        now_us < next_round_us) {
      return;
    }
    // What the link carries cyclically is not read by SDO.
    while (next_actual < actuals.size() &&
           (actuals[next_actual].absent || remote.cyclic(actuals[next_actual].index))) {
      ++next_actual;
    }
    if (next_actual >= actuals.size()) {
      next_actual = 0;
      next_round_us = now_us + config.actual_poll_us;
      return;
    }
    const std::size_t k = next_actual++;
    actual_in_flight = remote.read(actuals[k].index, true, [this, k](const detail::link_transfer& r) {
      actual_in_flight = false;
      if (r.ok) {
        actuals[k].value = r.value;
      } else if (!r.cancelled && r.abort != sdo_abort::sdo_protocol_timed_out) {
        actuals[k].absent = true;  // the drive has no such object (or will not say)
        actuals[k].value.reset();
      }
    });
  }

  std::string node_text() const { return remote.drive_text(); }

  remote_status status() const { return remote.status(); }

  void on_phase(detail::link_event why) {
    switch (why) {
      case detail::link_event::restarted:
        injected_fault = 0;
        state_known = false;
        forget_actuals();
        handshake.reset();
        break;
      case detail::link_event::failed:
        // The node went silent (or its set-up failed): nothing is known until set-up ran again.
        state_known = false;
        log.finish_pending(remote.phase_text().c_str());
        handshake.reset();
        break;
      case detail::link_event::running: {
        // Start from the drive's present values, so connecting changes nothing.
        objects.clear();
        for (const object_name& o : object_names(table)) {
          const auto v = remote.start_values().find(o.index);
          if (v != remote.start_values().end()) objects[o.index] = v->second;
        }
        const auto target = remote.start_values().find(0x60FF);
        if (target != remote.start_values().end()) {
          target_velocity = static_cast<std::int32_t>(target->second);
        }
        control_word = remote.last_sent();
        sent_before = control_word;
        forget_actuals();
        actual_in_flight = false;
        break;
      }
    }
  }

  // --- what the drive reports -------------------------------------------------------------------

  void on_status(std::uint16_t sw) {
    state s = state::start;
    if (!decode_status(table, sw, s)) {
      state_known = false;
      return;
    }
    if (state_known && s != observed) {
      const std::vector<inferred_transition> chain = infer_transitions(
          table, observed, s, observer_facts(table, remote.last_sent(), reset_sent_since_change));
      transition_seen seen;
      seen.from = observed;
      seen.to = s;
      if (!chain.empty()) {
        seen.number = chain.back().number;
        seen.from = chain.back().from;
      }
      last_transition = seen;
      // Every row of the chain goes into the history (one status word may show two, T13 and T14);
      // a change no chain explains goes in without a number.
      if (chain.empty()) {
        recording.note_transition({0, now_us, std::nullopt, observed, s, remote.last_sent(), sw, true});
      }
      for (const inferred_transition& t : chain) {
        recording.note_transition({0, now_us, int{t.number}, t.from, t.to, remote.last_sent(), sw, true});
      }
      if (seen.number) transition_this_poll = static_cast<std::uint8_t>(*seen.number);
      if (auto* a = log.pending()) {
        for (const inferred_transition& t : chain) a->transitions.push_back(t.number);
        a->busy_until = now_us;
      }
      reset_sent_since_change = false;
    }
    observed = s;
    state_known = true;
    if (handshake && handshake->raised && (sw & (1u << 12)) != 0) handshake->acknowledged = true;
  }

  void on_velocity(std::int32_t v) {
    if (velocity && *velocity != v && log.pending()) log.pending()->busy_until = now_us;
    velocity = v;
  }

  void process(std::uint32_t elapsed_us) {
    now_us += elapsed_us;
    transition_this_poll = no_transition;
    remote.poll(elapsed_us);
    // On the wall clock where serve gives one: the drive on the bus stops on wall time too.
    if (sign.lapsed(config.heartbeat_clock_us ? config.heartbeat_clock_us() : now_us)) stop_for_silence();
    if (handshake) run_handshake();
    read_actuals();
    if (state_known) record_row();
    if (log.pending()) settle();
    if (now_us >= next_publish_us) {
      next_publish_us = now_us + config.publish_us;
      board.publish([this](bool with_time) { return snapshot(with_time); });
    }
  }

  // The lease lapsed: a drive left enabled stops as its 0x6007 (as read at set-up) says.
  void stop_for_silence() {
    if (!state_known || observed != state::operation_enabled || not_running()) return;
    const auto known = objects.find(option_index(option::abort_connection));
    const int code = known != objects.end() ? static_cast<int>(known->second)
                                            : table.spec(option::abort_connection).default_value;
    if (const auto w = detail::stop_for_silent_page(table, control_word, code, sign.lease_us())) change_word(*w);
  }

  void run_handshake() {
    constexpr std::uint16_t bit4 = 1u << 4;
    handshake_run& h = *handshake;
    if (!h.raised) {
      if (now_us < h.raise_at_us || remote.words_queued()) return;
      control_word = static_cast<std::uint16_t>(control_word | bit4);
      remote.send_control_word(control_word);
      h.raised = true;
      h.give_up_us = now_us + detail::new_setpoint_wait_us;
      return;
    }
    if (!h.acknowledged && now_us < h.give_up_us) return;
    if (!h.acknowledged) {
      log.report_now("NEW_SET-POINT", "refused",
                     "refused: no set-point acknowledge (status bit 12) within " +
                         std::to_string(detail::new_setpoint_wait_us / 1000) + " ms; bit 4 cleared" +
                         conditions());
    }
    control_word = static_cast<std::uint16_t>(control_word & ~bit4);
    remote.send_control_word(control_word);
    handshake.reset();
  }

  // The recorder's row for this poll. The bus shows the words, the state, the velocity and the
  // error code; the plant columns are what the status word and the state tell: DC link = status
  // bit 4 (S11), torque and brake from the state's activity in the profile, STO and the fault
  // cause unknown (recorded as off).
  void record_row() {
    sim::trace_row row;
    row.time_us = now_us;
    row.velocity = velocity ? std::int64_t{*velocity} * 1000000 : 0;
    row.target_velocity = target_velocity;
    row.control_word = remote.last_sent();
    row.status_word = remote.status_word();
    row.error_code = remote.error_code();
    row.current = observed;
    row.transition = transition_this_poll;
    row.torque = table.info(observed).activity != state_activity::idle;
    row.brake_released = row.torque;
    row.brake_engaged = !row.torque;
    row.dc_link = (row.status_word & status_bit::voltage_enabled) != 0;
    // The SDO-read actual values as last read (0 while unknown; mode 0: none known).
    row.position = actual(object_index::position_actual_value).value_or(0);
    row.position_demand = row.position;
    row.torque_permille = static_cast<std::int32_t>(actual(object_index::torque_actual_value).value_or(0));
    row.mode = static_cast<std::int8_t>(actual(object_index::modes_of_operation_display).value_or(0));
    recording.record(row);
  }

  // --- actions and results --------------------------------------------------------------------

  std::string shown_state() const {
    return state_known ? state_name(observed) : "UNKNOWN";
  }

  std::string conditions() const {
    std::string s;
    auto add = [&s](const std::string& what) { s += (s.empty() ? " (" : ", ") + what; };
    const std::uint16_t error_code = remote.error_code();
    const std::uint16_t status_word = remote.status_word();
    if (error_code != 0) add("the drive reports error code " + hex(error_code, 4));
    if (remote.status_known() && (status_word & status_bit::voltage_enabled) == 0) {
      add("no DC-link voltage: status bit 4 is 0");
    }
    if (remote.status_known() && (status_word & status_bit::remote) == 0) {
      add("status bit 9 (remote) is 0: the drive does not process the control word");
    }
    if (!s.empty()) s += ")";
    return s;
  }

  detail::action_log::standing how_it_stands() const {
    // What the bus shows of it: status bit 4 (S11), and a stop state with the shaft still turning.
    std::string waiting_for;
    if (remote.status_known() && (remote.status_word() & status_bit::voltage_enabled) == 0) {
      waiting_for = "no DC-link voltage";
    } else if (state_known && velocity && *velocity != 0 &&
               (table.info(observed).activity == state_activity::quick_stop ||
                table.info(observed).activity == state_activity::fault_reaction)) {
      waiting_for = "a stop is ramping";
    }
    return {observed, shown_state(), conditions(), waiting_for};
  }

  std::uint64_t track(std::string action, bool refuse_without_transition,
                      detail::action_log::expectation expect = detail::action_log::expectation::act) {
    return log.track(std::move(action), refuse_without_transition,
                     state_known ? std::optional<state>(observed) : std::nullopt, now_us, expect);
  }

  // Settled: nothing left to send, no transition and no change of velocity for settle_quiet. A
  // stop the state runs (QUICK STOP ACTIVE, FAULT REACTION ACTIVE) counts as busy while the shaft
  // turns, so the transition that ends it is reported with the action.
  void settle() {
    const bool stopping =
        state_known && velocity && *velocity != 0 &&
        (table.info(observed).activity == state_activity::quick_stop ||
         table.info(observed).activity == state_activity::fault_reaction);
    // The actual values' reads are not the action's business: only the page's own requests count.
    log.settle(now_us, remote.words_queued() || stopping || user_transfers > 0);
  }

  // Logs a command or bit toggle and queues its word for RPDO1.
  std::uint64_t change_word(const detail::word_change& w) {
    handshake.reset();  // a word given by hand ends the handshake: bit 4 as the word has it
    const std::uint64_t id =
        w.tracked
            ? track(w.action, true,
                    w.expect_in(table, control_word,
                                state_known ? std::optional<state>(observed) : std::nullopt))
            : log.report_now(w.action, "done", w.text);
    remote.send_control_word(w.word, w.fault_reset_edge);
    control_word = w.word;
    return id;
  }

  std::optional<refused> not_running() const {
    if (remote.running()) return std::nullopt;
    std::string why = remote.phase_text().empty() ? node_text() + " is not ready" : remote.phase_text();
    return refused{503, why};
  }

  // Queues an SDO download for the cycle thread and waits for its end. `lock` holds the mutex.
  std::shared_ptr<user_wait> download(std::unique_lock<std::mutex>& lock, std::uint16_t index,
                                      std::int64_t value, unsigned bytes,
                                      std::function<void()> on_done,
                                      std::optional<std::string> track_action = std::nullopt) {
    auto w = std::make_shared<user_wait>();
    w->track_action = std::move(track_action);
    const bool queued = remote.write(index, value, bytes, [this, w, on_done](const detail::link_transfer& r) {
      --user_transfers;
      w->done = true;
      w->cancelled = r.cancelled;
      w->abort = r.abort;
      if (r.ok) {
        if (on_done) on_done();
        if (w->track_action) w->id = track(*w->track_action, false);
      }
      job_done.notify_all();
    });
    if (queued) {
      ++user_transfers;
    } else {
      w->done = w->cancelled = true;
    }
    job_done.wait_for(lock, config.request_timeout, [&] { return w->done || board.closed(); });
    return w;
  }

  // The reply for a finished (or abandoned) download; refusals are reported to the page too.
  reply download_reply(const std::shared_ptr<user_wait>& w, const std::string& action) {
    if (!w->done) {
      log.report_now(action, "refused", "refused: no answer in time");
      return refused{504, action + ": no answer from " + node_text() + " in time"};
    }
    if (w->cancelled) {
      const std::string why =
          remote.phase_text().empty() ? node_text() + " does not answer" : remote.phase_text();
      log.report_now(action, "refused", "refused: " + why);
      return refused{503, action + ": " + why};
    }
    if (w->abort != sdo_abort::none) {
      std::string text = "refused: " + abort_text(w->abort);
      if (w->abort == sdo_abort::sdo_protocol_timed_out) {
        text = "refused: " + node_text() + " does not answer (" + abort_text(w->abort) + ")";
      }
      log.report_now(action, "refused", text);
      return refused{w->abort == sdo_abort::sdo_protocol_timed_out ? 504 : 422,
                     action + ": " + text.substr(std::string("refused: ").size()), w->abort};
    }
    if (w->track_action) return accepted{w->id};
    return accepted{log.report_now(action, "done", "done")};
  }

  // --- snapshots ------------------------------------------------------------------------------

  json capabilities() const {
    json reasons = json::object();
    const bool fault_injection = remote.fault_injection();
    if (!fault_injection) {
      reasons["fault"] = std::string(not_remote) +
                         " (only a cia402 bus node offers fault injection, object 0x2001)";
    }
    reasons["dc_link"] = not_remote;
    reasons["sto"] = not_remote;
    return {{"fault", fault_injection}, {"dc_link", false}, {"sto", false}, {"reasons", reasons}};
  }

  json snapshot(bool with_time) const {
    json j;
    const bool live = !remote.failed();
    const bool status_known = remote.status_known();
    const std::uint16_t status_word = remote.status_word();
    j["state"] = live ? shown_state() : "UNKNOWN";
    j["status_word"] = hex(status_word, 4);
    j["control_word"] = hex(control_word, 4);
    j["decodes_to"] = command_name(table.decode(control_word));
    if (last_transition) {
      j["last_transition"] = {{"number", last_transition->number ? json(*last_transition->number)
                                                                 : json(nullptr)},
                              {"from", state_name(last_transition->from)},
                              {"to", state_name(last_transition->to)},
                              {"inferred", true}};
    } else {
      j["last_transition"] = nullptr;
    }
    // Not visible from the bus: the page shows them as unknown.
    j["stop_running"] = nullptr;
    j["ramp"] = nullptr;
    j["error_code"] = hex(remote.error_code(), 4);
    j["error_text"] = error_code_text(remote.error_code());
    j["error_register"] = hex(remote.error_register(), 2);
    // A silent node's last values are history: what is shown live says "unknown" instead.
    j["velocity"] = live && velocity ? json(*velocity) : json(nullptr);
    j["target_velocity"] = target_velocity;
    j["effective_target"] = target_velocity;
    j["torque"] = nullptr;
    j["brake_engaged"] = nullptr;
    // S11: status bit 4 is the DC-link voltage.
    j["dc_link"] = live && status_known ? json((status_word & status_bit::voltage_enabled) != 0)
                                        : json(nullptr);
    j["sto"] = nullptr;
    j["fault_cause"] = remote.fault_injection() ? json(hex(injected_fault, 4)) : json(nullptr);
    // The mode display and the actual values as last read by SDO (null: not read yet, the drive
    // lacks the object, or the node is silent); the mode requested as read at start or written.
    const auto shown = [live](std::optional<std::int64_t> v) { return live && v ? json(*v) : json(nullptr); };
    j["mode"] = shown(actual(object_index::modes_of_operation_display));
    const auto requested = objects.find(object_index::modes_of_operation);
    j["requested_mode"] = requested != objects.end() ? json(requested->second) : json(nullptr);
    j["position"] = shown(actual(object_index::position_actual_value));
    j["position_demand"] = nullptr;
    j["following_error"] = shown(actual(object_index::following_error_actual_value));
    j["torque_actual"] = shown(actual(object_index::torque_actual_value));
    json objs = json::object();
    for (const auto& [index, value] : objects) objs[hex(index, 4)] = value;
    j["objects"] = std::move(objs);
    j["results"] = log.results_json();
    j["remote"] = remote.describe();
    j["capabilities"] = capabilities();
    if (with_time) {
      j["cycle"] = now_us / config.cycle_us;
      j["time_ms"] = now_us / 1000;
    }
    return j;
  }
};

remote_drive::remote_drive(const profile& p, canopen::channel& bus, const remote_config& config)
    : impl_(std::make_unique<impl>(p, std::make_unique<canopen_link>(p, bus, config), config)) {}

remote_drive::remote_drive(const profile& p, std::unique_ptr<detail::remote_link> link, const remote_config& config)
    : impl_(std::make_unique<impl>(p, std::move(link), config)) {}

remote_drive::~remote_drive() { close(); }

void remote_drive::step() { process(impl_->config.cycle_us); }

void remote_drive::process(std::uint32_t elapsed_us) {
  std::lock_guard lock(impl_->mutex);
  impl_->process(elapsed_us);
}

reply remote_drive::command(page_command c) {
  std::lock_guard lock(impl_->mutex);
  if (auto no = impl_->not_running()) return *no;
  const auto change = detail::press_button(impl_->table, c, impl_->control_word);
  if (const refused* no = std::get_if<refused>(&change)) return *no;
  return accepted{impl_->change_word(std::get<detail::word_change>(change))};
}

void remote_drive::renew_lease() { impl_->sign.renew(); }

reply remote_drive::toggle_control_bit(int bit) {
  if (bit < 0 || bit > 15) return refused{400, "bit must be 0..15"};
  std::lock_guard lock(impl_->mutex);
  if (auto no = impl_->not_running()) return *no;
  return accepted{impl_->change_word(detail::flip_bit(impl_->table, impl_->control_word, bit))};
}

reply remote_drive::new_setpoint() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = m.not_running()) return *no;
  // The mode the drive shows; before the first read of 0x6061, the one asked for.
  std::optional<std::int64_t> mode = m.actual(object_index::modes_of_operation_display);
  if (!mode) {
    const auto requested = m.objects.find(object_index::modes_of_operation);
    if (requested != m.objects.end()) mode = requested->second;
  }
  if (auto no = detail::new_setpoint_refusal(m.table, mode)) return *no;
  constexpr std::uint16_t bit4 = 1u << 4;
  impl::handshake_run h;
  h.raise_at_us = m.now_us;
  if ((m.control_word & bit4) != 0) {
    // A rising edge: bit 4 low for a moment first.
    m.control_word = static_cast<std::uint16_t>(m.control_word & ~bit4);
    m.remote.send_control_word(m.control_word);
    h.raise_at_us = m.now_us + m.config.reset_pulse_us;
  }
  m.handshake = h;
  std::string options;
  if ((m.control_word & (1u << 5)) != 0) options += ", change set immediately";
  if ((m.control_word & (1u << 6)) != 0) options += ", relative";
  if ((m.control_word & (1u << 9)) != 0) options += ", change on set-point";
  return accepted{m.log.report_now(
      "NEW_SET-POINT", "done",
      "done" + options + ": bit 4 up until the drive acknowledges (status bit 12), then down")};
}

reply remote_drive::write_object(std::uint16_t index, std::int64_t value) {
  if (index == 0x6040) {
    return refused{400, "the control word is set by commands and bit toggles, not written here"};
  }
  const object_description* t = type_of(index);
  if (t == nullptr) {
    return refused{400, "object " + hex(index, 4) +
                            " is not one the page writes on a remote drive (option codes, "
                            "0x6060, 0x6083..0x6085, 0x60FF)"};
  }
  const std::string action = "WRITE " + hex(index, 4) + " = " + std::to_string(value);
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (const auto a = out_of_type(*t, value)) {
    const std::string text = "refused: " + abort_text(*a) + ", checked before sending";
    m.log.report_now(action, "refused", text);
    return refused{422, action + ": " + abort_text(*a), *a};
  }
  if (auto no = m.not_running()) return *no;
  const auto w = m.download(lock, index, value, static_cast<unsigned>(type_size(t->type)), [&m, index, value] {
    m.objects[index] = value;
    if (index == 0x60FF) m.target_velocity = static_cast<std::int32_t>(value);
  });
  return m.download_reply(w, action);
}

reply remote_drive::change_plant(const plant_change& change) {
  if (change.dc_link || change.sto) {
    return refused{409, std::string("DC-link voltage and STO are ") + not_remote};
  }
  if (change.target_velocity && change.fault) {
    return refused{400, "on a remote drive the target velocity and a fault go in separate requests"};
  }
  if (!change.target_velocity && !change.fault) return refused{400, "nothing to change"};
  if (change.fault && *change.fault && change.fault_code == 0) {
    return refused{400, "a fault needs a code 0x0001..0xFFFF and a class 0..4"};
  }
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (change.target_velocity) {
    const std::int64_t v = *change.target_velocity;
    const std::string action = "TARGET_VELOCITY=" + std::to_string(v);
    if (const auto a = out_of_type(*type_of(0x60FF), v)) {
      m.log.report_now("WRITE 0x60FF = " + std::to_string(v), "refused", "refused: " + abort_text(*a));
      return refused{422, "WRITE 0x60FF = " + std::to_string(v) + ": " + abort_text(*a), *a};
    }
    if (auto no = m.not_running()) return *no;
    const auto w = m.download(
        lock, 0x60FF, v, 4,
        [&m, v] {
          m.objects[0x60FF] = v;
          m.target_velocity = static_cast<std::int32_t>(v);
        },
        action);
    return m.download_reply(w, action);
  }
  if (!m.remote.fault_injection()) {
    return refused{409, std::string("fault injection is ") + not_remote + " (" + m.node_text() +
                            " has no fault-injection object 0x2001 of cia402 bus)"};
  }
  if (auto no = m.not_running()) return *no;
  const std::uint16_t code = *change.fault ? change.fault_code : 0;
  std::string action = *change.fault ? "FAULT " + hex(code, 4) + " ON" : std::string("FAULT OFF");
  // 0x2001 takes an error code only; the drive raises it with its default class.
  if (*change.fault && m.table.error_classes) action += " (class not sent: 0x2001 takes a code)";
  const auto w = m.download(
      lock, fault_injection_index, code, 2, [&m, code] { m.injected_fault = code; }, action);
  return m.download_reply(w, action);
}

std::string remote_drive::info_json(bool control, bool token_required) const {
  std::lock_guard lock(impl_->mutex);
  const impl& m = *impl_;
  json j = detail::profile_info(m.table);
  j["backend"] = "remote";
  j["remote"] = m.remote.where();
  j["transitions_inferred"] = true;
  j["control"] = control;
  j["token_required"] = token_required;
  j["cycle_us"] = m.config.cycle_us;
  j["lease_ms"] = m.sign.lease_us() / 1000;
  j["publish_ms"] = m.config.publish_us / 1000.0;
  j["capabilities"] = m.capabilities();
  // The modes the drive's own 0x6502 announces, where it was read.
  const auto supported = m.remote.start_values().find(object_index::supported_drive_modes);
  if (supported != m.remote.start_values().end()) {
    for (json& o : j["objects"]) {
      if (o["index"] != hex(object_index::modes_of_operation, 4)) continue;
      json values = json::array();
      for (int k = 1; k <= 10; ++k) {
        if ((mode::supported_bit(k) & static_cast<std::uint32_t>(supported->second)) != 0) values.push_back(k);
      }
      o["values"] = std::move(values);
    }
  }
  return j.dump();
}

std::string remote_drive::snapshot_json() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->board.present_json(impl_->snapshot(true));
}

std::string remote_drive::recording_json(std::uint64_t rows_seen,
                                         std::uint64_t transitions_seen) const {
  std::lock_guard lock(impl_->mutex);
  return impl_->recording.since_json(rows_seen, transitions_seen).dump();
}

std::string remote_drive::recording_file(recording_format format) const {
  std::lock_guard lock(impl_->mutex);
  sim::trace_info info;
  info.title = "instrument page recording of node " + std::to_string(impl_->config.node_id) +
               " (plant columns inferred from the status word)";
  info.profile_name = impl_->table.name;
  info.cycle_us = 1000;
  info.brake_fitted = false;
  return impl_->recording.file(format, info);
}

std::optional<published> remote_drive::wait_for_update(std::uint64_t seen,
                                                       std::chrono::milliseconds timeout) {
  return impl_->board.wait_for_update(seen, timeout);
}

published remote_drive::latest() const { return impl_->board.latest(); }

void remote_drive::close() {
  {
    // Under the drive's lock, so a request waiting for its transfer cannot miss it.
    std::lock_guard lock(impl_->mutex);
    impl_->board.close();
  }
  impl_->job_done.notify_all();
}

bool remote_drive::closed() const { return impl_->board.closed(); }

remote_status remote_drive::status() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->status();
}

std::string remote_drive::status_text() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->remote.phase_text();
}

bool remote_drive::fault_injection_available() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->remote.fault_injection();
}

}  // namespace cia402::page
