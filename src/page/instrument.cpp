#include "instrument_impl.hpp"

namespace cia402::page {


instrument::instrument(const profile& p, const instrument_config& config)
    : impl_(std::make_unique<impl>(p, config)) {}

instrument::~instrument() { close(); }

void instrument::step() {
  std::lock_guard lock(impl_->mutex);
  impl_->step_locked();
}

std::uint64_t instrument::cycle() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->drive->cycle();
}

reply instrument::command(page_command c) {
  std::lock_guard lock(impl_->mutex);
  const auto change = detail::press_button(*impl_->table, c, impl_->control_word);
  if (const refused* no = std::get_if<refused>(&change)) return *no;
  return accepted{impl_->change_word(std::get<detail::word_change>(change))};
}

reply instrument::toggle_control_bit(int bit) {
  if (bit < 0 || bit > 15) return refused{400, "bit must be 0..15"};
  std::lock_guard lock(impl_->mutex);
  return accepted{impl_->change_word(detail::flip_bit(*impl_->table, impl_->control_word, bit))};
}

reply instrument::new_setpoint() {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  if (auto no = detail::new_setpoint_refusal(*m.table, m.drive->view().operation_mode())) return *no;
  constexpr std::uint16_t bit4 = 1u << 4;
  const std::uint16_t word = m.control_word;
  m.scripted.clear();
  // A rising edge: bit 4 low for a cycle first if it was up.
  if ((word & bit4) != 0) m.scripted.push_back(static_cast<std::uint16_t>(word & ~bit4));
  m.scripted.push_back(static_cast<std::uint16_t>(word | bit4));
  const std::uint64_t cycle_us = m.drive->constants().cycle_us;
  m.handshake_until = m.drive->cycle() + m.scripted.size() +
                      detail::new_setpoint_wait_us / (cycle_us ? cycle_us : 1);
  std::string options;
  if ((word & (1u << 5)) != 0) options += ", change set immediately";
  if ((word & (1u << 6)) != 0) options += ", relative";
  if ((word & (1u << 9)) != 0) options += ", change on set-point";
  return accepted{m.log.report_now(
      "NEW_SET-POINT", "done",
      "done: 0x607A = " + std::to_string(m.drive->view().state_of_axis().objects.target_position) + options +
          "; bit 4 up until the drive acknowledges (status bit 12), then down")};
}

reply instrument::select_profile(std::string_view name) {
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  const profile* chosen = nullptr;
  std::string names;
  for (const profile* p : m.config.selectable) {
    if (chosen == nullptr && name == p->name) chosen = p;  // the instrument's own profile is first
    names += (names.empty() ? "" : ", ") + std::string(p->name);
  }
  if (chosen == nullptr) {
    return refused{400, "no profile '" + std::string(name) + "' here (" + names + ")"};
  }
  if (m.log.pending()) m.log.finish_pending("the profile was changed");
  m.end_jog("the profile was changed");
  m.end_walk("refused", "refused: the profile was changed");
  m.end_stop("the profile was changed");
  m.drive = std::make_unique<sim::virtual_drive>(*chosen, m.config.plant);
  m.table = chosen;
  m.control_word = 0;
  m.scripted.clear();
  m.handshake_until.reset();
  m.last_transition.reset();
  m.recording.clear();
  return accepted{m.log.report_now("PROFILE " + std::string(chosen->name), "done",
                                   std::string("done: ") + chosen->title + ", from power-up")};
}

reply instrument::write_object(std::uint16_t index, std::int64_t value) {
  if (index == sim::object::control_word) {
    return refused{400, "the control word is set by commands and bit toggles, not written here"};
  }
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  const std::string action = "WRITE " + hex(index, 4) + " = " + std::to_string(value);
  const sdo_abort r = m.drive->write(index, 0, value);
  if (r != sdo_abort::none) {
    const std::string text = "refused: " + abort_text(r);
    m.log.report_now(action, "refused", text);
    return refused{422, action + ": " + text, r};
  }
  return accepted{m.log.report_now(action, "done", "done")};
}

reply instrument::change_plant(const plant_change& change) {
  if (change.fault && *change.fault && (change.fault_code == 0 || change.fault_class > 4)) {
    return refused{400, "a fault needs a code 0x0001..0xFFFF and a class 0..4"};
  }
  std::lock_guard lock(impl_->mutex);
  impl& m = *impl_;
  sim::drive_view v = m.drive->view();
  std::string action;
  auto add = [&action](const std::string& what) { action += (action.empty() ? "" : ", ") + what; };
  if (change.target_velocity) {
    // The one part the drive can refuse: try it first, so a refusal leaves everything as it was.
    const sdo_abort r = v.write(sim::object::target_velocity, 0, *change.target_velocity);
    if (r != sdo_abort::none) {
      const std::string what = "WRITE 0x60FF = " + std::to_string(*change.target_velocity);
      m.log.report_now(what, "refused", "refused: " + abort_text(r));
      return refused{422, what + ": " + abort_text(r), r};
    }
    add("TARGET_VELOCITY=" + std::to_string(*change.target_velocity));
  }
  if (change.fault) {
    if (*change.fault) {
      v.inject_fault(change.fault_code, change.fault_class);
      add("FAULT " + hex(change.fault_code, 4) + " ON");
    } else {
      v.clear_faults();
      add("FAULT OFF");
    }
  }
  if (change.dc_link) {
    v.set_dc_link(*change.dc_link);
    add(std::string("DC_LINK ") + (*change.dc_link ? "ON" : "OFF"));
  }
  if (change.sto) {
    v.set_sto(*change.sto);
    add(std::string("STO ") + (*change.sto ? "ON" : "OFF"));
  }
  if (action.empty()) return refused{400, "nothing to change"};
  // A plant input is never refused; the page learns which transitions it caused.
  return accepted{m.track(action, false)};
}

void instrument::renew_lease() { impl_->sign.renew(); }

std::string instrument::info_json(bool control, bool token_required) const {
  std::lock_guard lock(impl_->mutex);
  json j = detail::profile_info(*impl_->table);
  j["backend"] = "virtual";
  json profiles = json::array();
  for (const profile* p : impl_->config.selectable) {
    profiles.push_back({{"name", p->name}, {"title", p->title}});
  }
  j["profiles"] = std::move(profiles);
  j["control"] = control;
  j["token_required"] = token_required;
  j["cycle_us"] = impl_->drive->constants().cycle_us;
  j["lease_ms"] = impl_->sign.lease_us() / 1000;
  // Snapshots come at most this often (the plot holds a value across a gap between them).
  j["publish_ms"] = impl_->config.publish_every * impl_->drive->constants().cycle_us / 1000.0;
  // The virtual drive's plant takes every input the page offers.
  j["capabilities"] = {
      {"fault", true}, {"dc_link", true}, {"sto", true}, {"reasons", json::object()}};
  return j.dump();
}

std::string instrument::snapshot_json() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->board.present_json(impl_->snapshot(true));
}

std::string instrument::recording_json(std::uint64_t rows_seen,
                                       std::uint64_t transitions_seen) const {
  std::lock_guard lock(impl_->mutex);
  return impl_->recording.since_json(rows_seen, transitions_seen).dump();
}

std::string instrument::recording_file(recording_format format) const {
  std::lock_guard lock(impl_->mutex);
  sim::trace_info info;
  info.title = "instrument page recording";
  info.profile_name = impl_->table->name;
  info.cycle_us = impl_->drive->constants().cycle_us;
  return impl_->recording.file(format, info);
}

std::optional<published> instrument::wait_for_update(std::uint64_t seen,
                                                     std::chrono::milliseconds timeout) {
  return impl_->board.wait_for_update(seen, timeout);
}

published instrument::latest() const { return impl_->board.latest(); }

void instrument::close() { impl_->board.close(); }

bool instrument::closed() const { return impl_->board.closed(); }

}  // namespace cia402::page
