#include "cia402/ethercat/axis/ecat_link.hpp"

#include <algorithm>

#include "cia402/hex_text.hpp"
#include "cia402/manufacturer_objects.hpp"
#include "cia402/master.hpp"
#include "cia402/objects.hpp"

namespace cia402::ethercat {
namespace {

// Frames lost (or short of their working counter) in a row before the line counts as gone: with a
// 1 ms cycle, 25 ms, well inside a drive's 100 ms sync-manager watchdog.
constexpr int lost_cycles_limit = 25;

// How long close() gives an enabled drive to come down to SWITCH ON DISABLED before the line leaves
// OP all the same: a drive still turning is quick-stopped first (for at most the first limit), then
// Disable voltage.
constexpr std::uint64_t quick_stop_limit_us = 2'000'000;
constexpr std::uint64_t stop_limit_us = 3'000'000;

// The states in which leaving OP is a lost connection to a drive with something to stop (0x6007
// acts; SWITCHED ON carries torque in some profiles).
bool carries_torque(state s) {
  return s == state::switched_on || s == state::operation_enabled || s == state::quick_stop_active;
}

// The types of ETG.1000.6's CoE communication objects (table 59 ff.), by index and sub-index.
std::optional<axes::value_format> coe_object_format(std::uint16_t index, std::uint8_t sub) {
  using axes::value_format;
  const auto u = [](unsigned bytes) { return value_format::integer(bytes, false); };
  switch (index) {
    case 0x1000: return sub == 0 ? std::optional(u(4)) : std::nullopt;  // device type
    case 0x1001: return sub == 0 ? std::optional(u(1)) : std::nullopt;  // error register
    case 0x1008:                                                         // device name,
    case 0x1009:                                                         // hardware and
    case 0x100A: return sub == 0 ? std::optional(value_format::text()) : std::nullopt;  // software version
    case 0x1017: return sub == 0 ? std::optional(u(2)) : std::nullopt;  // CiA 301's producer heartbeat time,
                                                                         // kept by CoE slaves of CANopen descent
    case 0x1018: return sub == 0 ? u(1) : sub <= 4 ? u(4) : std::optional<value_format>();  // identity
    case 0x1C00: return u(1);  // sync manager communication types
    default: break;
  }
  // PDO mapping (entries of 32 bits: index, sub-index, length) and PDO assignment (16-bit indices).
  if ((index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF)) return sub == 0 ? u(1) : u(4);
  if (index >= 0x1C10 && index <= 0x1C2F) return sub == 0 ? u(1) : u(2);
  // SM output / input parameter (ETG.1020 §5.3): the sync mode, cycle and shift times, the counters.
  if (index == 0x1C32 || index == 0x1C33) {
    switch (sub) {
      case 0x00: return u(1);
      case 0x01: case 0x04: case 0x08: case 0x0B: case 0x0C: return u(2);  // modes, get cycle time, counters
      case 0x02: case 0x03: case 0x05: case 0x06: case 0x07: case 0x09: case 0x0A: return u(4);  // times, ns
      case 0x20: return u(1);  // sync error (BOOLEAN)
      default: return std::nullopt;
    }
  }
  return std::nullopt;
}

}  // namespace

// --- the line -----------------------------------------------------------------------------------

ecat_line::ecat_line(master_link& link, const profile& p, std::uint32_t cycle_us, std::string name)
    : link_(&link), profile_(&p), master_(link, p, cycle_us), name_(std::move(name)) {}

bool ecat_line::scan() { return master_.scan(); }

bool ecat_line::bring_to_operational() {
  up_ = master_.bring_to_operational();
  next_cycle_us_ = link_->now_us();
  return up_;
}

void ecat_line::attach(ecat_link* l) { drives_.push_back(l); }

std::uint32_t ecat_line::service() {
  if (!up_ || left_op_) return 0xFFFFFFFFu;
  const std::uint64_t now = link_->now_us();
  if (!failure_.empty()) {
    if (retry_us_ == 0) return 0xFFFFFFFFu;
    if (now < retry_at_us_) return static_cast<std::uint32_t>(retry_at_us_ - now);
    retry_at_us_ = now + retry_us_;
    if (!master_.scan() || !master_.bring_to_operational()) return retry_us_;
    failure_.clear();
    lost_in_a_row_ = 0;
    next_cycle_us_ = link_->now_us();
    for (ecat_link* d : drives_) d->restart();
    return 0;
  }
  if (now < next_cycle_us_) return static_cast<std::uint32_t>(next_cycle_us_ - now);
  for (ecat_link* d : drives_) {
    if (!d->closed_ && d->before_cycle) d->before_cycle();
  }
  const bool ok = master_.cycle();
  lost_in_a_row_ = ok ? 0 : lost_in_a_row_ + 1;
  if (lost_in_a_row_ > lost_cycles_limit) {
    failure_ = "the line does not answer (" + master_.error() + ")";
    retry_at_us_ = now + retry_us_;
  }
  for (ecat_link* d : drives_) d->after_cycle(ok);
  // Late: go on from now rather than rush to catch up.
  next_cycle_us_ = std::max(next_cycle_us_ + master_.cycle_us(), now);
  const std::uint64_t after = link_->now_us();
  return next_cycle_us_ > after ? static_cast<std::uint32_t>(next_cycle_us_ - after) : 0;
}

void ecat_line::detach_closed() {
  if (left_op_ || !std::all_of(drives_.begin(), drives_.end(), [](const ecat_link* d) { return d->closed_; })) return;
  left_op_ = true;
  // What each drive showed last, before the line goes: a drive reacts to its master going as its
  // 0x6007 says only when it is enabled (CiA 402-2 §6.2.1: it has something to stop then).
  std::vector<std::string> left_in;
  for (const ecat_link* d : drives_) {
    state s = state::start;
    // (status_known() is false by now: the link is closed.)
    const bool known = d->status_count_ > 0 && decode_status(*profile_, d->status_word(), s);
    const bool enabled = s == state::operation_enabled || s == state::quick_stop_active;
    left_in.push_back(!known ? " left in PRE-OP with the drive's state unknown: 0x6007 acts if it was enabled"
                      : enabled ? std::string(" left in PRE-OP with the drive in ") + state_name(s) +
                                      ": it applies 0x6007 (abort connection) to its master going"
                                : std::string(" left in PRE-OP with the drive in ") + state_name(s) +
                                      ", not enabled: nothing for 0x6007 to stop");
  }
  // Every drive's session is done: out of OP at once, not by the watchdog 100 ms later.
  const bool ok = up_ && failure_.empty() && master_.leave_operational();
  for (std::size_t i = 0; i < drives_.size(); ++i) {
    ecat_link* d = drives_[i];
    if (ok) {
      d->report_.left.push_back(name_ + left_in[i]);
    } else {
      d->report_.left.push_back(name_ + " left as it was: " + (failure_.empty() ? master_.error() : failure_));
    }
    d->report_.done = true;
  }
}

// --- a drive ------------------------------------------------------------------------------------

ecat_link::ecat_link(ecat_line& line, std::size_t position) : line_(&line), position_(position) {
  line.attach(this);
}

ecat_link::~ecat_link() {
  auto& list = line_->drives_;
  list.erase(std::remove(list.begin(), list.end(), this), list.end());
}

std::string ecat_link::short_name() const { return "slave " + std::to_string(position_); }

std::string ecat_link::what() const {
  const auto& slaves = line_->master().slaves();
  const std::string station = position_ < slaves.size() ? " (station " + std::string(to_hex(slaves[position_].station, 4).c_str()) + ")" : "";
  return short_name() + station + " on " + line_->name();
}

axes::link_phase ecat_link::phase() const {
  if (!failure_.empty() || line_->failed() || closed_) return axes::link_phase::failed;
  if (!line_->operational() || position_ >= line_->master().slaves().size()) return axes::link_phase::connecting;
  return axes::link_phase::running;
}

std::string ecat_link::phase_text() const {
  if (!failure_.empty()) return failure_;
  if (line_->failed()) return line_->failure();
  if (closed_) return "closed";
  if (!line_->operational()) return line_->name() + " is not in OP yet";
  return {};
}

std::uint32_t ecat_link::poll(std::uint32_t) {
  if (phase() == axes::link_phase::connecting) return 1000;
  if (!started_ && phase() == axes::link_phase::running) {
    started_ = true;
    for (const auto& o : slave().inputs) {
      if (o.index != 0) inputs_.push_back({o.index, o.sub, o.bits});
    }
    for (const auto& o : slave().outputs) {
      if (o.index != 0) outputs_.push_back({o.index, o.sub, o.bits});
    }
    if (on_event) {
      on_event(axes::link_event::running, {});
      on_event(axes::link_event::cyclic, {});
    }
  }
  std::uint32_t next = line_->service();
  if (line_->failed() && failure_.empty()) fail(line_->failure());
  if (stopping_ && !failure_.empty()) {
    report_.left.push_back(short_name() + " not brought down to SWITCH ON DISABLED: " + failure_);
    finish_close();
  }
  if (phase() == axes::link_phase::running && !transfers_.empty()) {
    run_one_transfer();
    next = 0;  // the process data is due again (and the next transfer may run)
  }
  return next;
}

void ecat_link::after_cycle(bool ok) {
  if (closed_ || !failure_.empty()) return;
  const ecat_slave& s = slave();
  if (ok) ++status_count_;
  if (ok && (s.al_state & 0x0F) != static_cast<std::uint8_t>(line_state::operational)) {
    std::string why = what() + " left OP: AL state " + line_state_name(s.al_state);
    if (s.al_code != 0) why += ", AL status code " + std::string(to_hex(s.al_code, 4).c_str()) + " (" + al_status_code_text(s.al_code) + ")";
    return fail(why);
  }
  for (; emergencies_seen_ < s.emergencies.size(); ++emergencies_seen_) {
    if (on_emergency) on_emergency(s.emergencies[emergencies_seen_], 0, {});
  }
  if (stopping_) step_stop();
}

void ecat_link::restart() {
  if (closed_) return;
  failure_.clear();
  started_ = false;  // the next poll announces the link running again, with the new mapping
  inputs_.clear();
  outputs_.clear();
  emergencies_seen_ = 0;
}

void ecat_link::fail(std::string why) {
  if (!failure_.empty()) return;
  failure_ = std::move(why);
  axes::cancel_transfers(transfers_, failure_);
  if (on_event) on_event(axes::link_event::failed, failure_);
}

std::uint16_t ecat_link::status_word() const { return status_count_ > 0 ? slave().last_status : 0; }

std::optional<std::uint16_t> ecat_link::error_code() const {
  if (status_count_ == 0 || !slave().error_code) return std::nullopt;
  return slave().last_error_code;
}

void ecat_link::set_control_word(std::uint16_t word) {
  // Once close() is bringing the drive down, the control word is the link's.
  if (phase() == axes::link_phase::running && !stopping_) line_->master().send_control_word(position_, word);
}

std::optional<std::int64_t> ecat_link::cyclic_input(std::uint16_t index, std::uint8_t sub) const {
  if (status_count_ == 0) return std::nullopt;
  return line_->master().input(position_, index, sub);
}

bool ecat_link::set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) {
  if (phase() != axes::link_phase::running || stopping_) return false;
  return line_->master().set_output(position_, index, value, sub);
}

// --- transfers ----------------------------------------------------------------------------------

bool ecat_link::queue_transfer(transfer t) {
  if (t.download && t.bytes.empty()) return false;  // a CoE SDO download carries at least one byte
  transfers_.push_back(std::move(t));
  return true;
}

void ecat_link::run_one_transfer() {
  transfer t = std::move(transfers_.front());
  transfers_.pop_front();
  // The master keeps the process data flowing while it waits for the mailbox.
  const ecat_sdo_result r = t.download ? line_->master().sdo_write_bytes(position_, t.index, t.sub, t.bytes)
                                       : line_->master().sdo_read(position_, t.index, t.sub);
  axes::transfer_result out;
  out.ok = r.ok;
  if (r.aborted) out.abort = r.abort;
  if (!r.ok && !r.aborted) out.error = r.error;
  if (r.ok && !t.download) out.data = r.data;
  if (t.done) t.done(out);
}

std::optional<axes::value_format> ecat_link::describe(std::uint16_t index, std::uint8_t sub) const {
  if (const auto f = coe_object_format(index, sub)) return f;
  if (position_ < line_->master().slaves().size() && slave().sii.device_name == virtual_drive_device_name && sub == 0) {
    if (index == device_label_index) return axes::value_format::text();
    if (index == fault_injection_index) return axes::value_format::integer(2, false);
  }
  return std::nullopt;
}

void ecat_link::close() {
  if (closed_ || stopping_) return;
  axes::cancel_transfers(transfers_, "closed");
  state s = state::start;
  if (failure_.empty() && phase() == axes::link_phase::running && status_known() &&
      decode_status(*line_->profile_, status_word(), s) && carries_torque(s)) {
    // A drive left enabled would take the line leaving OP for a lost connection and do what its
    // 0x6007 says (1 by default: a fault). Brought down to SWITCH ON DISABLED first, it has
    // nothing for 0x6007 to stop, and the next run finds it without a fault.
    stopping_ = true;
    stop_from_ = s;
    stop_started_us_ = line_->link_->now_us();
    step_stop();
    return;
  }
  finish_close();
}

void ecat_link::step_stop() {
  const std::uint64_t took = line_->link_->now_us() - stop_started_us_;
  state s = state::start;
  const bool known = decode_status(*line_->profile_, status_word(), s);
  if (known && !carries_torque(s)) {
    report_.restored.push_back(short_name() + " brought from " + state_name(stop_from_) + " to " + state_name(s) +
                               " before the line left OP (no lost connection for 0x6007)");
    return finish_close();
  }
  if (took >= stop_limit_us) {
    report_.left.push_back(short_name() + " still in " + (known ? state_name(s) : "an unknown state") + " " +
                           std::to_string(stop_limit_us / 1000) +
                           " ms after the close began to disable it: 0x6007 acts as the line leaves OP");
    return finish_close();
  }
  // Still turning: the quick stop its 0x605A describes first, rather than let the shaft coast.
  const std::optional<std::int64_t> v = cyclic_input(object_index::velocity_actual_value, 0);
  const bool turning = v && *v != 0 && took < quick_stop_limit_us &&
                       (s == state::operation_enabled || s == state::quick_stop_active);
  std::uint16_t word = turning ? 0x0002 : 0x0000;
  (void)encode_command(*line_->profile_, turning ? cia402::command::quick_stop : cia402::command::disable_voltage, 0, word);
  line_->master().send_control_word(position_, word);
}

void ecat_link::finish_close() {
  stopping_ = false;
  closed_ = true;
  line_->detach_closed();
  if (!line_->left_op_) report_.done = true;  // the line leaves OP with its last drive
}

}  // namespace cia402::ethercat
