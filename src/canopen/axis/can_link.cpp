#include "cia402/canopen/axis/can_link.hpp"

#include <algorithm>

#include "cia402/canopen/301/pdo.hpp"
#include "cia402/manufacturer_objects.hpp"
#include "cia402/objects.hpp"
#include "cia402/support/text.hpp"

namespace cia402::canopen {
namespace {

using support::hex;

// CiA 301's consumer heartbeat time, where a master's guard entry lives.
constexpr std::uint16_t consumer_heartbeat_time = 0x1016;

std::string object_text(std::uint16_t index, std::uint8_t sub) { return hex(index, 4) + ":" + std::to_string(sub); }

axes::transfer_result result_of(const sdo_result& r, const std::string& node, std::uint16_t index, std::uint8_t sub) {
  axes::transfer_result t;
  t.ok = r.ok();
  t.cancelled = r.cancelled;
  t.abort = r.cancelled ? sdo_abort::none : r.abort;
  t.data = r.data;
  if (r.abort == sdo_abort::sdo_protocol_timed_out) {
    t.abort = sdo_abort::none;
    t.error = node + " does not answer (SDO timeout on " + object_text(index, sub) + ")";
  }
  if (r.cancelled) t.error = node + ": the link was lost";
  return t;
}

std::optional<axes::value_format> find_format(const std::vector<dictionary::object_entry>& table, std::uint16_t index,
                                              std::uint8_t sub) {
  for (const dictionary::object_entry& o : table) {
    if (o.index != index) continue;
    for (const dictionary::sub_entry& e : o.subs) {
      if (e.sub == sub) return axes::format_of(e.type);
    }
  }
  return std::nullopt;
}

}  // namespace

can_link::can_link(channel& bus, can_link_config config)
    : bus_(&bus), config_(std::move(config)), sdo_(bus, config_.node_id, config_.sdo_timeout_us) {}

can_link::~can_link() = default;

std::string can_link::short_name() const { return "node " + std::to_string(config_.node_id); }

std::string can_link::what() const {
  return short_name() + (config_.bus_name.empty() ? std::string() : " on " + config_.bus_name);
}

axes::link_phase can_link::phase() const {
  if (!failure_.empty()) return axes::link_phase::failed;
  switch (stage_) {
    case stage::acyclic: return axes::link_phase::running;
    case stage::recording: return axes::link_phase::connecting;
    case stage::closed: return axes::link_phase::failed;
    case stage::setting_up:
    case stage::cyclic:
    case stage::restoring: break;
  }
  switch (master_->phase()) {
    case master_phase::configuring: return axes::link_phase::connecting;
    case master_phase::running: return axes::link_phase::running;
    case master_phase::failed: break;
  }
  return axes::link_phase::failed;
}

std::string can_link::phase_text() const {
  if (!failure_.empty()) return failure_;
  switch (stage_) {
    case stage::acyclic: return {};
    case stage::recording: return "reading what the set-up will change, to put it back at the end";
    case stage::closed: return "closed";
    default: break;
  }
  if (master_->phase() == master_phase::configuring) return "setting up " + short_name() + " (PDOs, heartbeat, NMT start)";
  return master_->phase() == master_phase::failed ? master_->failure_text() : std::string();
}

bool can_link::cyclic() const {
  return (stage_ == stage::cyclic || stage_ == stage::restoring) && master_->phase() == master_phase::running;
}

bool can_link::status_known() const { return cyclic() && master_->status_known() && !pdos_quiet_; }

std::uint16_t can_link::status_word() const { return master_ ? master_->status_word() : 0; }

std::optional<std::uint16_t> can_link::error_code() const {
  if (!cyclic()) return std::nullopt;
  return master_->error_code();
}

// --- the frames and the time --------------------------------------------------------------------

std::uint32_t can_link::poll(std::uint32_t elapsed_us) {
  if (stage_ == stage::closed) return no_deadline;
  now_us_ += elapsed_us;
  if (failure_.empty() && !master_) {
    if (const std::error_code ec = bus_->failure()) fail_own("the bus connection failed: " + ec.message());
  }
  frame f;
  for (int n = 0; n < 4096 && bus_->receive(f); ++n) on_frame(f);
  std::uint32_t next = no_deadline;
  const bool own = !master_ || stage_ == stage::recording;
  if (own) {
    run_own_transfers(elapsed_us);
    if (own_busy_) next = earliest(next, sdo_.process(0));
  } else {
    next = master_->process(elapsed_us);
    run_held();
  }
  if ((sdo_held_ || booting_) && !own_.empty() && !own_busy_) {
    const std::uint64_t held = now_us_ - held_since_us_;
    next = earliest(next, held < config_.sdo_timeout_us ? static_cast<std::uint32_t>(config_.sdo_timeout_us - held) : 0);
  }
  if (stage_ == stage::recording && !own_busy_ && own_.empty() && failure_.empty()) record_next();
  if (stage_ == stage::setting_up && master_->phase() == master_phase::running) {
    learn_cyclic();
    stage_ = stage::cyclic;
    if (word_) master_->send_control_word(*word_);
    if (on_event) on_event(axes::link_event::cyclic, {});
  }
  if (stage_ == stage::restoring) restore_next();
  std::vector<std::pair<transfer, axes::transfer_result>> said;
  said.swap(results_);
  for (auto& [t, r] : said) {
    if (t.done) t.done(r);
  }
  return next;
}

void can_link::on_frame(const frame& f) {
  if (master_ && stage_ != stage::recording) {
    master_->on_frame(f);
    return;
  }
  if (f.extended || f.rtr) return;
  if (f.id == cob::heartbeat + config_.node_id && f.len >= 1 &&
      f.data[0] == static_cast<std::uint8_t>(nmt_state::initialising)) {
    return on_boot_up();
  }
  if (sdo_.on_frame(f)) return;
  if (f.id == cob::emcy + config_.node_id && f.len >= 3 && on_emergency) {
    on_emergency(static_cast<std::uint16_t>(get_le(f.data.data(), 2)), f.data[2],
                 std::span<const std::uint8_t>(f.data.data() + 3, f.len - 3u));
  }
}

void can_link::run_own_transfers(std::uint32_t elapsed_us) {
  if (own_busy_) {
    (void)sdo_.process(elapsed_us);
    if (!sdo_.finished()) return;
    transfer t = std::move(own_.front());
    own_.pop_front();
    own_busy_ = false;
    axes::transfer_result r;
    r.ok = sdo_.state() == sdo_client::status::done;
    if (r.ok && !t.download) r.data = sdo_.data();
    const sdo_abort abort = r.ok ? sdo_abort::none : sdo_.abort_code();
    sdo_.clear();
    if (abort == sdo_abort::sdo_protocol_timed_out) {
      r.error = short_name() + " does not answer (SDO timeout on " + object_text(t.index, t.sub) + ")";
      results_.emplace_back(std::move(t), r);
      fail_own(results_.back().second.error);
      return;
    }
    r.abort = abort;
    if (r.ok && !t.download) note_name(t.index, t.sub, r.data);
    results_.emplace_back(std::move(t), r);
  }
  if (own_busy_ || own_.empty() || !failure_.empty()) return;
  if (booting_ && now_us_ - held_since_us_ >= config_.sdo_timeout_us) booting_ = false;  // no boot-up came: go on
  if (sdo_held_ && now_us_ - held_since_us_ >= config_.sdo_timeout_us) return end_held();
  if (sdo_held_ || booting_) return;
  const transfer& t = own_.front();
  talked_ = true;
  // A long value by block transfer: a download by its length, an upload by what the entry holds.
  if (t.download) {
    own_busy_ = t.bytes.size() >= sdo_client::block_from_bytes ? sdo_.start_block_download(t.index, t.sub, t.bytes)
                                                               : sdo_.start_download(t.index, t.sub, t.bytes);
  } else {
    own_busy_ = most_bytes(t.index, t.sub) >= sdo_client::block_from_bytes
                    ? sdo_.start_block_upload(t.index, t.sub, static_cast<std::uint8_t>(sdo_client::block_from_bytes - 1))
                    : sdo_.start_upload(t.index, t.sub);
  }
}

// --- NMT ----------------------------------------------------------------------------------------

std::error_code can_link::send_nmt(nmt_command c) {
  if (const std::error_code ec = bus_->send(nmt_frame(c, config_.node_id))) return ec;
  switch (c) {
    case nmt_command::stop:
      // CiA 301 §7.3.2.2.4: a STOPPED node serves no SDO and sends no PDO; an SDO under way is lost.
      hold_own_transfer();
      sdo_held_ = true;
      pdos_quiet_ = true;
      start_sent_ = false;
      break;
    case nmt_command::enter_pre_operational:
      // PRE-OPERATIONAL: SDO again, still no PDO.
      sdo_held_ = false;
      pdos_quiet_ = true;
      start_sent_ = false;
      break;
    case nmt_command::start:
      sdo_held_ = false;
      start_sent_ = true;
      break;
    case nmt_command::reset_node:
    case nmt_command::reset_communication:
      sdo_held_ = false;
      // In the cyclic stage the 402 master sets the node up again on its boot-up message.
      if (master_ && stage_ != stage::recording) break;
      hold_own_transfer();
      booting_ = true;
      break;
  }
  return {};
}

void can_link::hold_own_transfer() {
  held_since_us_ = now_us_;
  if (!own_busy_) return;
  // The node drops it: the transfer stays first in the queue and goes again when the node answers.
  sdo_.cancel();
  sdo_.clear();
  own_busy_ = false;
}

void can_link::end_held() {
  axes::transfer_result r;
  r.error = short_name() + " is STOPPED (NMT stop): it serves no SDO until NMT start or preop";
  for (transfer& t : own_) results_.emplace_back(std::move(t), r);
  own_.clear();
}

void can_link::run_held() {
  // The cyclic stage: transfers held while the node is STOPPED go to the master once it is not.
  if (own_.empty() || stage_ != stage::cyclic) return;
  if (sdo_held_) {
    if (now_us_ - held_since_us_ >= config_.sdo_timeout_us) end_held();
    return;
  }
  std::deque<transfer> go;
  go.swap(own_);
  if (master_->phase() != master_phase::running) {
    return axes::cancel_transfers(go, short_name() + ": " + master_->phase_text());
  }
  for (transfer& t : go) (void)forward(std::move(t));
}

void can_link::on_boot_up() {
  booting_ = false;
  sdo_held_ = false;
  pdos_quiet_ = false;
  hold_own_transfer();  // lost with the restart: it goes again
  if (!talked_ || stage_ != stage::acyclic || !failure_.empty()) return;
  // A node this link talked to started afresh (its defaults): what was read there is old.
  talked_ = false;
  const std::string why = short_name() + " restarted (boot-up message)";
  axes::cancel_transfers(own_, why);
  if (on_event) on_event(axes::link_event::restarted, why);
}

void can_link::fail_own(std::string text) {
  if (!failure_.empty()) return;
  failure_ = std::move(text);
  if (own_busy_) sdo_.cancel();
  own_busy_ = false;
  axes::transfer_result r;
  r.cancelled = true;
  r.error = failure_;
  for (transfer& t : own_) results_.emplace_back(std::move(t), r);
  own_.clear();
  if (on_event) on_event(axes::link_event::failed, failure_);
}

void can_link::note_name(std::uint16_t index, std::uint8_t sub, const std::vector<std::uint8_t>& data) {
  if (index != axes::device_name_index || sub != 0) return;
  device_name_.assign(data.begin(), data.end());
  while (!device_name_.empty() && device_name_.back() == '\0') device_name_.pop_back();
}

// --- transfers ----------------------------------------------------------------------------------

bool can_link::queue_transfer(transfer t) {
  if (t.download && t.bytes.empty()) return false;  // an SDO download carries at least one byte
  if (stage_ != stage::acyclic && !sdo_held_) return forward(std::move(t));
  if ((sdo_held_ || booting_) && own_.empty()) held_since_us_ = now_us_;
  own_.push_back(std::move(t));
  return true;
}

bool can_link::forward(transfer t) {
  const std::uint16_t index = t.index;
  const std::uint8_t sub = t.sub;
  auto done = [this, index, sub, done = std::move(t.done)](const sdo_result& r) {
    const axes::transfer_result x = result_of(r, short_name(), index, sub);
    if (x.ok) note_name(index, sub, x.data);
    if (done) done(x);
  };
  return t.download ? master_->download(index, sub, std::move(t.bytes), std::move(done))
                    : master_->upload(index, sub, std::move(done));
}

std::size_t can_link::most_bytes(std::uint16_t index, std::uint8_t sub) const {
  // The same sources as describe(), in the same order.
  const auto in = [&](const std::vector<dictionary::object_entry>& table) -> std::optional<std::size_t> {
    for (const dictionary::object_entry& o : table) {
      if (o.index != index) continue;
      for (const dictionary::sub_entry& e : o.subs) {
        if (e.sub == sub) return type_size(e.type) != 0 ? type_size(e.type) : std::max(e.capacity, e.default_text.size());
      }
    }
    return std::nullopt;
  };
  if (const auto n = in(config_.eds)) return *n;
  const bool ours = device_name_ == virtual_drive_device_name;
  if ((index >= 0x1000 && index <= 0x1FFF) || (ours && index >= 0x2000 && index <= 0x5FFF)) {
    return in(config_.known_objects).value_or(0);
  }
  return 0;  // not known: the ordinary upload
}

std::optional<axes::value_format> can_link::describe(std::uint16_t index, std::uint8_t sub) const {
  if (const auto f = find_format(config_.eds, index, sub)) return f;
  // CiA 301's communication objects are the same on every node; the manufacturer's are known only
  // on a node that says it is the project's virtual drive.
  const bool ours = device_name_ == virtual_drive_device_name;
  if ((index >= 0x1000 && index <= 0x1FFF) || (ours && index >= 0x2000 && index <= 0x5FFF)) {
    return find_format(config_.known_objects, index, sub);
  }
  return std::nullopt;
}

// --- the cyclic exchange ------------------------------------------------------------------------

void can_link::start_cyclic() {
  if (stage_ != stage::acyclic || !failure_.empty()) return;
  // The set-up reads and writes by SDO: a node this link stopped is brought to PRE-OPERATIONAL
  // first (the set-up's NMT start takes it on to OPERATIONAL).
  if (sdo_held_) (void)send_nmt(nmt_command::enter_pre_operational);
  make_master();
  to_record_ = master_->objects_written();
  recorded_.clear();
  stage_ = stage::recording;
  // Read behind what is queued already; the set-up waits for the last of them.
  const std::uint8_t guard_node = drive_master_config{}.master_node_id;
  for (const auto& [index, sub] : to_record_) {
    own_.push_back({index, sub, false, {}, [this, index = index, sub = sub, guard_node](const axes::transfer_result& r) {
                      recorded rec{index, sub, r.ok ? r.data : std::vector<std::uint8_t>{}};
                      // A guard entry for this master's node-ID that a master killed earlier left is
                      // not how the node was meant to be: it goes back to 0.
                      if (index == consumer_heartbeat_time && rec.bytes.size() == 4 && rec.bytes[2] == guard_node &&
                          (rec.bytes[0] | rec.bytes[1]) != 0) {
                        rec.bytes = {0, 0, 0, 0};
                      }
                      recorded_.push_back(std::move(rec));
                    }});
  }
}

void can_link::make_master() {
  drive_master_config mc;
  mc.node_id = config_.node_id;
  mc.cycle_us = config_.cycle_us;
  mc.drive_heartbeat_ms = config_.drive_heartbeat_ms;
  mc.master_heartbeat_ms = config_.master_heartbeat_ms;
  mc.heartbeat_clock_us = config_.heartbeat_clock_us;
  mc.sdo_timeout_us = config_.sdo_timeout_us;
  mc.retry_us = config_.retry_us;
  mc.drive_profile = config_.drive_profile;
  mc.timing = pdo_timing::sync;
  mc.map_velocity = true;
  mc.map_position = config_.map_position;
  master_ = std::make_unique<drive_master>(*bus_, mc);
  master_->on_status = [this](std::uint16_t) {
    if (pdos_quiet_ && !start_sent_ && stage_ == stage::cyclic) return;  // sent before the NMT stop or preop
    pdos_quiet_ = false;
    ++status_count_;
    // Every status word gets the control word back, as a SYNC master's RPDO1 answers TPDO1.
    if (word_ && stage_ == stage::cyclic) master_->send_control_word(*word_);
  };
  master_->on_emcy = [this](std::uint16_t code, std::uint8_t reg, const std::uint8_t* bytes) {
    if (on_emergency) on_emergency(code, reg, std::span<const std::uint8_t>(bytes, 5));
  };
  master_->before_sync = [this] {
    if (before_cycle) before_cycle();
  };
  master_->on_phase = [this](master_phase p, phase_reason why) {
    if (p == master_phase::running) {
      // The set-up ends with NMT start: the node serves SDO and sends its PDOs again.
      sdo_held_ = false;
      pdos_quiet_ = false;
    }
    if (!on_event) return;
    if (why == phase_reason::failed) on_event(axes::link_event::failed, master_->failure_text());
    if (why == phase_reason::node_restarted) on_event(axes::link_event::restarted, master_->phase_text());
  };
}

void can_link::record_next() {
  // Everything the set-up writes is known: let it run.
  if (recorded_.size() == to_record_.size()) stage_ = stage::setting_up;
}

void can_link::learn_cyclic() {
  inputs_ = {{object_index::status_word, 0, 16}};
  outputs_ = {{object_index::control_word, 0, 16}};
  if (master_->error_code_mapped()) inputs_.push_back({object_index::error_code, 0, 16});
  if (master_->velocity_mapped()) inputs_.push_back({object_index::velocity_actual_value, 0, 32});
  if (master_->position_mapped()) {
    inputs_.push_back({object_index::position_actual_value, 0, 32});
    outputs_.push_back({object_index::target_position, 0, 32});
  }
}

std::optional<std::int64_t> can_link::cyclic_input(std::uint16_t index, std::uint8_t sub) const {
  if (!status_known() || sub != 0) return std::nullopt;
  switch (index) {
    case object_index::status_word: return master_->status_word();
    case object_index::error_code:
      if (master_->error_code_mapped()) return master_->error_code();
      break;
    case object_index::velocity_actual_value:
      if (const auto v = master_->velocity(); v && master_->velocity_mapped()) return *v;
      break;
    case object_index::position_actual_value:
      if (const auto p = master_->position(); p && master_->position_mapped()) return *p;
      break;
    default: break;
  }
  return std::nullopt;
}

bool can_link::set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) {
  if (!cyclic() || sub != 0) return false;
  if (index == object_index::control_word) {
    set_control_word(static_cast<std::uint16_t>(value));
    return true;
  }
  if (index == object_index::target_position && master_->position_mapped()) {
    master_->set_position_set_point(static_cast<std::int32_t>(value));
    return true;
  }
  return false;
}

void can_link::set_control_word(std::uint16_t word) {
  const bool changed = !word_ || *word_ != word;
  word_ = word;
  if (changed && stage_ == stage::cyclic && master_->phase() == master_phase::running) master_->send_control_word(word);
}

}  // namespace cia402::canopen
