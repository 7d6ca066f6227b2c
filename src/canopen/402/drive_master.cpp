#include "cia402/canopen/drive_master.hpp"

#include <algorithm>
#include <cstdio>

#include "cia402/canopen/pdo.hpp"

namespace cia402::canopen {

const char* master_failure_name(master_failure f) noexcept {
  switch (f) {
    case master_failure::none: return "none";
    case master_failure::no_answer: return "no_answer";
    case master_failure::sdo_refused: return "sdo_refused";
    case master_failure::not_a_drive: return "not_a_drive";
    case master_failure::heartbeat_lost: return "heartbeat_lost";
  }
  return "unknown";
}

drive_master::drive_master(channel& out, const drive_master_config& config)
    : out_(&out),
      config_(config),
      profile_(config.drive_profile != nullptr ? config.drive_profile : &standard_profile()),
      sdo_(out, config.node_id, config.sdo_timeout_us),
      options_(make_axis(*profile_)) {
  consumer_.on_change = [this](std::uint8_t, bool lost) {
    if (lost && phase_ == master_phase::running) {
      fail(master_failure::heartbeat_lost, sdo_abort::none, 0, 0);
    }
  };
  producer_.configure(config_.master_heartbeat_ms);
  build_script();
}

void drive_master::build_script() {
  const std::uint8_t node = config_.node_id;
  const auto fixed = [](std::int64_t v) { return [v] { return v; }; };
  const auto write = [&](std::uint16_t index, std::uint8_t sub, std::int64_t v, unsigned bytes) {
    sdo_step s;
    s.write = true;
    s.index = index;
    s.sub = sub;
    s.value = fixed(v);
    s.bytes = bytes;
    return s;
  };

  sdo_step type;
  type.index = 0x1000;
  type.then = [this](const sdo_client& c) {
    if ((c.value() & 0xFFFF) != 0x0192) fail(master_failure::not_a_drive, sdo_abort::none, 0x1000, 0);
  };
  script_.push_back(type);
  for (std::uint16_t index : std::initializer_list<std::uint16_t>{0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007}) {
    sdo_step s;
    s.index = index;
    s.optional = true;
    s.then = [this, index](const sdo_client& c) {
      if (c.state() == sdo_client::status::done) {
        (void)write_option(*profile_, options_, index, static_cast<std::int32_t>(c.value(true)));
      }
    };
    script_.push_back(s);
  }
  if (config_.drive_heartbeat_ms != 0) {
    script_.push_back(write(0x1017, 0, config_.drive_heartbeat_ms, 2));
  }
  if (config_.master_heartbeat_ms != 0) {
    const std::uint32_t watch = std::min<std::uint32_t>(3u * config_.master_heartbeat_ms, 0xFFFF);
    script_.push_back(write(0x1016, 1, (static_cast<std::int64_t>(config_.master_node_id) << 16) | watch, 4));
  }
  // TPDO1: status word (+ error code), on every SYNC.
  const std::int64_t tpdo_id = cob::tpdo1 + node;
  script_.push_back(write(0x1800, 1, pdo_cob_invalid | tpdo_id, 4));
  script_.push_back(write(0x1A00, 0, 0, 1));
  script_.push_back(write(0x1A00, 1, 0x60410010, 4));
  sdo_step error_entry = write(0x1A00, 2, 0x603F0010, 4);
  error_entry.optional = true;
  error_entry.then = [this](const sdo_client& c) {
    error_code_mapped_ = c.state() == sdo_client::status::done;
  };
  script_.push_back(error_entry);
  sdo_step count = write(0x1A00, 0, 0, 1);
  count.value = [this] { return std::int64_t{error_code_mapped_ ? 2 : 1}; };
  script_.push_back(count);
  script_.push_back(write(0x1800, 2, 1, 1));
  script_.push_back(write(0x1800, 1, tpdo_id, 4));
  // RPDO1: control word, acting on receipt.
  const std::int64_t rpdo_id = cob::rpdo1 + node;
  script_.push_back(write(0x1400, 1, pdo_cob_invalid | rpdo_id, 4));
  script_.push_back(write(0x1600, 0, 0, 1));
  script_.push_back(write(0x1600, 1, 0x60400010, 4));
  script_.push_back(write(0x1600, 0, 1, 1));
  script_.push_back(write(0x1400, 2, 255, 1));
  script_.push_back(write(0x1400, 1, rpdo_id, 4));
}

void drive_master::start_step() {
  step_started_ = true;
  const sdo_step& s = script_[step_];
  sdo_.clear();
  if (s.write) {
    (void)sdo_.start_download(s.index, s.sub, s.value(), s.bytes);
  } else {
    (void)sdo_.start_upload(s.index, s.sub);
  }
}

void drive_master::fail(master_failure f, sdo_abort a, std::uint16_t index, std::uint8_t sub) {
  if (phase_ == master_phase::failed) return;
  phase_ = master_phase::failed;
  failure_ = f;
  failed_abort_ = a;
  failed_index_ = index;
  failed_sub_ = sub;
}

std::string drive_master::failure_text() const {
  char buf[160];
  switch (failure_) {
    case master_failure::none: return "no failure";
    case master_failure::no_answer:
      std::snprintf(buf, sizeof buf, "node %u does not answer (SDO timeout reading/writing 0x%04X:%u)",
                    config_.node_id, failed_index_, failed_sub_);
      return buf;
    case master_failure::sdo_refused:
      std::snprintf(buf, sizeof buf, "node %u refused 0x%04X:%u: SDO abort 0x%08X (%s)", config_.node_id,
                    failed_index_, failed_sub_, static_cast<unsigned>(failed_abort_),
                    sdo_abort_text(failed_abort_));
      return buf;
    case master_failure::not_a_drive:
      std::snprintf(buf, sizeof buf, "node %u is not a CiA 402 drive (0x1000 low word is not 0x0192)",
                    config_.node_id);
      return buf;
    case master_failure::heartbeat_lost:
      std::snprintf(buf, sizeof buf, "node %u: heartbeat lost (none for %u ms)", config_.node_id,
                    3u * config_.drive_heartbeat_ms);
      return buf;
  }
  return "unknown failure";
}

void drive_master::set_target(state target) {
  mode_ = mode::target;
  pending_target_ = target;
  policy_ = master_policy::make(*profile_, options_, target);
  master_.set_target(policy_, now_us_, config_.transition_timeout_us);
}

void drive_master::set_command(command c) {
  mode_ = mode::command;
  command_ = c;
  master_.clear_target();
}

void drive_master::clear_target() {
  mode_ = mode::idle;
  master_.clear_target();
}

void drive_master::send_control_word(std::uint16_t cw) {
  frame f;
  f.id = cob::rpdo1 + config_.node_id;
  f.len = 2;
  put_le(f.data.data(), cw, 2);
  (void)out_->send(f);
}

void drive_master::on_status(std::uint16_t sw, std::uint16_t err) {
  status_known_ = true;
  status_word_ = sw;
  error_code_ = err;
  state s = state::start;
  if (!decode_status(*profile_, sw, s)) s = state::start;
  if (s != observed_) {
    const state before = observed_;
    observed_ = s;
    if (on_state) on_state(before, s, sw);
  }
  if (phase_ != master_phase::running) return;
  switch (mode_) {
    case mode::idle: break;
    case mode::target: send_control_word(master_.step(sw, now_us_, err)); break;
    case mode::command: {
      std::uint16_t cw = 0;
      if (encode_command(*profile_, command_, 0, cw)) send_control_word(cw);
      break;
    }
  }
}

void drive_master::on_frame(const frame& f) {
  if (f.extended || f.rtr) return;
  const std::uint8_t node = config_.node_id;
  if (sdo_.on_frame(f)) return;
  if (consumer_.on_frame(f)) return;
  if (f.id == cob::emcy + node && f.len == 8) {
    if (on_emcy) on_emcy(static_cast<std::uint16_t>(get_le(f.data.data(), 2)), f.data[2], f.data.data() + 3);
    return;
  }
  if (f.id == cob::tpdo1 + node && f.len >= 2) {
    const auto sw = static_cast<std::uint16_t>(get_le(f.data.data(), 2));
    const auto err = f.len >= 4 && error_code_mapped_ ? static_cast<std::uint16_t>(get_le(f.data.data() + 2, 2))
                                                      : std::uint16_t{0};
    on_status(sw, err);
  }
}

std::uint32_t drive_master::process(std::uint32_t elapsed_us) {
  now_us_ += elapsed_us;
  std::uint32_t next = producer_.process(elapsed_us, *out_, config_.master_node_id,
                                         nmt_state::operational);
  next = earliest(next, consumer_.process(elapsed_us));
  if (phase_ == master_phase::configuring) {
    if (!step_started_) start_step();
    next = earliest(next, sdo_.process(elapsed_us));
    while (phase_ == master_phase::configuring && sdo_.finished()) {
      const sdo_step& s = script_[step_];
      if (sdo_.state() == sdo_client::status::aborted && !s.optional) {
        fail(sdo_.abort_code() == sdo_abort::sdo_protocol_timed_out ? master_failure::no_answer
                                                                    : master_failure::sdo_refused,
             sdo_.abort_code(), s.index, s.sub);
        break;
      }
      // An optional read that timed out still means a silent node.
      if (sdo_.state() == sdo_client::status::aborted &&
          sdo_.abort_code() == sdo_abort::sdo_protocol_timed_out) {
        fail(master_failure::no_answer, sdo_.abort_code(), s.index, s.sub);
        break;
      }
      if (s.then) s.then(sdo_);
      if (phase_ != master_phase::configuring) break;
      if (++step_ == script_.size()) {
        sdo_.clear();
        (void)out_->send(nmt_frame(nmt_command::start, config_.node_id));
        if (config_.drive_heartbeat_ms != 0) {
          consumer_.configure({{config_.node_id,
                                static_cast<std::uint16_t>(std::min<std::uint32_t>(
                                    3u * config_.drive_heartbeat_ms, 0xFFFF))}});
        }
        phase_ = master_phase::running;
        sync_timer_.start(config_.cycle_us);
        if (mode_ == mode::target) master_.set_target(policy_, now_us_, config_.transition_timeout_us);
        (void)out_->send(make_frame(cob::sync, {}));
        break;
      }
      start_step();
    }
    if (phase_ == master_phase::configuring) next = earliest(next, sdo_.process(0));
    return next;
  }
  if (phase_ == master_phase::running) {
    if (sync_timer_.expired(elapsed_us)) (void)out_->send(make_frame(cob::sync, {}));
    next = earliest(next, sync_timer_.left());
  }
  return next;
}

std::uint32_t drive_master::poll(channel& in, std::uint32_t elapsed_us) {
  frame f;
  while (in.receive(f)) on_frame(f);
  return process(elapsed_us);
}

}  // namespace cia402::canopen
