// One-click enable and stop, and the jog with its dead-man, on the virtual drive (backend.hpp;
// the per-cycle part is in instrument_impl.hpp, the shared rules in commissioning.hpp).
#include "instrument_impl.hpp"

namespace cia402::page {

reply instrument::enable() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  const state s = m.shown();
  if (s == state::operation_enabled) {
    return accepted{m.log.report_now("ENABLE", "nothing to do", "nothing to do: already OPERATION_ENABLED")};
  }
  std::string why = m.blocker(s);
  if (why.empty()) {
    why = detail::next_enable_step(*m.table, m.drive->view().state_of_axis().core, s, m.control_word).refusal;
  }
  if (!why.empty()) {
    const std::string text = "refused in " + std::string(state_name(s)) + ": " + why;
    m.log.report_now("ENABLE", "refused", text);
    return refused{409, text};
  }
  m.end_walk("refused", "refused: Enable pressed again");
  m.end_stop("Enable pressed");
  m.handshake_until.reset();
  m.scripted.clear();
  const std::uint64_t id = m.log.report_now("ENABLE", "pending", "walking to OPERATION_ENABLED");
  m.walk = detail::enable_walk{id, std::nullopt, 0, {}};
  return accepted{id};
}

reply instrument::stop() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  m.end_jog("Stop pressed");
  m.end_walk("refused", "refused: Stop pressed");
  m.end_stop("Stop pressed again");
  std::uint16_t word = 0;
  const bool quick = m.drive->view().current() == state::operation_enabled &&
                     encode_command(*m.table, command::quick_stop, m.control_word, word);
  if (!quick && !encode_command(*m.table, command::disable_voltage, m.control_word, word)) {
    return refused{409, std::string("profile ") + m.table->name + " has no Disable voltage"};
  }
  m.handshake_until.reset();
  m.scripted.clear();
  m.apply_word(word);
  const std::uint64_t id = m.log.report_now(
      "STOP", "pending", quick ? "QUICK_STOP, then DISABLE_VOLTAGE once stopped" : "DISABLE_VOLTAGE");
  m.stopping = impl::stop_run{id, quick, m.drive->cycle() + m.config.settle_limit, {}};
  return accepted{id};
}

reply instrument::jog(std::int64_t velocity_rpm, std::uint64_t time_to_live_us) {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (velocity_rpm == 0) {
    if (!m.jogging) return accepted{m.log.report_now("JOG RELEASE", "nothing to do", "nothing to do: no jog runs")};
    const std::uint64_t id = m.jogging->id;
    m.end_jog("released");
    return accepted{id};
  }
  const state now = m.drive->view().current();
  if (now != state::operation_enabled) {
    return refused{409, "jog refused: the drive is in " + std::string(state_name(now)) +
                            ", not OPERATION_ENABLED (press Enable first)"};
  }
  if (m.jogging && m.jogging->velocity_rpm == velocity_rpm && m.jogging->time_to_live_us == time_to_live_us) {
    m.jogging->renew(m.drive->time_us());  // the keep-alive
    return accepted{m.jogging->id};
  }
  // Profile velocity first (a drive without it refuses, and nothing else changes), then 0x60FF.
  const std::string action = "JOG " + std::to_string(velocity_rpm) + " rpm";
  sdo_abort r = sdo_abort::none;
  if (m.drive->view().operation_mode() != sim::profile_velocity_mode) {
    r = m.drive->write(object_index::modes_of_operation, 0, sim::profile_velocity_mode);
  }
  if (r == sdo_abort::none) r = m.drive->write(sim::object::target_velocity, 0, velocity_rpm);
  if (r != sdo_abort::none) {
    m.end_jog("the new jog was refused");
    m.log.report_now(action, "refused", "refused: " + abort_text(r));
    return refused{422, action + ": " + abort_text(r), r};
  }
  if (m.jogging) {
    m.jogging->velocity_rpm = velocity_rpm;
    m.jogging->time_to_live_us = time_to_live_us;
    m.jogging->renew(m.drive->time_us());
    return accepted{m.jogging->id};
  }
  detail::jog_run j;
  j.action = action;
  j.velocity_rpm = velocity_rpm;
  j.time_to_live_us = time_to_live_us;
  j.started_us = m.drive->time_us();
  j.renew(j.started_us);
  j.id = m.log.report_now(action, "pending",
                          "running in profile velocity while renewed within " +
                              std::to_string(time_to_live_us / 1000) + " ms");
  m.jogging = j;
  return accepted{j.id};
}

}  // namespace cia402::page
