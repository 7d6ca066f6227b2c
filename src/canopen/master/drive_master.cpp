#include "cia402/canopen/master/drive_master.hpp"

#include <algorithm>

#include "cia402/canopen/301/pdo.hpp"
#include "cia402/master.hpp"  // decode_status
#include "cia402/support/text.hpp"
#include "cia402/words.hpp"

namespace cia402::canopen {
namespace {

using support::hex;

std::string abort_text(sdo_abort code) {
  return "SDO abort " + hex(static_cast<std::uint32_t>(code), 8) + " (" + sdo_abort_text(code) + ")";
}

}  // namespace

const char* master_failure_name(master_failure f) noexcept {
  switch (f) {
    case master_failure::none: return "none";
    case master_failure::no_answer: return "no_answer";
    case master_failure::sdo_refused: return "sdo_refused";
    case master_failure::not_a_drive: return "not_a_drive";
    case master_failure::heartbeat_lost: return "heartbeat_lost";
    case master_failure::bus_failed: return "bus_failed";
  }
  return "unknown";
}

drive_master::drive_master(channel& out, const drive_master_config& config)
    : out_(&out),
      config_(config),
      profile_(config.drive_profile != nullptr ? config.drive_profile : &standard_profile()),
      sdo_(out, config.node_id, config.sdo_timeout_us),
      options_(make_axis(*profile_)) {
  if (config_.cycle_us == 0) config_.cycle_us = 1000;
  consumer_.on_change = [this](std::uint8_t, bool lost) { heartbeat_lost_ = lost; };
  producer_.configure(config_.master_heartbeat_ms);
  text_ = "configuring " + node_text();
  build_script();
}

std::string drive_master::node_text() const { return "node " + std::to_string(config_.node_id); }

void drive_master::set_phase(master_phase p, phase_reason why) {
  phase_ = p;
  if (on_phase) on_phase(p, why);
}

void drive_master::restart(phase_reason why, std::string text) {
  drop_requests();
  failure_ = master_failure::none;
  failed_abort_ = sdo_abort::none;
  failed_index_ = 0;
  failed_sub_ = 0;
  text_ = std::move(text);
  step_ = 0;
  skipped_group_ = 0;
  device_name_.clear();
  fault_injection_ = false;
  heartbeat_watched_ = false;
  error_code_mapped_ = false;
  velocity_mapped_ = false;
  position_mapped_ = false;
  position_.reset();
  stale_guard_ = false;
  consumer_.configure({});
  heartbeat_lost_ = false;
  outbox_.clear();
  set_phase(master_phase::configuring, why);
}

void drive_master::go_running() {
  text_.clear();
  if (heartbeat_watched_) {
    consumer_.configure({{config_.node_id, static_cast<std::uint16_t>(std::min<std::uint32_t>(
                                               3u * config_.drive_heartbeat_ms, 0xFFFF))}});
  }
  // The drive watches this master's heartbeat (0x1016) only from the first one it hears: one goes
  // now, before any control word, so a bus that falls silent after the enable reaches the drive's
  // 0x6007 however soon it does.
  producer_.send_now(*out_, config_.master_node_id, nmt_state::operational);
  next_poll_us_ = now_us_ + config_.poll_us;
  word_sent_ = false;
  set_phase(master_phase::running, phase_reason::running);
  if (config_.timing == pdo_timing::sync) {
    sync_timer_.start(config_.cycle_us);
    send_sync();
  }
}

void drive_master::fail(master_failure f, sdo_abort a, std::uint16_t index, std::uint8_t sub,
                        std::string text) {
  if (phase_ == master_phase::failed) return;
  drop_requests();
  failure_ = f;
  failed_abort_ = a;
  failed_index_ = index;
  failed_sub_ = sub;
  text_ = std::move(text);
  retry_at_us_ = now_us_ + config_.retry_us;
  outbox_.clear();
  consumer_.configure({});
  heartbeat_lost_ = false;
  set_phase(master_phase::failed, phase_reason::failed);
}

// --- SDO transfers ------------------------------------------------------------------------------

void drive_master::drop_requests() {
  std::vector<std::function<void(const sdo_result&)>> cancelled;
  if (current_) {
    if (sdo_.state() == sdo_client::status::busy) sdo_.cancel();
    if (current_->done) cancelled.push_back(std::move(current_->done));
    current_.reset();
  }
  sdo_.clear();
  for (sdo_job& j : requests_) {
    if (j.done) cancelled.push_back(std::move(j.done));
  }
  requests_.clear();
  sdo_result r;
  r.cancelled = true;
  for (auto& done : cancelled) done(r);
}

bool drive_master::queue_request(std::uint16_t index, std::uint8_t sub, sdo_job j,
                                 std::function<void(const sdo_result&)> done) {
  if (phase_ != master_phase::running) return false;
  j.index = index;
  j.sub = sub;
  j.done = std::move(done);
  requests_.push_back(std::move(j));
  return true;
}

bool drive_master::read(std::uint16_t index, std::uint8_t sub, bool is_signed,
                        std::function<void(const sdo_result&)> done) {
  sdo_job j;
  j.is_signed = is_signed;
  return queue_request(index, sub, std::move(j), std::move(done));
}

bool drive_master::write(std::uint16_t index, std::uint8_t sub, std::int64_t value, unsigned bytes,
                         std::function<void(const sdo_result&)> done) {
  std::vector<std::uint8_t> data(bytes);
  put_le(data.data(), static_cast<std::uint64_t>(value), bytes);
  return download(index, sub, std::move(data), std::move(done));
}

bool drive_master::upload(std::uint16_t index, std::uint8_t sub, std::function<void(const sdo_result&)> done) {
  return read(index, sub, false, std::move(done));
}

bool drive_master::download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes,
                            std::function<void(const sdo_result&)> done) {
  sdo_job j;
  j.write = true;
  j.raw = std::move(bytes);
  return queue_request(index, sub, std::move(j), std::move(done));
}

std::vector<std::pair<std::uint16_t, std::uint8_t>> drive_master::objects_written() const {
  std::vector<std::pair<std::uint16_t, std::uint8_t>> out;
  for (const sdo_job& j : script_) {
    if (!j.write) continue;
    const std::pair<std::uint16_t, std::uint8_t> at{j.index, j.sub};
    if (std::find(out.begin(), out.end(), at) == out.end()) out.push_back(at);
  }
  return out;
}

bool drive_master::request_pending() const noexcept {
  return !requests_.empty() || (current_ && current_->done);
}

void drive_master::start_transfer(const sdo_job& j) {
  sdo_.clear();
  if (j.write && j.raw && j.raw->size() >= sdo_client::block_from_bytes) {
    (void)sdo_.start_block_download(j.index, j.sub, *j.raw);
  } else if (j.write && j.raw) {
    (void)sdo_.start_download(j.index, j.sub, *j.raw);
  } else if (j.write) {
    (void)sdo_.start_download(j.index, j.sub, j.value(), j.bytes);
  } else {
    (void)sdo_.start_upload(j.index, j.sub);
  }
}

drive_master::sdo_job drive_master::next_poll() {
  // What no PDO carries, one object per poll period in turn.
  std::vector<std::uint16_t> list{0x1001};
  if (!velocity_mapped_) list.push_back(0x606C);
  if (!error_code_mapped_) list.push_back(0x603F);
  if (!heartbeat_watched_) list.push_back(0x6041);
  const std::uint16_t index = list[poll_index_++ % list.size()];
  sdo_job j;
  j.index = index;
  j.optional = true;
  j.is_signed = index == 0x606C;
  j.then = [this, index](const sdo_client& c) {
    if (c.state() != sdo_client::status::done) return;
    switch (index) {
      case 0x1001: error_register_ = static_cast<std::uint8_t>(c.value()); break;
      case 0x606C: note_velocity(static_cast<std::int32_t>(c.value(true))); break;
      case 0x603F: error_code_ = static_cast<std::uint16_t>(c.value()); break;
      case 0x6041: note_status(static_cast<std::uint16_t>(c.value())); break;
      default: break;
    }
  };
  return j;
}

bool drive_master::start_next_job() {
  if (phase_ == master_phase::configuring) {
    while (phase_ == master_phase::configuring && step_ < script_.size()) {
      const sdo_job& j = script_[step_];
      if ((j.group != 0 && j.group == skipped_group_) || (j.wanted && !j.wanted())) {
        ++step_;
        continue;
      }
      if (j.nmt_start) {
        ++step_;
        (void)out_->send(nmt_frame(nmt_command::start, config_.node_id));
        go_running();
        return false;
      }
      current_ = j;
      start_transfer(*current_);
      return true;
    }
    return false;
  }
  if (phase_ != master_phase::running) return false;
  if (!requests_.empty()) {
    current_ = std::move(requests_.front());
    requests_.pop_front();
    start_transfer(*current_);
    return true;
  }
  if (config_.poll_us != 0 && now_us_ >= next_poll_us_) {
    next_poll_us_ = now_us_ + config_.poll_us;
    current_ = next_poll();
    start_transfer(*current_);
    return true;
  }
  return false;
}

void drive_master::complete_current() {
  sdo_job job = std::move(*current_);
  current_.reset();
  const bool ok = sdo_.state() == sdo_client::status::done;
  const sdo_abort abort = ok ? sdo_abort::none : sdo_.abort_code();
  const bool timed_out = abort == sdo_abort::sdo_protocol_timed_out;
  const std::string what = std::string(job.write ? "writing " : "reading ") +
                           hex(job.index, 4) + ":" + std::to_string(job.sub);
  const auto lose = [&] {
    fail(master_failure::no_answer, abort, job.index, job.sub,
         node_text() + " does not answer (SDO timeout " + what + ")");
  };

  if (job.done) {  // a request
    sdo_result r;
    r.abort = abort;
    if (ok) r.value = sdo_.value(job.is_signed);
    if (ok && !job.write) r.data = sdo_.data();
    job.done(r);
    // A node that lets an SDO request time out is silent, whatever its heartbeat did last.
    if (timed_out) lose();
    return;
  }
  if (phase_ == master_phase::running) {  // a poll
    if (job.then) job.then(sdo_);
    if (timed_out) lose();
    return;
  }
  if (phase_ != master_phase::configuring) return;
  if (timed_out) {
    lose();
    return;
  }
  if (!ok && !job.optional) {
    fail(master_failure::sdo_refused, abort, job.index, job.sub,
         node_text() + " refused " + what + ": " + abort_text(abort));
    return;
  }
  if (!ok && job.group != 0) skipped_group_ = job.group;
  if (job.then) job.then(sdo_);
  ++step_;
}

void drive_master::drive_jobs() {
  for (int guard = 0; guard < 64; ++guard) {
    if (!current_ && !start_next_job()) return;
    if (!current_ || !sdo_.finished()) return;
    complete_current();
  }
}

// --- what the drive reports ---------------------------------------------------------------------

void drive_master::note_velocity(std::int32_t v) {
  velocity_ = v;
  if (on_velocity) on_velocity(v);
}

void drive_master::note_status(std::uint16_t sw) {
  status_known_ = true;
  status_word_ = sw;
  state s = state::start;
  if (!decode_status(*profile_, sw, s)) s = state::start;
  if (on_status) on_status(sw);
  if (s != observed_) {
    const state before = observed_;
    observed_ = s;
    if (on_state) on_state(before, s, sw);
  }
}

void drive_master::on_frame(const frame& f) {
  if (f.extended || f.rtr) return;
  if (phase_ == master_phase::failed && failure_ == master_failure::bus_failed) return;
  const std::uint8_t node = config_.node_id;
  if (sdo_.on_frame(f)) {
    // The answer ends its transfer before the next frame (a TPDO the write caused) is looked at.
    if (current_ && sdo_.finished()) drive_jobs();
    return;
  }
  if (f.id == cob::heartbeat + node && f.len >= 1) {
    nmt_seen_ = f.data[0];
    if (f.data[0] == static_cast<std::uint8_t>(nmt_state::initialising) &&
        (phase_ != master_phase::failed || config_.retry_us != 0)) {
      // Boot-up: the node starts afresh with its default PDOs; set it up again.
      restart(phase_reason::node_restarted,
              node_text() + " restarted (boot-up message): configuring it again");
      drive_jobs();
      return;
    }
    (void)consumer_.on_frame(f);
    return;
  }
  if (phase_ == master_phase::failed) return;
  if (f.id == cob::emcy + node && f.len >= 3) {
    const auto code = static_cast<std::uint16_t>(get_le(f.data.data(), 2));
    last_emcy_ = code;
    error_register_ = f.data[2];
    if (!error_code_mapped_) error_code_ = code;
    if (on_emcy) on_emcy(code, f.data[2], f.data.data() + 3);
    return;
  }
  if (f.id == cob::tpdo1 + node && f.len >= 2) {
    if (error_code_mapped_ && f.len >= 4) {
      error_code_ = static_cast<std::uint16_t>(get_le(f.data.data() + 2, 2));
    }
    note_status(static_cast<std::uint16_t>(get_le(f.data.data(), 2)));
    return;
  }
  if (velocity_mapped_ && f.id == cob::tpdo1 + 0x100 + node && f.len >= 4) {
    note_velocity(static_cast<std::int32_t>(static_cast<std::uint32_t>(get_le(f.data.data(), 4))));
    return;
  }
  // TPDO3: the status word (TPDO1 has it too, and steers) and the position actual value.
  if (position_mapped_ && f.id == cob::tpdo1 + 0x200 + node && f.len >= 6) {
    position_ = static_cast<std::int32_t>(static_cast<std::uint32_t>(get_le(f.data.data() + 2, 4)));
    if (on_position) on_position(*position_);
  }
}

// --- the words carried ---------------------------------------------------------------------------

void drive_master::clear_target() { outbox_.clear(); }

void drive_master::send_control_word(std::uint16_t word, bool fault_reset_edge) {
  outbox_.clear();
  if (!fault_reset_edge) {
    outbox_.emplace_back(word, now_us_);
    return;
  }
  // Each level of the edge held for reset_pulse_us, so the drive steps on both.
  const fault_reset_words edge = cia402::fault_reset_edge(last_sent_, word);
  for (std::uint8_t i = 0; i < edge.count; ++i) {
    outbox_.emplace_back(edge.words[i], now_us_ + std::uint64_t{i} * config_.reset_pulse_us);
  }
}

void drive_master::send_word(std::uint16_t cw) {
  if (position_mapped_ && position_set_point_ && set_point_unsent_) {
    // RPDO3 carries it with the set-point at the next SYNC.
    last_sent_ = cw;
    word_sent_ = true;
    if (on_sent) on_sent(cw);
    return;
  }
  frame f;
  f.id = cob::rpdo1 + config_.node_id;
  f.len = 2;
  put_le(f.data.data(), cw, 2);
  last_sent_ = cw;
  word_sent_ = true;
  (void)out_->send(f);
  if (on_sent) on_sent(cw);
}

void drive_master::send_sync() {
  if (before_sync) before_sync();
  if (position_mapped_ && position_set_point_ && word_sent_) {
    // RPDO3 takes effect at the SYNC that follows it: the control word it carries is the last one
    // given (sent in RPDO1 already, or held for this RPDO3 with a new set-point), the set-point is
    // this cycle's.
    frame f;
    f.id = cob::rpdo1 + 0x200 + config_.node_id;
    f.len = 6;
    put_le(f.data.data(), last_sent_, 2);
    put_le(f.data.data() + 2, static_cast<std::uint32_t>(*position_set_point_), 4);
    (void)out_->send(f);
    set_point_unsent_ = false;
  }
  (void)out_->send(make_frame(cob::sync, {}));
}

// --- time ---------------------------------------------------------------------------------------

std::uint32_t drive_master::process(std::uint32_t elapsed_us) {
  now_us_ += elapsed_us;
  if (failure_ == master_failure::bus_failed) return no_deadline;
  if (const std::error_code ec = out_->failure()) {
    fail(master_failure::bus_failed, sdo_abort::none, 0, 0,
         "the bus connection failed: " + ec.message());
    return no_deadline;
  }
  if (!started_) {
    started_ = true;
    set_phase(master_phase::configuring, phase_reason::started);
  }
  std::uint32_t heartbeat_elapsed_us = elapsed_us;
  if (config_.heartbeat_clock_us) {
    const std::uint64_t now = config_.heartbeat_clock_us();
    const std::uint64_t before = heartbeat_clock_before_.value_or(now);
    const std::uint64_t passed = now > before ? now - before : 0;
    heartbeat_elapsed_us = static_cast<std::uint32_t>(std::min<std::uint64_t>(passed, no_deadline));
    heartbeat_clock_before_ = now;
  }
  std::uint32_t next = producer_.process(heartbeat_elapsed_us, *out_, config_.master_node_id,
                                         nmt_state::operational);
  next = earliest(next, consumer_.process(elapsed_us));
  if (heartbeat_lost_ && phase_ == master_phase::running) {
    fail(master_failure::heartbeat_lost, sdo_abort::none, 0, 0,
         node_text() + " does not answer (no heartbeat for " +
             std::to_string(3u * config_.drive_heartbeat_ms) + " ms)");
  }
  heartbeat_lost_ = false;
  const bool was_running = phase_ == master_phase::running;
  if (current_) next = earliest(next, sdo_.process(elapsed_us));
  drive_jobs();
  if (phase_ == master_phase::failed && config_.retry_us != 0 && now_us_ >= retry_at_us_) {
    restart(phase_reason::retrying, text_ + "; trying again");
    drive_jobs();
  }
  if (phase_ == master_phase::running) {
    while (!outbox_.empty() && outbox_.front().second <= now_us_) {
      send_word(outbox_.front().first);
      outbox_.pop_front();
    }
    if (!outbox_.empty()) {
      next = earliest(next, static_cast<std::uint32_t>(
                                std::min<std::uint64_t>(outbox_.front().second - now_us_, no_deadline)));
    }
    if (config_.timing == pdo_timing::sync) {
      // The SYNC that started the running phase counts as this cycle's.
      if (was_running && sync_timer_.expired(elapsed_us)) send_sync();
      next = earliest(next, sync_timer_.left());
    }
    if (config_.poll_us != 0 && !current_) {
      next = earliest(next, static_cast<std::uint32_t>(std::min<std::uint64_t>(
                                next_poll_us_ > now_us_ ? next_poll_us_ - now_us_ : 0, no_deadline)));
    }
  }
  if (current_) next = earliest(next, sdo_.process(0));
  if (phase_ == master_phase::failed && config_.retry_us != 0) {
    next = earliest(next, static_cast<std::uint32_t>(std::min<std::uint64_t>(
                              retry_at_us_ > now_us_ ? retry_at_us_ - now_us_ : 0, no_deadline)));
  }
  return next;
}

std::uint32_t drive_master::poll(channel& in, std::uint32_t elapsed_us) {
  frame f;
  for (int n = 0; n < 4096 && in.receive(f); ++n) on_frame(f);
  return process(elapsed_us);
}

}  // namespace cia402::canopen
