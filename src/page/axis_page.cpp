// The page's drive: the session's cycle, what the drive shows (transitions, rows, snapshots) and the
// parts of the backend interface that only read (axis_page.hpp).
#include "axis_page_impl.hpp"

#include <algorithm>
#include <stdexcept>
#include <thread>

#include "cia402/error_codes.hpp"
#include "cia402/manufacturer_objects.hpp"
#include "cia402/objects.hpp"
#include "cia402/page/transition_inference.hpp"
#include "cia402/words.hpp"
#include "page_json.hpp"
#include "json_text.hpp"
#include "page_names.hpp"

namespace cia402::page {
namespace {

using json = nlohmann::ordered_json;
using detail::hex;

constexpr const char* not_remote = "not available on a remote drive";

constexpr std::uint16_t following_error_actual = 0x60F4;  // CiA 402-2
constexpr std::uint16_t error_register = 0x1001;          // CiA 301

// What a drive on a bus does not carry cyclically and the snapshots show: polled by the session.
constexpr std::uint16_t shown_actuals[] = {
    object_index::modes_of_operation, object_index::modes_of_operation_display, object_index::position_actual_value,
    object_index::torque_actual_value, following_error_actual,
    object_index::velocity_actual_value, object_index::target_velocity, error_register,
    object_index::digital_inputs};

}  // namespace

axis_page::impl::impl(const profile& p, connection_factory f, axis_page_config c)
    : table(&p),
      connect(std::move(f)),
      config(std::move(c)),
      drive(connect ? connect(p) : drive_connection{}),
      plant(detail::local_plant::of(drive)),
      log({config.results_kept, config.settle_quiet_us, config.settle_limit_us,
           "still busy when the page stopped waiting", plant ? "" : " (numbers inferred)"},
          [this] { return how_it_stands(); }) {
  if (config.cycle_us == 0) config.cycle_us = 1000;
  start_session(p);
  if (plant) {
    if (config.selectable.empty()) {
      for (std::size_t i = 0; i < builtin_profile_count(); ++i) config.selectable.push_back(&builtin_profile(i));
    }
    if (std::find(config.selectable.begin(), config.selectable.end(), &p) == config.selectable.end()) {
      config.selectable.insert(config.selectable.begin(), &p);
    }
  }
}

axis_page::impl::~impl() = default;

void axis_page::impl::start_session(const profile& p) {
  if (!drive.link) throw std::invalid_argument("axis_page: the connection gave no link");
  table = &p;
  axes::session_config sc;
  sc.drive_profile = &p;
  sc.lease_us = lease_armed ? config.lease_us : 0;  // see renew_lease()
  sc.poll_us = config.poll_us;
  sc.reset_pulse_us = config.reset_pulse_us != 0 ? config.reset_pulse_us : config.cycle_us;
  session = std::make_unique<axes::session>(*drive.link, sc);
  session->on_state = [this](state from, state to, std::uint16_t sw) { on_state(from, to, sw); };
  session->on_cycle = [this] { on_cycle(); };
  session->on_link = [this](axes::link_event e, const std::string& text) {
    if (e == axes::link_event::failed) {
      observed.reset();
      offering.reset();
      log.finish_pending(text.c_str());
    } else if (e == axes::link_event::restarted) {
      injected_fault = 0;
      objects.clear();
      homing_read_asked = false;
      error_field.stale = true;
    } else if (e == axes::link_event::running) {
      drive.link->start_cyclic();
    }
  };
  session->on_progress = [this](axes::progress_kind k, const axes::result&) {
    if (k == axes::progress_kind::jog_started && jogging) jogging->turning = true;
  };
  session->on_emergency = [this](std::uint16_t code, std::uint8_t, std::span<const std::uint8_t>) {
    last_emergency = code;
  };
  session->on_lease_lapsed = [this](const std::string& what) {
    const std::string action = "SIGN OF LIFE LOST (no page for " + std::to_string(session->lease_us() / 1000) +
                               " ms, 0x6007 = " + std::to_string(session->option_code(option::abort_connection)) + ")";
    if (observed == state::operation_enabled) {
      log.track(action + ": " + what, false, observed, now_us);
    } else {
      log.report_now(action, "nothing to do", "nothing to do: " + what);
    }
  };
  if (!plant) {
    for (const std::uint16_t index : shown_actuals) session->keep_polled(index, true);
  }
  drive.link->start_cyclic();
  // A drive in this process is read at start without time passing: the page opens on it prepared.
  // On a bus the start-up reads come with the cycle thread's polls.
  (void)session->poll_until_idle();
}

void axis_page::impl::advance(std::uint32_t elapsed_us) {
  now_us += elapsed_us;
  session->poll(elapsed_us);
  if (elapsed_us > 0) ++cycles;
  if (plant) {
    close_row();
    if (observed) note_error_code(plant->error_code());
  } else if (observed) {
    record_bus_row();
    note_error_code(session->error_code());
  }
  keep_views_read();
  check_enable_walk();
  if (log.pending()) log.settle(now_us, busy_now());
  if (now_us >= next_publish_us) {
    next_publish_us = now_us + config.publish_us;
    board.publish([this](bool with_time) { return snapshot(with_time); });
  }
  answered.notify_all();
}

// The status word shows another state. A drive in this process says which transition it took (its
// own rows, on_cycle); on a bus the number is inferred from the profile's rows and the words sent.
void axis_page::impl::on_state(state from, state to, std::uint16_t status_word) {
  const bool first = !observed;
  observed = to;
  // A drive in this process: its step ran, the row that closes says which transition it took
  // (before the session's requests learn the new state).
  if (plant) return close_row();
  if (first || from == to) return;
  const std::vector<inferred_transition> chain = infer_transitions(
      *table, from, to, observer_facts(*table, word_shown(), reset_sent_since_change));
  reset_sent_since_change = false;
  if (chain.empty()) return note_transition(std::nullopt, from, to, true, status_word);
  for (const inferred_transition& t : chain) note_transition(int{t.number}, t.from, t.to, true, status_word);
}

void axis_page::impl::note_transition(std::optional<int> number, state from, state to, bool inferred,
                                      std::uint16_t status_word, std::optional<std::uint64_t> at_us) {
  last_transition = transition_seen{number, from, to, inferred};
  if (inferred && number) transition_for_sample = transition_for_row = number;
  recording.note_transition({0, at_us.value_or(now_us), number, from, to, word_shown(), status_word, inferred});
  if (!number) return;
  if (auto* a = log.pending()) {
    a->transitions.push_back(*number);
    a->busy_until = now_us;
  }
  if (enabling) enabling->transitions.push_back(*number);
  if (stopping) stopping->transitions.push_back(*number);
}

void axis_page::impl::note_error_code(std::uint16_t code) {
  if (code == error_shown) return;
  error_shown = code;
  error_field.stale = true;  // the drive's own list 0x1003 changed with it
  if (code == 0) return;
  errors_seen.push_front({now_us, code, config.wall_clock_us ? std::optional(config.wall_clock_us()) : std::nullopt});
  if (errors_seen.size() > errors_kept) errors_seen.pop_back();
}

// Once per cycle of a drive in this process, before its step: the cycle before is complete.
void axis_page::impl::on_cycle() {
  if (!plant) return push_bus_sample();
  close_row();
  open_plant_sample(plant->open_cycle());
}

// A drive in this process only: the cycle its step ended, once.
void axis_page::impl::close_row() {
  const auto c = plant->close_cycle();
  if (!c) return;
  recording.record(c->row);
  push_plant_sample(c->out);
  if (c->out.transition != no_transition) {
    // At the time of the cycle whose step took it, as the recording's row for that cycle says.
    note_transition(int{c->out.transition}, c->before, c->out.current, false, c->out.status_word, c->row.time_us);
  }
}

// A drive on a bus shows the words, the state, the velocity and the error code; the plant columns
// are what the status word and the state tell: DC link = status bit 4 (S11), torque and brake from
// the state's activity, STO and the fault cause unknown (recorded as off).
void axis_page::impl::record_bus_row() {
  sim::trace_row row;
  row.time_us = now_us;
  row.velocity = value_of(object_index::velocity_actual_value).value_or(0) * 1000000;
  row.target_velocity = static_cast<std::int32_t>(value_of(object_index::target_velocity).value_or(0));
  row.control_word = word_shown();
  row.status_word = session->status_word();
  row.error_code = session->error_code();
  row.current = *observed;
  // The inferred transition in the row of the cycle it was seen in (the scope's trigger reads rows);
  // of a chain seen in one cycle (3 then 4) the row holds the last, as the sample does.
  row.transition = transition_for_row ? static_cast<std::uint8_t>(*transition_for_row) : no_transition;
  transition_for_row.reset();
  row.torque = table->info(*observed).activity != state_activity::idle;
  row.brake_released = row.torque;
  row.brake_engaged = !row.torque;
  row.dc_link = (row.status_word & status_bit::voltage_enabled) != 0;
  row.position = value_of(object_index::position_actual_value).value_or(0);
  row.position_demand = row.position;
  row.torque_permille = static_cast<std::int32_t>(value_of(object_index::torque_actual_value).value_or(0));
  row.mode = static_cast<std::int8_t>(value_of(object_index::modes_of_operation_display).value_or(0));
  recording.record(row);
}

// The walk to OPERATION ENABLED ends where the drive's own inputs block it (a fault, STO, no DC
// link), and leaves no Enable operation in the word: it would act by itself once the blocker is
// gone, a restart nobody asked for.
void axis_page::impl::check_enable_walk() {
  if (!enabling || !observed) return;
  const std::string why = enable_blocker(*observed);
  if (why.empty()) return;
  // Over before the word goes: the session ends the walk it supersedes from inside send_word.
  const operation walk = *enabling;
  enabling.reset();
  std::uint16_t word = 0;
  if (table->decode(word_shown()) == command::enable_operation &&
      encode_command(*table, command::switch_on, word_shown(), word)) {
    send_word(word, false);
  } else {
    send_word(word_shown(), false);  // the walk ends where it stands
  }
  log.update({walk.id, walk.action, "refused", "refused in " + std::string(state_name(*observed)) + ": " + why,
              walk.transitions});
}

// Something still goes on that keeps the tracked action from settling: a word not yet sent, a stop
// that ramps (QUICK STOP ACTIVE, FAULT REACTION ACTIVE until the shaft stands).
bool axis_page::impl::busy_now() const {
  if (requested_word) return true;
  return plant && plant->stop_ramping(*table);
}

std::optional<std::int64_t> axis_page::impl::value_of(std::uint16_t index) const {
  if (auto v = session->actual(index)) return v;
  if (auto v = session->output(index)) return v;
  if (const auto o = objects.find(index); o != objects.end()) return o->second;
  for (int k = 0; k < option_count; ++k) {
    const auto o = static_cast<option>(k);
    if (option_index(o) == index && session->prepared()) return session->option_code(o);
  }
  return std::nullopt;
}

std::uint16_t axis_page::impl::word_shown() const { return session->control_word().value_or(0); }

std::string axis_page::impl::link_text() const {
  const std::string text = session->link().phase_text();
  if (session->link().phase() == axes::link_phase::running) return "";
  return text.empty() ? session->link().short_name() + " is connecting" : text;
}

std::string axis_page::impl::conditions() const {
  std::string s;
  auto add = [&s](const std::string& what) { s += (s.empty() ? " (" : ", ") + what; };
  if (plant) {
    for (const std::string& held : plant->conditions()) add(held);
  } else if (session->status_known()) {
    const std::uint16_t sw = session->status_word();
    if (session->error_code() != 0) add("the drive reports error code " + hex(session->error_code(), 4));
    if ((sw & status_bit::voltage_enabled) == 0) add("no DC-link voltage: status bit 4 is 0");
    if ((sw & status_bit::remote) == 0) add("status bit 9 (remote) is 0: the drive does not process the control word");
  }
  if (!s.empty()) s += ")";
  return s;
}

detail::action_log::standing axis_page::impl::how_it_stands() const {
  const state now = observed.value_or(state::start);
  // On a bus the page cannot tell what holds a tracked action back: it settles on the quiet alone.
  const std::string waiting_for = plant ? plant->waiting_for() : std::string();
  return {now, observed ? state_name(now) : "UNKNOWN", conditions(), waiting_for};
}

json axis_page::impl::capabilities() const {
  if (plant) return {{"fault", true}, {"dc_link", true}, {"sto", true}, {"reasons", json::object()}};
  json reasons = json::object();
  const bool fault_injection = session->device_name() == virtual_drive_device_name;
  if (!fault_injection) {
    reasons["fault"] = std::string(not_remote) + " (only a cia402 bus node offers fault injection, object 0x2001)";
  }
  reasons["dc_link"] = not_remote;
  reasons["sto"] = not_remote;
  return {{"fault", fault_injection}, {"dc_link", false}, {"sto", false}, {"reasons", reasons}};
}

json axis_page::impl::remote_json() const {
  const axes::drive_link& l = session->link();
  json r;
  r["node"] = config.node;
  r["bus"] = config.bus.empty() ? l.what() : config.bus;
  if (!config.where.empty()) r["where"] = config.where;
  r["status"] = running() ? "running"
                : l.phase() == axes::link_phase::failed ? "no_answer"
                                                        : "configuring";
  r["text"] = link_text();
  r["nmt"] = nullptr;
  // A drive's name may be bytes that are not UTF-8 (Latin-1 "Servoverst\xe4rker"): shown as Latin-1.
  r["device_name"] = detail::display_text(session->device_name());
  r["cyclic"] = l.cyclic();
  r["lease_lapsed"] = session->lease_lapsed();
  r["last_emcy"] = last_emergency ? json(hex(*last_emergency, 4)) : json(nullptr);
  return r;
}

json axis_page::impl::snapshot(bool with_time) const {
  json j;
  j["state"] = observed ? state_name(*observed) : "UNKNOWN";
  j["status_word"] = hex(session->status_word(), 4);
  j["control_word"] = hex(word_shown(), 4);
  j["decodes_to"] = command_name(table->decode(word_shown()));
  if (last_transition) {
    j["last_transition"] = {{"number", last_transition->number ? json(*last_transition->number) : json(nullptr)},
                            {"from", state_name(last_transition->from)},
                            {"to", state_name(last_transition->to)}};
    if (last_transition->inferred) j["last_transition"]["inferred"] = true;
  } else {
    j["last_transition"] = nullptr;
  }
  if (plant) {
    plant->show(j, *table);
  } else {
    j = bus_snapshot(std::move(j));
  }
  j["results"] = log.results_json();
  json history = json::array();
  for (const error_seen& e : errors_seen) {
    history.push_back({{"time_ms", e.time_us / 1000}, {"code", hex(e.code, 4)}, {"text", error_code_text(e.code)},
                       {"unix_ms", e.wall_us ? json(*e.wall_us / 1000) : json(nullptr)}});
  }
  j["error_history"] = std::move(history);
  j["drive_errors"] = drive_errors_json();
  j["homing"] = homing_json();
  j["doing_now"] = detail::doing_now(mode_reading_now());
  j["set_point"] = set_point_json();
  // "Why can't I enable?": what blocks the way to OPERATION ENABLED now, from the drive's own inputs.
  const std::string blocker =
      observed && *observed != state::operation_enabled ? enable_blocker(*observed) : std::string();
  j["enable_blocker"] = blocker.empty() ? json(nullptr) : json(blocker);
  j["profile"] = table->name;
  if (with_time) {
    j["cycle"] = cycles;
    j["time_ms"] = now_us / 1000;
  }
  return j;
}

// What a drive on a bus shows of itself; what the bus does not show is null (the page shows it as
// unknown), and a silent drive's last values are history, null too.
json axis_page::impl::bus_snapshot(json j) const {
  const bool live = session->link().phase() == axes::link_phase::running;
  const auto shown = [live, this](std::uint16_t index) {
    const auto v = value_of(index);
    return live && v ? json(*v) : json(nullptr);
  };
  const std::uint16_t sw = session->status_word();
  j["stop_running"] = nullptr;
  j["ramp"] = nullptr;
  j["error_code"] = hex(session->error_code(), 4);
  j["error_text"] = error_code_text(session->error_code());
  const auto reg = session->actual(error_register);
  j["error_register"] = hex(reg.value_or(0), 2);
  j["velocity"] = shown(object_index::velocity_actual_value);
  const auto target = value_of(object_index::target_velocity);
  j["target_velocity"] = target ? json(*target) : json(nullptr);
  j["effective_target"] = j["target_velocity"];
  j["torque"] = nullptr;
  j["brake_engaged"] = nullptr;
  j["dc_link"] = live && session->status_known() ? json((sw & status_bit::voltage_enabled) != 0) : json(nullptr);
  j["sto"] = nullptr;
  j["fault_cause"] = capabilities()["fault"].get<bool>() ? json(hex(injected_fault, 4)) : json(nullptr);
  j["mode"] = shown(object_index::modes_of_operation_display);
  const auto requested = value_of(object_index::modes_of_operation);
  j["requested_mode"] = requested ? json(*requested) : json(nullptr);
  j["position"] = shown(object_index::position_actual_value);
  j["position_demand"] = nullptr;
  j["following_error"] = shown(following_error_actual);
  j["torque_actual"] = shown(object_index::torque_actual_value);
  j["digital_inputs"] = shown(object_index::digital_inputs);
  json objs = json::object();
  for (const object_name& o : object_names(*table)) {
    if (const auto v = value_of(o.index)) objs[hex(o.index, 4)] = *v;
  }
  j["objects"] = std::move(objs);
  j["remote"] = remote_json();
  j["capabilities"] = capabilities();
  return j;
}

// --- the backend interface: the cycle and what only reads -------------------------------------

axis_page::axis_page(const profile& p, connection_factory connect, axis_page_config config)
    : impl_(std::make_unique<impl>(p, std::move(connect), std::move(config))) {}

axis_page::~axis_page() { close(); }

void axis_page::shut_down(std::chrono::milliseconds wait) {
  close();
  std::lock_guard lock(impl_->mutex);
  axes::session& s = *impl_->session;
  s.close(true);
  using clock = std::chrono::steady_clock;
  const auto end = clock::now() + wait;
  auto last = clock::now();
  while (!s.closed() && clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const auto now = clock::now();
    s.poll(static_cast<std::uint32_t>(std::chrono::duration_cast<std::chrono::microseconds>(now - last).count()));
    last = now;
  }
}

void axis_page::step() { advance(impl_->config.cycle_us); }

void axis_page::advance(std::uint32_t elapsed_us) {
  std::lock_guard lock(impl_->mutex);
  impl_->advance(elapsed_us);
}

std::uint64_t axis_page::cycle() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->cycles;
}

std::string axis_page::link_text() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->link_text();
}

bool axis_page::fault_injection_available() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->capabilities()["fault"].get<bool>();
}

std::string axis_page::info_json(bool control, bool token_required) const {
  std::lock_guard lock(impl_->mutex);
  const impl& m = *impl_;
  json j = detail::profile_info(*m.table);
  // The period of the drive's cycles, one scope sample each: a step here, the link's cycle on a bus
  // (the SYNC period over CANopen, the LRW's over EtherCAT), not the page's own step.
  std::uint32_t cycle_us = m.config.cycle_us;
  if (m.plant) {
    j["backend"] = "virtual";
    json profiles = json::array();
    for (const profile* p : m.config.selectable) profiles.push_back({{"name", p->name}, {"title", p->title}});
    j["profiles"] = std::move(profiles);
  } else {
    j["backend"] = "remote";
    j["remote"] = {{"node", m.config.node}, {"bus", m.config.bus.empty() ? m.session->link().what() : m.config.bus}};
    j["transitions_inferred"] = true;
    cycle_us = m.session->link().cycle_us();
    // The modes the drive's own 0x6502 announces, where it was read.
    if (const auto supported = m.session->supported_modes()) {
      for (json& o : j["objects"]) {
        if (o["index"] != hex(object_index::modes_of_operation, 4)) continue;
        json values = json::array();
        for (int k = 1; k <= 10; ++k) {
          if ((mode::supported_bit(k) & *supported) != 0) values.push_back(k);
        }
        o["values"] = std::move(values);
      }
    }
  }
  j["control"] = control;
  j["token_required"] = token_required;
  j["cycle_us"] = cycle_us;
  j["lease_ms"] = m.config.lease_us / 1000;
  // Snapshots come at most this often (the plot holds a value across a gap between them).
  j["publish_ms"] = m.config.publish_us / 1000.0;
  j["capabilities"] = m.capabilities();
  return detail::json_text(j);
}

std::string axis_page::snapshot_json() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->board.present_json(impl_->snapshot(true));
}

std::string axis_page::recording_json(std::uint64_t rows_seen, std::uint64_t transitions_seen) const {
  std::lock_guard lock(impl_->mutex);
  return detail::json_text(impl_->recording.since_json(rows_seen, transitions_seen));
}

std::string axis_page::recording_file(recording_format format) const {
  std::lock_guard lock(impl_->mutex);
  const impl& m = *impl_;
  sim::trace_info info;
  info.profile_name = m.table->name;
  info.cycle_us = m.config.cycle_us;
  if (m.plant) {
    info.title = "instrument page recording";
  } else {
    info.title = "instrument page recording of " + m.session->link().short_name() +
                 " (plant columns inferred from the status word)";
    info.brake_fitted = false;
  }
  return m.recording.file(format, info);
}

std::optional<published> axis_page::wait_for_update(std::uint64_t seen, std::chrono::milliseconds timeout) {
  return impl_->board.wait_for_update(seen, timeout);
}

published axis_page::latest() const { return impl_->board.latest(); }

void axis_page::close() {
  {
    // Under the page's lock, so a request waiting for its answer cannot miss it.
    std::lock_guard lock(impl_->mutex);
    impl_->board.close();
  }
  impl_->answered.notify_all();
}

bool axis_page::closed() const { return impl_->board.closed(); }

}  // namespace cia402::page
