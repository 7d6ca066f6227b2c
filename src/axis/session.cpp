// The session's loop: the link's poll, what the status word shows, the operation's steps, the lease
// and the control word (session.hpp).
#include <algorithm>

#include "cia402/error_codes.hpp"
#include "cia402/lost_client.hpp"
#include "cia402/objects.hpp"
#include "cia402/words.hpp"
#include "session_internal.hpp"

namespace cia402::axes {

std::string word_hex(std::uint16_t w) {
  static const char* d = "0123456789ABCDEF";
  std::string s = "0x";
  for (int i = 3; i >= 0; --i) s += d[(w >> (4 * i)) & 0xF];
  return s;
}

std::string object_name(std::uint16_t index, std::uint8_t sub) { return word_hex(index) + ":" + std::to_string(sub); }

std::string error_code_words(std::uint16_t code) { return word_hex(code) + " (" + error_code_text(code) + ")"; }

std::string transfer_failure(const transfer_result& r) {
  if (r.cancelled) return "cancelled: the link to the drive was lost";
  if (r.abort != sdo_abort::none) {
    static const char* d = "0123456789ABCDEF";
    const auto code = static_cast<std::uint32_t>(r.abort);
    std::string s = "SDO abort 0x";
    for (int i = 7; i >= 0; --i) s += d[(code >> (4 * i)) & 0xF];
    return s + " (" + sdo_abort_text(r.abort) + ")";
  }
  return r.error.empty() ? std::string("no answer") : r.error;
}

std::string mode_words(std::int64_t m) {
  const std::string name = mode::short_name(m);
  return name.empty() ? "mode " + std::to_string(m) : name + " (" + std::to_string(m) + ")";
}

session::session(drive_link& link, const session_config& config)
    : link_(&link),
      config_(config),
      profile_(config.drive_profile != nullptr ? config.drive_profile : &standard_profile()),
      options_(make_axis(*profile_)),
      lease_us_(config.lease_us) {
  link_->on_event = [this](link_event e, const std::string& text) { on_link_event(e, text); };
  link_->on_emergency = [this](std::uint16_t code, std::uint8_t reg, std::span<const std::uint8_t> bytes) {
    if (on_emergency) on_emergency(code, reg, bytes);
  };
  link_->before_cycle = [this] {
    stream_tick();
    if (on_cycle) on_cycle();
  };
  if (link_->phase() == link_phase::running) start_up_reads();
}

session::~session() {
  link_->on_event = nullptr;
  link_->on_emergency = nullptr;
  link_->before_cycle = nullptr;
}

// --- the loop -----------------------------------------------------------------------------------

std::uint32_t session::poll(std::uint32_t elapsed_us) {
  now_us_ += elapsed_us;
  const std::uint32_t link_next = link_->poll(elapsed_us);
  if (link_->phase() == link_phase::running && !start_up_queued_) start_up_reads();
  std::vector<std::function<void()>> due;
  due.swap(deferred_);
  for (auto& f : due) f();
  if (!after_settled_.empty() && settled()) {
    std::vector<std::function<void()>> settled_now;
    settled_now.swap(after_settled_);
    for (auto& f : settled_now) f();
  }
  note_status();
  check_lease();
  run_operation();
  run_jobs();
  drive_control_word();
  if (closing_ && !op_ && !link_closed_) {
    link_closed_ = true;
    link_->close();
  }
  return std::min(link_next, next_deadline());
}

bool session::poll_until_idle() {
  // A transfer answered in one round may queue the next (a read whose completion asks for more),
  // and the session hands the link one transfer at a time: so the rounds go on while either says so.
  const auto work_left = [this] { return !deferred_.empty() || link_->work_now(); };
  (void)poll(0);
  for (int round = 1; round < max_zero_time_polls && work_left(); ++round) (void)poll(0);
  return !work_left();
}

void session::on_link_event(link_event e, const std::string& text) {
  switch (e) {
    case link_event::running:
      if (!start_up_queued_) start_up_reads();
      break;
    case link_event::cyclic: break;
    case link_event::failed:
    case link_event::restarted:
      // What was read or commanded is unknown again: a restarted drive has its defaults, a lost one
      // may have done anything meanwhile.
      prepared_ = false;
      start_up_queued_ = false;
      transfer_busy_ = false;
      control_ = control::none;
      sent_.reset();
      state_announced_ = false;
      observed_ = state::start;
      for (auto& [index, p] : polled_) {
        p.value.reset();
        p.absent = false;
      }
      outputs_.clear();
      if (op_) finish(outcome::failed, e == link_event::failed ? link_->short_name() + ": " + text : text);
      break;
  }
  if (on_link) on_link(e, text);
}

void session::note_status() {
  if (!status_known()) return;
  state s = state::start;
  if (!decode_status(*profile_, link_->status_word(), s)) s = state::start;
  if (s != observed_ || !state_announced_) {
    const state before = observed_;
    observed_ = s;
    state_announced_ = true;
    if (on_state) on_state(before, s, link_->status_word());
  }
  status_seen_ = link_->status_count();
}

std::uint64_t session::begin(std::string name, std::vector<step> steps, completion done, bool motion) {
  if (op_) finish(outcome::superseded, "superseded by " + name);
  // A motion command starts without the halt a stop left (halt set by hand is refused in check()).
  auto op = std::make_unique<operation>();
  op->id = next_id_++;
  op->name = std::move(name);
  op->steps = std::move(steps);
  op->motion = motion;
  op->done = std::move(done);
  op->res.id = op->id;
  op_ = std::move(op);
  return op_->id;
}

void session::run_operation() {
  for (int guard = 0; op_ && guard < 64; ++guard) {
    operation& op = *op_;
    if (link_->phase() == link_phase::failed) {
      return finish(outcome::failed, link_->short_name() + ": " + link_->phase_text());
    }
    if (!op.fault_ok && status_known() &&
        (observed_ == state::fault || observed_ == state::fault_reaction_active)) {
      // Before it commanded anything a request is refused; later the fault ended it.
      return finish(outcome::failed, fault_text() + (op.commanded ? "" : "; reset it first"));
    }
    if (op.at >= op.steps.size()) return finish(outcome::done, {});
    step& s = op.steps[op.at];
    if (!op.started) {
      op.started = true;
      if (s.start) s.start();
      if (op_.get() != &op) return;  // the start finished the operation (or began another)
    }
    const step_state st = s.poll ? s.poll() : step_state::done;
    if (op_.get() != &op) return;
    if (st == step_state::running) return;
    if (st == step_state::failed) return finish(outcome::failed, op.error);
    ++op.at;
    op.started = false;
  }
}

void session::fill_result(result& r) const {
  // What the cyclic data shows; a result that read the status over SDO keeps what it read.
  if (status_known()) {
    r.status_word = link_->status_word();
    r.shown = observed_;
    r.error_code = error_code();
  }
  if (const auto m = actual(object_index::modes_of_operation_display)) r.mode = static_cast<std::int8_t>(*m);
}

void session::finish(outcome end, std::string error) {
  if (!op_) return;
  std::unique_ptr<operation> op = std::move(op_);
  for (std::uint16_t index : op->polls) {
    auto p = polled_.find(index);
    if (p != polled_.end() && p->second.wanted > 0) --p->second.wanted;
  }
  if (op->streaming) {
    source_ = nullptr;
    if (end != outcome::done) error += "; max following error seen " + std::to_string(max_following_error_);
  }
  if (op->jogging) {
    // A jog that ends other than by its release leaves no velocity behind.
    jog_until_us_ = 0;
    write_integer(object_index::target_velocity, 0, 0, [](const std::string&) {});
  }
  result& r = op->res;
  r.end = end;
  r.error = std::move(error);
  if (op->limited) {
    const std::string limit = "the drive limited the set-point: status bit 11 (internal limit active) was set";
    if (end == outcome::failed) r.error += "; " + limit;
    else r.note += (r.note.empty() ? "" : "; ") + limit;
  }
  // S20: a motion command that failed stops what it set moving before it says so.
  if (end == outcome::failed && op->motion && op->commanded && stop_after_failure(op)) return;
  fill_result(r);
  if (op->done) op->done(r);
}

void session::cancel(std::string why) {
  if (!op_ || op_->stop) return;
  finish(outcome::failed, std::move(why));
}

bool session::stop_after_failure(std::unique_ptr<operation>& op) {
  result& r = op->res;
  if (link_->phase() != link_phase::running || !status_known()) {
    r.error += "; the link is down: the drive stops as its 0x6007 says (0x6007 = " +
               std::to_string(option_code(option::abort_connection)) + ")";
    return false;
  }
  if (observed_ == state::fault || observed_ == state::fault_reaction_active) {
    r.error += "; the drive's fault reaction stops it (0x605E = " + std::to_string(option_code(option::fault_reaction)) + ")";
    return false;
  }
  if (observed_ == state::quick_stop_active) {
    r.error += "; the drive stops in QUICK STOP ACTIVE as 0x605A = " + std::to_string(option_code(option::quick_stop)) + " says";
    return false;
  }
  if (observed_ != state::operation_enabled) return false;  // no torque: nothing turns by the drive
  auto said = std::make_shared<std::string>();
  std::shared_ptr<operation> failed(std::move(op));
  begin("stop after a failure", {failure_stop(said)}, [this, failed, said](const result& stop) {
    result& out = failed->res;
    out.error += "; " + (stop.ok() || stop.error.empty() ? *said : *said + " (cut short: " + stop.error + ")");
    fill_result(out);
    if (failed->done) failed->done(out);
  }, false);
  op_->stop = true;
  op_->fault_ok = true;
  op_->commanded = true;
  return true;
}

// --- the control word ---------------------------------------------------------------------------

void session::drive_control_word() {
  if (control_ == control::none || !status_known()) return;
  const std::uint16_t app = static_cast<std::uint16_t>(mode_bits_ | ((halt_by_user_ || halt_by_stop_) ? control_bit::halt : 0));
  std::uint16_t word = sent_.value_or(0);
  switch (control_) {
    case control::none: return;
    case control::target:
      master_.application_bits = app;
      word = master_.step(link_->status_word(), now_us_, error_code());
      break;
    case control::command: {
      std::uint16_t w = 0;
      if (encode_command(*profile_, command_, app, w)) word = w;
      break;
    }
    case control::words:
      // The next word only once this one went out, was held its time and the drive answered it:
      // a master whose poll comes late would otherwise send both words of an edge between two
      // cycles of the drive, which then sees no edge at all.
      if (words_.size() > 1 && sent_ == words_.front().first && now_us_ - word_changed_us_ >= words_.front().second &&
          word_taken()) {
        words_.pop_front();
      }
      if (!words_.empty()) word = words_.front().first;
      break;
  }
  if (sent_ && *sent_ == word) return;
  sent_ = word;
  word_changed_us_ = now_us_;
  word_changed_count_ = link_->status_count();
  link_->set_control_word(word);
}

void session::set_target(state target) {
  if (op_) op_->commanded = true;
  control_ = control::target;
  words_.clear();
  policy_ = master_policy::make(*profile_, options_, target);
  // The planner starts from the last word the drive got: its bit 7 decides the first command.
  master_ = cia402::master{};
  master_.set_target(policy_, now_us_, config_.transition_timeout_us);
}

void session::set_command(command c) {
  if (op_) op_->commanded = true;
  control_ = control::command;
  words_.clear();
  command_ = c;
}

void session::set_mode_bits(std::uint16_t bits) {
  mode_bits_ = static_cast<std::uint16_t>(bits & ~(control_bit::halt | owned_control_bits(*profile_)));
  // A status word from before this is no answer to it, even if the word sent turns out the same.
  word_changed_us_ = now_us_;
  word_changed_count_ = link_->status_count();
}

// --- the lease ----------------------------------------------------------------------------------

void session::renew(std::string_view client) {
  lease_renewed_us_ = now_us_;
  lapsed_ = false;
  if (!client.empty()) client_ = std::string(client);
}

void session::set_lease(std::uint64_t lease_us) {
  lease_us_ = lease_us;
  renew();
}

void session::check_lease() {
  if (lease_us_ == 0 || lapsed_ || closing_ || now_us_ - lease_renewed_us_ < lease_us_) return;
  lapsed_ = true;
  const std::string who = client_.empty() ? std::string("the client") : client_;
  // Every operation under way stops, the way up to OPERATION ENABLED too: a drive still switching
  // on would otherwise end enabled with nobody renewing (S20).
  const bool moving = op_ && (op_->motion || op_->commanded) && !op_->stop;
  const bool enabling = control_ == control::target && policy_.target == state::operation_enabled;
  const bool enabled = status_known() && (observed_ == state::operation_enabled || observed_ == state::quick_stop_active);
  if (control_ == control::none || (!moving && !enabling && !enabled)) {
    if (on_lease_lapsed) on_lease_lapsed(who + " stopped renewing its lease; the drive is not enabled: nothing to stop");
    return;
  }
  const std::string action = stop_as_0x6007(who + " stopped renewing its lease");
  if (on_lease_lapsed) on_lease_lapsed(who + " stopped renewing its lease: " + action);
}

std::string session::stop_as_0x6007(const std::string& why) {
  // 0x6007 says what the drive does when its master goes; a master whose client went does the same
  // where it can command it: 2 Disable voltage, 3 Quick stop; 1 (a fault, which a master cannot
  // raise) the quick stop, which stops as 0x605A says; 0 (no action) a halt, which stops the shaft
  // and keeps the drive enabled, or a quick stop where the profile has no halt.
  const int code = option_code(option::abort_connection);
  const lost_client_stop how = stop_for_lost_client(code, profile_->spec(option::halt).exists());
  std::string action;
  std::vector<step> steps;
  if (how == lost_client_stop::disable_voltage) {
    action = "Disable voltage (0x6007 = 2)";
    steps = {command_step(command::disable_voltage), wait_stopped(false)};
  } else if (how == lost_client_stop::halt) {
    action = "halt (0x6007 = 0: no action on the drive; the master stops the shaft and keeps it enabled)";
    steps = {call_step([this] {
               set_mode_bits(0);
               halt_by_stop_ = true;
               // A client's own words carry no halt of the session's: the state it is in is held.
               if (control_ == control::words && observed_ == state::operation_enabled) set_target(observed_);
             }),
             wait_stopped(true)};
  } else {
    action = "Quick stop (0x6007 = " + std::to_string(code) +
             (code == 1 ? ": a fault, which a master cannot raise; the quick stop ends as 0x605A says)" : ")");
    steps = {command_step(command::quick_stop), wait_stopped(false)};
  }
  if (op_) finish(outcome::superseded, why);
  begin("stop (" + why + ")", std::move(steps), nullptr, false);
  op_->fault_ok = true;
  op_->stop = true;
  return action;
}

// --- the end ------------------------------------------------------------------------------------

void session::close(bool stop_first) {
  if (closing_) return;
  closing_ = true;
  jog_until_us_ = 0;
  if (op_) finish(outcome::superseded, "the session closed");
  const bool enabled = status_known() && observed_ == state::operation_enabled && control_ != control::none;
  // As a lapsed lease: the owner went, the drive stops as 0x6007 says; poll() closes the link once
  // the stop has ended (or failed).
  if (stop_first && enabled) (void)stop_as_0x6007("the master is closing");
}

bool session::closed() const { return link_->closing().done; }

// --- what the session knows ---------------------------------------------------------------------

std::uint16_t session::error_code() const noexcept {
  if (const auto code = link_->error_code()) return *code;
  const auto p = polled_.find(object_index::error_code);
  return p != polled_.end() && p->second.value ? static_cast<std::uint16_t>(*p->second.value) : std::uint16_t{0};
}

std::optional<std::int64_t> session::actual(std::uint16_t index) const {
  if (link_->cyclic()) {
    if (const auto v = link_->cyclic_input(index, 0)) return v;
  }
  const auto p = polled_.find(index);
  return p != polled_.end() ? p->second.value : std::nullopt;
}

void session::keep_polled(std::uint16_t index, bool on) {
  polled& p = polled_[index];
  p.wanted = std::max(0, p.wanted + (on ? 1 : -1));
}

std::optional<std::int64_t> session::output(std::uint16_t index) const {
  const auto o = outputs_.find(index);
  return o != outputs_.end() ? std::optional(o->second) : std::nullopt;
}

bool session::put_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) {
  if (!link_->set_cyclic_output(index, sub, value)) return false;
  if (sub == 0) outputs_[index] = value;
  return true;
}

std::uint32_t session::next_deadline() const {
  std::uint64_t next = 0xFFFFFFFFu;  // none
  const auto until = [&](std::uint64_t at) { next = std::min(next, at > now_us_ ? at - now_us_ : 0); };
  if (lease_us_ != 0 && !lapsed_) until(lease_renewed_us_ + lease_us_);
  if (control_ == control::words && words_.size() > 1 && word_changed_us_ + words_.front().second > now_us_) {
    until(word_changed_us_ + words_.front().second);  // after that, the drive's status words wake the poll
  }
  if (jog_until_us_ != 0) until(jog_until_us_);
  for (const auto& [index, p] : polled_) {
    if (p.wanted > 0 && !p.absent) until(p.next_us);
  }
  if (op_) until(now_us_ + config_.poll_us);  // waits and time-outs are checked at least this often
  return static_cast<std::uint32_t>(next);
}

}  // namespace cia402::axes
