// The requests: state targets, quick stop, fault reset, halt and stop, the mode switch, and the
// motion commands with their handshakes (CiA 402-2; docs/modes.md).
#include <algorithm>
#include <cstdlib>

#include "cia402/words.hpp"
#include "session_internal.hpp"

namespace cia402::axes {
namespace {

bool holdable(state s) noexcept {
  return s == state::switch_on_disabled || s == state::ready_to_switch_on || s == state::switched_on ||
         s == state::operation_enabled;
}

std::int64_t window_of(std::int64_t target) noexcept { return std::max<std::int64_t>(1, std::abs(target) / 100); }

}  // namespace

std::function<void()> session::answer_with_state(std::uint64_t id, completion done) {
  return [this, id, done = std::move(done)] {
    result r;
    r.id = id;
    fill_result(r);
    if (done) done(r);
  };
}

std::uint64_t session::refuse_now(std::string error, completion done, bool bad_input) {
  // Said at once, from the next poll() as every completion; the running operation goes on.
  const std::uint64_t id = next_id_++;
  deferred_.push_back([this, id, error = std::move(error), done = std::move(done), bad_input] {
    result r;
    r.id = id;
    r.end = outcome::failed;
    r.error = error;
    r.bad_input = bad_input;
    fill_result(r);
    if (done) done(r);
  });
  return id;
}

session::step session::progress_step(progress_kind kind) {
  return call_step([this, kind] { progress(kind); });
}

session::step session::read_position_step() {
  return read_step(object_index::position_actual_value, 0, [this](std::int64_t v) { op_->res.position = v; }, false);
}

// The way into every motion command: the link and start-up, what would stop it at once, the mode
// (switched by the command itself), then OPERATION ENABLED by the planner.
std::vector<session::step> session::motion_start(std::int8_t m, std::vector<step> limits) {
  std::vector<step> steps;
  steps.push_back(need_prepared());
  steps.push_back(need_cyclic());
  steps.push_back(check(true));
  // S20: every limit is read and judged before the first word that could move the drive.
  steps.push_back(mode_supported(m));
  for (step& l : limits) steps.push_back(std::move(l));
  steps.push_back(call_step([this] {
    op_->commanded = true;  // from here on a failure stops the drive (S20)
    halt_by_stop_ = false;
    set_mode_bits(0);
  }));
  steps.push_back(mode_step(m));
  steps.push_back(target_step(state::operation_enabled));
  return steps;
}

// --- the state machine --------------------------------------------------------------------------

std::uint64_t session::read_state(completion done) {
  const std::uint64_t id = next_id_++;
  if (status_known()) {
    deferred_.push_back(answer_with_state(id, std::move(done)));
    return id;
  }
  // No cyclic status yet: over SDO, without setting anything up.
  queue_upload(object_index::status_word, 0, [this, id, done](const transfer_result& sw) {
    if (!sw.ok || sw.data.size() != 2) {
      result r;
      r.id = id;
      r.end = outcome::failed;
      r.error = link_->short_name() + (sw.abort != sdo_abort::none ? " refused" : " did not answer") +
                " reading 0x6041: " + transfer_failure(sw);
      if (done) done(r);
      return;
    }
    const auto word = static_cast<std::uint16_t>(sw.data[0] | (sw.data[1] << 8));
    queue_upload(object_index::error_code, 0, [this, id, word, done](const transfer_result& ec) {
      result r;
      r.id = id;
      fill_result(r);
      r.status_word = word;
      state s = state::start;
      r.shown = decode_status(*profile_, word, s) ? std::optional(s) : std::nullopt;
      if (ec.ok && ec.data.size() == 2) {
        r.error_code = static_cast<std::uint16_t>(ec.data[0] | (ec.data[1] << 8));
        polled& p = polled_[object_index::error_code];
        p.value = r.error_code;
        p.read_us = now_us_;
      }
      if (done) done(r);
    }, true);
  });
  return id;
}

std::uint64_t session::go_to(state target, completion done) {
  std::vector<step> steps{need_prepared(), need_cyclic(), check(target == state::operation_enabled),
                          target_step(target)};
  return begin(std::string("to ") + state_name(target), std::move(steps), std::move(done), false);
}

std::uint64_t session::quick_stop(completion done) {
  std::vector<step> steps{need_prepared(), need_cyclic(), check(false), command_step(command::quick_stop),
                          wait_settled(), wait_stopped(false)};
  return begin("quick stop", std::move(steps), std::move(done), false);
}

std::uint64_t session::reset(completion done) {
  auto in_fault = std::make_shared<bool>(false);
  std::vector<step> steps;
  steps.push_back(need_prepared());
  // Look before touching: a drive that is not in FAULT is left as it is (no set-up, no word).
  steps.push_back(step{[this, in_fault] {
                         if (status_known()) {
                           *in_fault = observed_ == state::fault || observed_ == state::fault_reaction_active;
                           return;
                         }
                         queue_upload(object_index::status_word, 0, [this, in_fault](const transfer_result& r) {
                           state s = state::start;
                           if (r.ok && r.data.size() == 2) {
                             const auto word = static_cast<std::uint16_t>(r.data[0] | (r.data[1] << 8));
                             (void)decode_status(*profile_, word, s);
                           }
                           *in_fault = s == state::fault || s == state::fault_reaction_active;
                           if (!*in_fault && op_) {
                             op_->res.status_word = r.ok && r.data.size() == 2 ? static_cast<std::uint16_t>(r.data[0] | (r.data[1] << 8)) : 0;
                             op_->res.shown = s;
                             op_->res.note = "not in FAULT, nothing to reset";
                             op_->at = op_->steps.size() - 1;  // past every step but the last, which ends it
                           }
                         }, true);
                       },
                       [this] { return transfer_busy_ || !jobs_.empty() ? step_state::running : step_state::done; }});
  steps.push_back(step{nullptr, [this, in_fault] {
                         if (!*in_fault && status_known()) {
                           op_->res.note = "not in FAULT, nothing to reset";
                           op_->at = op_->steps.size() - 1;
                         }
                         return step_state::done;
                       }});
  steps.push_back(need_cyclic());
  steps.push_back(wait_step([this] { return settled() && observed_ != state::fault_reaction_active; },
                            config_.transition_timeout_us,
                            [this] { return "the fault reaction did not end (" + state_text() + ")"; }));
  steps.push_back(call_step([this] {
    op_->commanded = true;
    control_ = control::words;
    words_.clear();
    std::uint16_t off = 0;
    (void)encode_command(*profile_, command::disable_voltage, 0, off);
    const fault_reset_words edge = fault_reset_edge(sent_.value_or(0), off);
    for (std::uint8_t i = 0; i < edge.count; ++i) {
      words_.emplace_back(edge.words[i], config_.reset_pulse_us);
    }
  }));
  steps.push_back(edge_sent());
  steps.push_back(wait_step([this] { return settled() && observed_ != state::fault; }, config_.reset_timeout_us, [this] {
    return "still in FAULT after the fault-reset edge: error code " + error_code_words(error_code()) +
           "; is the fault cause still present?";
  }));
  steps.push_back(target_step(state::switch_on_disabled));
  steps.push_back(call_step([] {}));  // the end, where a drive not in FAULT jumps to
  const std::uint64_t id = begin("reset", std::move(steps), std::move(done), false);
  op_->fault_ok = true;
  return id;
}

std::uint64_t session::halt(bool on, completion done) {
  if (!profile_->spec(option::halt).exists()) {
    return refuse_now(std::string("profile ") + profile_->name + " has no halt (0x605D): control bit 8 means something else there",
                      std::move(done), true);
  }
  const auto apply = [this, on] {
    halt_by_user_ = on;
    if (!on) halt_by_stop_ = false;
  };
  if (control_ != control::none && status_known()) {
    // Beside the running operation (a halted move resumes when the halt goes): done once the drive
    // has had the word.
    apply();
    word_changed_us_ = now_us_;
    word_changed_count_ = link_->status_count();
    const std::uint64_t id = next_id_++;
    after_settled_.push_back(answer_with_state(id, std::move(done)));
    return id;
  }
  std::vector<step> steps{need_prepared(), need_cyclic(), check(false), step{[this, apply] {
                            apply();
                            // Taking control holds the drive where it is, with the halt bit.
                            if ((control_ == control::none || control_ == control::words) && holdable(observed_)) set_target(observed_);
                          }, [this] {
                            if (control_ == control::none) return fail_step("the drive shows " + state_text() + ": no state to hold");
                            return step_state::done;
                          }}, wait_settled()};
  return begin(on ? "halt on" : "halt off", std::move(steps), std::move(done), false);
}

std::uint64_t session::stop(completion done) {
  const bool has_halt = profile_->spec(option::halt).exists();
  std::vector<step> steps{need_prepared(), need_cyclic(), check(false), step{[this, has_halt] {
                            if (!has_halt) return set_command(command::quick_stop);
                            halt_by_stop_ = true;
                            set_mode_bits(0);
                            if ((control_ == control::none || control_ == control::words) && holdable(observed_)) set_target(observed_);
                          }, nullptr}, wait_settled(), wait_stopped(has_halt)};
  const std::uint64_t id = begin("stop", std::move(steps), std::move(done), false);
  op_->res.note = has_halt ? "halted: control bit 8 stays set until the next motion command or halt off" : "quick stop";
  return id;
}

std::uint64_t session::set_mode(std::int8_t m, completion done) {
  std::vector<step> steps{need_prepared(), mode_step(m, true)};
  const std::uint64_t id = begin("mode " + mode_words(m), std::move(steps), std::move(done), false);
  op_->fault_ok = true;
  return id;
}

// --- motion -------------------------------------------------------------------------------------

std::uint64_t session::move(const move_request& r, completion done) {
  std::vector<step> limits = position_limits(r.target, r.relative);
  if (r.velocity) {
    for (step& l : velocity_limits(*r.velocity, "profile velocity")) limits.push_back(std::move(l));
  }
  std::vector<step> steps = motion_start(mode::profile_position, std::move(limits));
  if (r.velocity) steps.push_back(write_step(object_index::profile_velocity, 0, *r.velocity));
  // After OPERATION ENABLED: entering it clears the set-points on some profiles (002's T4).
  steps.push_back(write_step(object_index::target_position, 0, r.target));
  const std::uint16_t relative = r.relative ? control_bit::relative : 0;
  steps.push_back(call_step([this, r, relative] {
    set_mode_bits(static_cast<std::uint16_t>(control_bit::new_set_point | control_bit::change_set_immediately | relative));
    op_->res.position = r.target;
    progress(progress_kind::set_point);
  }));
  steps.push_back(wait_step([this] { return settled() && (link_->status_word() & status_bit::set_point_acknowledge) != 0; },
                            config_.acknowledge_timeout_us, [this] {
                              return "no set-point acknowledge (status bit 12) within " +
                                     std::to_string(config_.acknowledge_timeout_us / 1000) +
                                     " ms of control bit 4 (the drive shows " + state_text() + ")";
                            }));
  steps.push_back(bits_step(relative));  // bit 4 down: the handshake is done
  auto moved = std::make_shared<bool>(r.relative && r.target == 0);
  steps.push_back(call_step([this] { need(object_index::position_actual_value); }));
  steps.push_back(wait_step([this, moved, r] {
    const std::uint16_t sw = link_->status_word();
    if (!settled()) return false;
    if ((sw & status_bit::target_reached) == 0) *moved = true;
    const auto at = actual(object_index::position_actual_value);
    const bool there = *moved || (!r.relative && at && *at == r.target);
    return there && (sw & status_bit::target_reached) != 0 && (sw & status_bit::set_point_acknowledge) == 0;
  }, 0, [] { return std::string(); }));
  steps.push_back(bits_step(0));
  steps.push_back(read_position_step());
  return begin("move", std::move(steps), std::move(done), true);
}

// Profile velocity and torque alike: the mode, the set-point written after OPERATION ENABLED, then
// the actual value within 1 % (at least 1) of it, from a status word after the write.
std::uint64_t session::reach(const char* name, std::int8_t m, std::uint16_t set_point, std::uint16_t actual_index,
                             std::int64_t target, progress_kind kind, std::optional<std::int64_t> result::*field,
                             std::vector<step> limits, completion done) {
  std::vector<step> steps = motion_start(m, std::move(limits));
  steps.push_back(write_step(set_point, 0, target));
  auto since = std::make_shared<moment>();
  steps.push_back(call_step([this, since, actual_index, target, kind, field] {
    *since = now_moment();
    need(actual_index);
    op_->res.*field = target;
    progress(kind);
  }));
  steps.push_back(wait_step([this, since, actual_index, target, field] {
    if (settled() && (link_->status_word() & status_bit::internal_limit_active) != 0) op_->limited = true;
    const auto v = fresh(actual_index, *since);
    if (!v) return false;
    op_->res.*field = *v;
    return std::abs(*v - target) <= window_of(target);
  }, 0, [] { return std::string(); }));
  return begin(name, std::move(steps), std::move(done), true);
}

std::uint64_t session::velocity(std::int32_t rpm, completion done) {
  return reach("velocity", mode::profile_velocity, object_index::target_velocity, object_index::velocity_actual_value, rpm,
               progress_kind::target_velocity, &result::velocity, velocity_limits(rpm, "velocity"), std::move(done));
}

std::uint64_t session::torque(std::int16_t permille, completion done) {
  std::vector<step> limits;
  limits.push_back(torque_limit(permille));
  return reach("torque", mode::profile_torque, object_index::target_torque, object_index::torque_actual_value, permille,
               progress_kind::target_torque, &result::torque, std::move(limits), std::move(done));
}

std::uint64_t session::home(const home_request& r, completion done) {
  std::vector<step> steps{need_prepared(), need_cyclic(), check(true), mode_supported(mode::homing)};
  if (r.method) steps.push_back(homing_method_supported(*r.method));
  steps.push_back(call_step([this] {
    op_->commanded = true;
    halt_by_stop_ = false;
    set_mode_bits(0);
  }));
  if (r.method) steps.push_back(write_step(object_index::homing_method, 0, *r.method));
  if (r.offset) steps.push_back(write_step(object_index::home_offset, 0, *r.offset));
  steps.push_back(mode_step(mode::homing));
  steps.push_back(target_step(state::operation_enabled));
  steps.push_back(call_step([this] {
    set_mode_bits(control_bit::homing_operation_start);
    progress(progress_kind::homing_started);
  }));
  steps.push_back(step{nullptr, [this] {
                         const std::uint16_t sw = link_->status_word();
                         if (!settled()) return step_state::running;
                         if (sw & status_bit::homing_error) {
                           return fail_step("homing error (status bit 13, statusword " + word_hex(sw) + ")");
                         }
                         const std::uint16_t attained = status_bit::homing_attained | status_bit::target_reached;
                         return (sw & attained) == attained ? step_state::done : step_state::running;
                       }});
  steps.push_back(bits_step(0));
  steps.push_back(read_position_step());
  return begin("home", std::move(steps), std::move(done), true);
}

std::uint64_t session::jog(std::int32_t rpm, std::uint64_t hold_us, completion done) {
  std::vector<step> steps = motion_start(mode::profile_velocity, velocity_limits(rpm, "jog velocity"));
  steps.push_back(write_step(object_index::target_velocity, 0, rpm));
  steps.push_back(call_step([this, rpm, hold_us] {
    jog_until_us_ = now_us_ + hold_us;
    op_->jogging = true;
    op_->res.velocity = rpm;
    progress(progress_kind::jog_started);
  }));
  steps.push_back(wait_step([this] { return now_us_ >= jog_until_us_; }, 0, [] { return std::string(); }));
  // Released: to standstill on the profile's deceleration.
  steps.push_back(write_step(object_index::target_velocity, 0, 0));
  auto since = std::make_shared<moment>();
  steps.push_back(call_step([this, since] {
    jog_until_us_ = 0;
    op_->jogging = false;
    *since = now_moment();
    need(object_index::velocity_actual_value);
  }));
  steps.push_back(wait_step([this, since] {
    const auto v = fresh(object_index::velocity_actual_value, *since);
    if (v) op_->res.velocity = *v;
    return v && std::abs(*v) <= 1;
  }, 0, [] { return std::string(); }));
  return begin("jog", std::move(steps), std::move(done), true);
}

void session::renew_jog(std::uint64_t hold_us) {
  if (op_ && op_->jogging && jog_until_us_ != 0) jog_until_us_ = now_us_ + hold_us;
}

std::uint64_t session::watch(completion done) {
  std::vector<step> steps{need_cyclic(), call_step([this] {
                            if (!link_->cyclic_input(object_index::velocity_actual_value, 0)) {
                              keep_polled(object_index::velocity_actual_value, true);
                            }
                          })};
  const std::uint64_t id = begin("watch", std::move(steps), std::move(done), false);
  op_->fault_ok = true;
  return id;
}

std::uint64_t session::send_word(std::uint16_t word, bool reset_edge, completion done) {
  std::vector<step> steps{need_cyclic(), call_step([this, word, reset_edge] {
                            op_->commanded = true;
                            control_ = control::words;
                            words_.clear();
                            // A status word from before this is no answer to it, even if the word is the same.
                            word_changed_us_ = now_us_;
                            word_changed_count_ = link_->status_count();
                            if (!reset_edge) {
                              words_.emplace_back(word, 0);
                              return;
                            }
                            const fault_reset_words edge = fault_reset_edge(sent_.value_or(0), word);
                            for (std::uint8_t i = 0; i < edge.count; ++i) {
                              words_.emplace_back(edge.words[i], config_.reset_pulse_us);
                            }
                          }),
                          edge_sent()};
  const std::uint64_t id = begin(reset_edge ? "fault-reset edge" : "control word", std::move(steps), std::move(done), false);
  op_->fault_ok = true;
  return id;
}

}  // namespace cia402::axes
