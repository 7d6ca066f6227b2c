// The pieces every operation is built of: waiting for the link and the start-up reads, the checks
// that refuse at once, object writes and reads, the mode switch confirmed by 0x6061, state targets
// through the core's planner, and waits.
#include <cstdlib>

#include "cia402/words.hpp"
#include "session_internal.hpp"

namespace cia402::axes {

session::step_state session::fail_step(std::string error) {
  if (op_) op_->error = std::move(error);
  return step_state::failed;
}

void session::progress(progress_kind kind) {
  if (!op_) return;
  fill_result(op_->res);
  if (on_progress) on_progress(kind, op_->res);
}

bool session::settled() const {
  return link_->status_count() >= word_changed_count_ + 2 || now_us_ - word_changed_us_ >= config_.settle_us;
}

bool session::word_taken() const {
  return link_->cyclic() ? link_->status_count() >= word_changed_count_ + 2 : settled();
}

std::optional<std::int64_t> session::fresh(std::uint16_t index, moment m) const {
  if (link_->cyclic()) {
    if (const auto v = link_->cyclic_input(index, 0)) {
      return link_->status_count() >= m.count + 2 ? v : std::nullopt;
    }
  }
  const auto p = polled_.find(index);
  if (p == polled_.end() || !p->second.value || p->second.read_us <= m.us) return std::nullopt;
  return p->second.value;
}

void session::need(std::uint16_t index) {
  if (!op_) return;
  polled& p = polled_[index];
  ++p.wanted;
  p.next_us = std::min(p.next_us, now_us_);
  op_->polls.push_back(index);
}

std::string session::state_text() const {
  if (!status_known()) return "state not known yet";
  std::string s = std::string(state_name(observed_)) + " (statusword " + word_hex(link_->status_word()) + ")";
  return s;
}

std::string session::fault_text() const {
  std::string s = std::string("the drive is in ") + state_name(observed_);
  const std::uint16_t code = error_code();
  s += code != 0 ? ": error code " + error_code_words(code) : ": error code not known";
  return s;
}

std::optional<std::string> session::cannot_command(bool motion) const {
  if (link_->phase() == link_phase::failed) return link_->short_name() + ": " + link_->phase_text();
  // A stop is never refused, not even to a client whose lease lapsed.
  if (lapsed_ && motion) return std::string("the client's lease lapsed and the drive was stopped: renew it first");
  if (!status_known()) return std::nullopt;
  const std::uint16_t sw = link_->status_word();
  if (observed_ == state::fault || observed_ == state::fault_reaction_active) return fault_text() + "; reset it first";
  if ((sw & status_bit::remote) == 0) {
    return "remote is off (status bit 9 is 0, statusword " + word_hex(sw) + "): the drive does not take the control word";
  }
  if (motion && (sw & status_bit::voltage_enabled) == 0) {
    return "no DC link: status bit 4 (voltage enabled) is 0 (statusword " + word_hex(sw) + ")";
  }
  if (motion && halt_by_user_) return std::string("halt is on (control bit 8): halt off first");
  return std::nullopt;
}

// --- steps --------------------------------------------------------------------------------------

session::step session::call_step(std::function<void()> f) {
  return {std::move(f), nullptr};
}

session::step session::need_prepared() {
  return {nullptr, [this] {
            if (link_->phase() == link_phase::failed) return fail_step(link_->short_name() + ": " + link_->phase_text());
            return prepared_ ? step_state::done : step_state::running;
          }};
}

session::step session::need_cyclic() {
  return {[this] { link_->start_cyclic(); },
          [this] {
            if (link_->phase() == link_phase::failed) return fail_step(link_->short_name() + ": " + link_->phase_text());
            return status_known() ? step_state::done : step_state::running;
          }};
}

session::step session::check(bool motion) {
  return {nullptr, [this, motion] {
            if (const auto why = cannot_command(motion)) return fail_step(*why);
            return step_state::done;
          }};
}

session::step session::bits_step(std::uint16_t bits) {
  return {[this, bits] { set_mode_bits(bits); }, nullptr};
}

session::step session::wait_step(std::function<bool()> done, std::uint64_t timeout_us, std::function<std::string()> why) {
  auto since = std::make_shared<std::uint64_t>(0);
  return {[this, since] { *since = now_us_; },
          [this, since, done = std::move(done), timeout_us, why = std::move(why)] {
            if (done()) return step_state::done;
            if (timeout_us != 0 && now_us_ - *since >= timeout_us) return fail_step(why());
            return step_state::running;
          }};
}

session::step session::wait_settled() {
  return {nullptr, [this] { return settled() ? step_state::done : step_state::running; }};
}

session::step session::edge_sent() {
  return wait_step([this] { return words_.size() <= 1 && settled(); }, config_.reset_timeout_us, [this] {
    return "the drive did not answer the control words sent (" + std::to_string(words_.size()) +
           " not yet sent, " + std::to_string(link_->status_count() - word_changed_count_) +
           " status words since the last)";
  });
}

void session::write_integer(std::uint16_t index, std::uint8_t sub, std::int64_t value,
                            std::function<void(std::string)> done) {
  if (index == object_index::modes_of_operation) mode_written_us_ = now_us_;
  if (link_->cyclic() && put_output(index, sub, value)) {
    word_changed_us_ = now_us_;  // the output goes with the next cycle, as a control word does
    word_changed_count_ = link_->status_count();
    done({});
    return;
  }
  const object_description* o = find_drive_object(index, sub);
  const value_format f = o != nullptr ? axes::format_of(o->type) : value_format::integer(smallest_size(value), value < 0);
  std::vector<std::uint8_t> bytes;
  std::string why;
  if (!encode_value(object_value::of_integer(value), f, bytes, why)) {
    done(object_name(index, sub) + ": " + why);
    return;
  }
  queue_download(index, sub, std::move(bytes), [this, index, sub, value, done](const transfer_result& r) {
    if (index == object_index::modes_of_operation) mode_written_us_ = now_us_;
    if (r.ok) return done({});
    // Only an abort is the drive's refusal; anything else is the way to it failing.
    const std::string what = r.abort != sdo_abort::none ? "the drive refused " : "writing ";
    done(what + object_name(index, sub) + " = " + std::to_string(value) + (r.abort != sdo_abort::none ? ": " : " failed: ") +
         transfer_failure(r));
  });
}

session::step session::write_step(std::uint16_t index, std::uint8_t sub, std::int64_t value) {
  struct status {
    bool done = false;
    std::string error;
  };
  auto s = std::make_shared<status>();
  return {[this, s, index, sub, value] {
            write_integer(index, sub, value, [s](std::string error) {
              s->done = true;
              s->error = std::move(error);
            });
          },
          [this, s] {
            if (!s->done) return step_state::running;
            return s->error.empty() ? step_state::done : fail_step(s->error);
          }};
}

session::step session::read_step(std::uint16_t index, std::uint8_t sub, std::function<void(std::int64_t)> use,
                                 bool optional) {
  struct status {
    bool done = false;
    std::string error;
  };
  auto s = std::make_shared<status>();
  return {[this, s, index, sub, use, optional] {
            if (link_->cyclic()) {
              if (const auto v = link_->cyclic_input(index, sub)) {
                use(*v);
                s->done = true;
                return;
              }
            }
            const object_description* o = find_drive_object(index, sub);
            const std::optional<value_format> f = o != nullptr ? std::optional(axes::format_of(o->type)) : std::nullopt;
            queue_upload(index, sub, [s, index, sub, use, optional, f](const transfer_result& r) {
              s->done = true;
              if (r.ok) {
                const object_value v = decode_value(r.data, f);
                if (v.what == value_format::kind::integer) return use(v.number);
                s->error = "reading " + object_name(index, sub) + " gave " + std::to_string(r.data.size()) + " bytes";
                return;
              }
              if (!optional || r.cancelled) s->error = "reading " + object_name(index, sub) + ": " + transfer_failure(r);
            });
          },
          [this, s] {
            if (!s->done) return step_state::running;
            return s->error.empty() ? step_state::done : fail_step(s->error);
          }};
}

session::step session::mode_step(std::int8_t m, bool report_always) {
  struct status {
    bool skip = false;
    bool written = false;
    std::string error;
    moment since;
  };
  auto s = std::make_shared<status>();
  return {[this, s, m] {
            need(object_index::modes_of_operation_display);
            if (supported_modes_ && (*supported_modes_ & mode::supported_bit(m)) == 0) {
              std::string list;
              for (std::int64_t k = 1; k <= 10; ++k) {
                if (*supported_modes_ & mode::supported_bit(k)) list += (list.empty() ? "" : ", ") + mode_words(k);
              }
              s->error = mode_words(m) + " is not among the modes 0x6502 announces (" + (list.empty() ? "none" : list) + ")";
              return;
            }
            const auto shown = actual(object_index::modes_of_operation_display);
            const auto p = polled_.find(object_index::modes_of_operation_display);
            const bool current = link_->cyclic_input(object_index::modes_of_operation_display, 0).has_value() ||
                                 (p != polled_.end() && p->second.read_us >= mode_written_us_);
            if (shown && *shown == m && current) {
              s->skip = true;
              return;
            }
            write_integer(object_index::modes_of_operation, 0, m, [this, s](std::string error) {
              s->written = true;
              s->error = std::move(error);
              s->since = now_moment();
            });
          },
          [this, s, m, report_always] {
            if (!s->error.empty()) return fail_step(s->error);
            if (!s->skip) {
              if (!s->written) return step_state::running;
              const auto shown = fresh(object_index::modes_of_operation_display, s->since);
              if (!shown || *shown != m) {
                if (now_us_ - s->since.us < config_.mode_timeout_us) return step_state::running;
                const auto last = actual(object_index::modes_of_operation_display);
                return fail_step("0x6061 still shows " + (last ? mode_words(*last) : std::string("nothing readable")) + " " +
                                 std::to_string(config_.mode_timeout_us / 1000) + " ms after 0x6060 = " + mode_words(m));
              }
            }
            op_->res.mode = m;
            if (report_always || !s->skip) progress(progress_kind::mode_confirmed);
            return step_state::done;
          }};
}

session::step session::target_step(state target) {
  return {[this, target] { set_target(target); },
          [this, target] {
            if (!settled()) return step_state::running;
            switch (master_.outcome()) {
              case master_outcome::reached: return step_state::done;
              case master_outcome::fault: return fail_step(fault_text());
              case master_outcome::timed_out: {
                std::string why = "transition T" + std::to_string(master_.transition()) + " did not happen within " +
                                  std::to_string(config_.transition_timeout_us / 1000) + " ms (the drive shows " +
                                  state_text();
                const std::uint16_t sw = link_->status_word();
                if ((sw & status_bit::voltage_enabled) == 0) why += "; no DC link: status bit 4 is 0";
                if ((sw & status_bit::warning) != 0) why += "; status bit 7 (warning) is set: safe torque off or another warning";
                return fail_step(why + ")");
              }
              case master_outcome::unreachable:
                return fail_step(std::string("no command sequence leads from ") + state_name(observed_) + " to " +
                                 state_name(target) + " in profile " + profile_->name);
              case master_outcome::not_remote:
                return fail_step("remote is off (status bit 9 is 0): the drive does not take the control word");
              case master_outcome::bad_status_word:
                return fail_step("statusword " + word_hex(link_->status_word()) + " shows no state");
              case master_outcome::idle:
              case master_outcome::in_progress: break;
            }
            return step_state::running;
          }};
}

session::step session::command_step(command c) {
  return {[this, c] { set_command(c); }, nullptr};
}

session::step session::wait_stopped(bool halted) {
  auto since = std::make_shared<std::uint64_t>(0);
  return {[this, since] { *since = now_us_; },
          [this, halted, since] {
            if (!settled()) return step_state::running;
            const std::uint16_t sw = link_->status_word();
            const auto waited = [&] {
              if (now_us_ - *since < config_.stop_timeout_us) return step_state::running;
              return fail_step("the drive did not show standstill within " + std::to_string(config_.stop_timeout_us / 1000) +
                               " ms (it shows " + state_text() + ")");
            };
            if (halted) {
              const auto v = actual(object_index::velocity_actual_value);
              const bool still = (sw & status_bit::target_reached) != 0 || (v && std::abs(*v) <= 1);
              return still || observed_ != state::operation_enabled ? step_state::done : waited();
            }
            if (observed_ == state::quick_stop_active) {
              // Ended as 0x605A says (S5): 0 coasting into QUICK STOP ACTIVE, 5..8 at standstill there
              // (status bit 10); 1..4 leave it for SWITCH ON DISABLED (T12). Standstill there ends the
              // wait whatever the session believes of the code: a belief can be wrong.
              const int code = option_code(option::quick_stop);
              const bool held = code == 0 || (sw & status_bit::target_reached) != 0;
              return held ? step_state::done : waited();
            }
            const bool torque_off = observed_ != state::operation_enabled && observed_ != state::fault_reaction_active;
            return torque_off ? step_state::done : waited();
          }};
}

session::step session::failure_stop(std::shared_ptr<std::string> said) {
  struct status {
    int stage = 0;  // 0 halt, 1 quick stop, 2 Disable voltage
    moment since;
    std::uint64_t began = 0;
  };
  auto s = std::make_shared<status>();
  const auto enter = [this, s](int stage) {
    s->stage = stage;
    s->since = now_moment();
    if (stage == 0) {
      halt_by_stop_ = true;
      set_mode_bits(0);
      if (control_ != control::target) set_target(state::operation_enabled);
    } else {
      set_command(stage == 1 ? command::quick_stop : command::disable_voltage);
    }
  };
  const bool has_halt = profile_->spec(option::halt).exists();
  return {[this, s, enter, has_halt] {
            s->began = now_us_;
            need(object_index::velocity_actual_value);
            enter(has_halt ? 0 : 1);
          },
          [this, s, said, enter] {
            if (!settled()) return step_state::running;
            const std::uint16_t sw = link_->status_word();
            const auto v = fresh(object_index::velocity_actual_value, s->since);
            const bool still = v ? std::abs(*v) <= 1 : (sw & status_bit::target_reached) != 0;
            const bool torque_off = observed_ != state::operation_enabled && observed_ != state::quick_stop_active &&
                                    observed_ != state::fault_reaction_active;
            const std::string ms = std::to_string((now_us_ - s->began) / 1000) + " ms";
            static const char* how[] = {"halt (control bit 8, as 0x605D = ", "quick stop (as 0x605A = ", "Disable voltage ("};
            const auto what = [&](int stage) {
              return std::string(how[stage]) +
                     (stage == 0 ? std::to_string(option_code(option::halt)) + ")"
                                 : stage == 1 ? std::to_string(option_code(option::quick_stop)) + ")" : "torque off)");
            };
            if (still || torque_off) {
              *said += (said->empty() ? "stopped by " : "; then ") + what(s->stage) + ": " +
                       (torque_off ? std::string("the drive shows ") + state_name(observed_) : std::string("at standstill")) +
                       " after " + ms;
              if (s->stage == 0) *said += "; halt stays set until the next motion command";
              return step_state::done;
            }
            if (now_us_ - s->since.us < config_.stop_timeout_us) return step_state::running;
            *said += (said->empty() ? "" : "; then ") + what(s->stage) + " did not stop the shaft within " +
                     std::to_string(config_.stop_timeout_us / 1000) + " ms";
            if (s->stage == 2) return fail_step(*said + " (the drive shows " + state_text() + ")");
            enter(s->stage + 1);
            return step_state::running;
          }};
}

}  // namespace cia402::axes
