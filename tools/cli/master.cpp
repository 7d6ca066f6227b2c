#include "cli/master.hpp"

#include <poll.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <csignal>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>

#include <nlohmann/json.hpp>

#include "cia402/apps/elapsed_clock.hpp"
#include "cia402/objects.hpp"
#include "cia402/canopen/transport/channel_url.hpp"
#include "cia402/canopen/402/drive_master.hpp"
#include "cia402/canopen/301/sdo_client.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

constexpr int usage_error = 2;
constexpr int failed = 1;
volatile std::sig_atomic_t stop_requested = 0;
extern "C" void request_master_stop(int) { stop_requested = 1; }

// The bus the master runs on: a real channel with real time, or an in-process bus holding one
// virtual drive, run in virtual time (no waiting).
class bus_session {
 public:
  bool open(const master_args& a, const profile& p, std::ostream& err) {
    canopen::channel_url url;
    std::string why;
    if (!canopen::parse_channel_url(a.can, url, why)) {
      err << "cia402 master: --can " << a.can << ": " << why << "\n";
      return false;
    }
    if (url.type == canopen::channel_url::kind::virtual_bus) {
      virtual_ = true;
      drive_ = std::make_unique<apps::virtual_drive_node>(
          p, bus_.attach(), apps::drive_node_config(static_cast<std::uint8_t>(a.node)));
      master_ch_ = bus_.attach();
      channel_ = master_ch_.get();
      for (int i = 0; i < 10; ++i) drive_->poll(1000);  // past power-up (T0, T1)
      frame_drain();
      return true;
    }
    real_ = canopen::open_channel(url, why);
    if (!real_) {
      err << "cia402 master: " << why << "\n";
      open_failed_ = true;
      return false;
    }
    channel_ = real_.get();
    clock_ = apps::elapsed_clock();
    return true;
  }
  canopen::channel& channel() { return *channel_; }
  /// Waits for the next thing to do (at most `wait_us`) and returns the microseconds that passed.
  std::uint32_t wait(std::uint32_t wait_us) {
    if (virtual_) {
      drive_->poll(virtual_step_us_);
      return virtual_step_us_;
    }
    pollfd p{channel_->native_handle(), POLLIN, 0};
    if (precise_) {
      // A SYNC period that a millisecond's rounding would stretch: wait to the microsecond.
      const std::uint32_t us = std::clamp<std::uint32_t>(wait_us, 50, 10000);
      const timespec ts{0, static_cast<long>(us) * 1000};
      if (p.fd >= 0) ::ppoll(&p, 1, &ts, nullptr);
      return clock_.take();
    }
    const int ms = static_cast<int>(std::min<std::uint32_t>(wait_us / 1000 + 1, 10));
    if (p.fd >= 0) ::poll(&p, 1, ms);
    return clock_.take();
  }
  /// For a SYNC period of `us` kept to the microsecond (csp-stream): on the virtual bus one wait()
  /// passes at most that long (1000 us otherwise), on a real one it waits to the microsecond.
  void set_sync_period(std::uint32_t us) {
    virtual_step_us_ = std::clamp<std::uint32_t>(us, 1, 1000);
    precise_ = true;
  }
  /// One pass of a master: waits for the next thing to do, hands it the frames and the time that
  /// passed, lets a virtual drive answer at once. Returns the microseconds that passed; `next` is
  /// when the master next wants to run.
  std::uint32_t pump(canopen::drive_master& m, std::uint32_t& next) {
    const std::uint32_t us = wait(next);
    canopen::frame f;
    while (channel_->receive(f)) m.on_frame(f);
    next = m.process(us);
    settle();
    while (channel_->receive(f)) m.on_frame(f);
    next = std::min(next, m.process(0));
    return us;
  }
  /// Runs one started SDO transfer to its end, at most `timeout_us`; true when it is done.
  bool finish(canopen::sdo_client& sdo, std::uint64_t timeout_us) {
    for (std::uint64_t waited = 0; !sdo.finished() && waited < timeout_us;) {
      settle();
      canopen::frame f;
      while (channel_->receive(f)) sdo.on_frame(f);
      if (sdo.finished()) break;
      const std::uint32_t us = wait(1000);
      waited += us;
      sdo.process(us);
    }
    return sdo.state() == canopen::sdo_client::status::done;
  }
  /// Lets the virtual drive answer at once (no time passes).
  void settle() {
    if (virtual_) drive_->poll(0);
  }
  std::error_code failure() const { return channel_->failure(); }
  /// Drops what the virtual drive said while powering up (its boot-up message).
  void frame_drain() {
    canopen::frame f;
    while (master_ch_->receive(f)) {}
  }

 private:
  bool virtual_ = false;
  std::uint32_t virtual_step_us_ = 1000;
  bool precise_ = false;
  canopen::virtual_bus bus_;
  std::unique_ptr<apps::virtual_drive_node> drive_;
  std::unique_ptr<canopen::virtual_channel> master_ch_;
  std::unique_ptr<canopen::channel> real_;
  canopen::channel* channel_ = nullptr;
  apps::elapsed_clock clock_;

 public:
  bool open_failed_ = false;  // the URL was fine, the bus could not be reached
};

std::string word(std::uint16_t w) { return hex(w, 4); }

// The status word and error code over SDO, without configuring anything. False (and said on `err`)
// when the node does not answer or refuses 0x6041.
bool read_status(bus_session& s, const master_args& a, std::uint16_t& status_word,
                 std::uint16_t& error_code, std::ostream& err) {
  canopen::sdo_client sdo(s.channel(), static_cast<std::uint8_t>(a.node), 500000);
  const auto transfer = [&](std::uint16_t index) {
    sdo.clear();
    sdo.start_upload(index, 0);
    return s.finish(sdo, a.timeout_ms * 1000ull);
  };
  if (!transfer(0x6041)) {
    if (sdo.abort_code() == sdo_abort::sdo_protocol_timed_out || !sdo.finished()) {
      err << "cia402 master: node " << a.node << " does not answer (SDO timeout reading 0x6041)\n";
    } else {
      err << "cia402 master: node " << a.node << " refused 0x6041: SDO abort "
          << hex(static_cast<std::uint32_t>(sdo.abort_code()), 8) << " ("
          << sdo_abort_text(sdo.abort_code()) << ")\n";
    }
    return false;
  }
  status_word = static_cast<std::uint16_t>(sdo.value());
  error_code = transfer(0x603F) ? static_cast<std::uint16_t>(sdo.value()) : std::uint16_t{0};
  return true;
}

// One line per event: prose, or with --json one JSON object that names the node.
using node_event = std::function<void(nlohmann::ordered_json, const std::string&)>;
node_event node_events(const master_args& a, std::ostream& out) {
  return [&a, &out](nlohmann::ordered_json j, const std::string& text) {
    if (a.json) {
      nlohmann::ordered_json line{{"node", a.node}};
      line.update(j);
      out << line.dump() << "\n";
    } else {
      out << "node " << a.node << ": " << text << "\n";
    }
  };
}

// A line for every state the drive reports.
void print_states(canopen::drive_master& m, const node_event& event) {
  m.on_state = [event](state, state to, std::uint16_t sw) {
    event({{"event", "state"}, {"state", state_name(to)}, {"statusword", word(sw)}},
          std::string(state_name(to)) + " (statusword " + word(sw) + ")");
  };
}

std::string describe(const profile& p, int node, std::uint16_t status_word, std::uint16_t error_code) {
  state st = state::start;
  const bool known = decode_status(p, status_word, st);
  std::string text = "node " + std::to_string(node) + ": " + (known ? state_name(st) : "UNKNOWN") +
                     " (statusword " + word(status_word) + ")";
  if (error_code != 0) text += ", error code " + hex(error_code, 4);
  return text;
}

int read_state(bus_session& s, const master_args& a, const profile& p, std::ostream& out,
               std::ostream& err) {
  std::uint16_t sw = 0;
  std::uint16_t code = 0;
  if (!read_status(s, a, sw, code, err)) return failed;
  if (a.json) {
    state st = state::start;
    const bool known = decode_status(p, sw, st);
    nlohmann::ordered_json j{{"node", a.node},
                             {"state", known ? nlohmann::ordered_json(state_name(st)) : nullptr},
                             {"statusword", word(sw)},
                             {"error_code", hex(code, 4)}};
    out << j.dump() << "\n";
  } else {
    out << describe(p, a.node, sw, code) << "\n";
  }
  return 0;
}

// One SDO transfer on its own, no set-up: what a test bench scripts.
int run_sdo(bus_session& s, const master_args& a, std::ostream& out, std::ostream& err) {
  const auto& ops = a.operands;
  const bool writing = !ops.empty() && ops[0] == "write";
  if (ops.empty() || (ops[0] != "read" && ops[0] != "write") || ops.size() != (writing ? 3u : 2u)) {
    err << "cia402 master: sdo read INDEX[:SUB] | sdo write INDEX[:SUB] VALUE\n";
    return usage_error;
  }
  const std::string& where = ops[1];
  const auto colon = where.find(':');
  const auto index = parse_number(where.substr(0, colon));
  const auto sub = colon == std::string::npos ? std::optional<std::int64_t>(0)
                                               : parse_number(where.substr(colon + 1));
  if (!index || *index < 0 || *index > 0xFFFF || !sub || *sub < 0 || *sub > 0xFF) {
    err << "cia402 master: '" << where << "' is not INDEX[:SUB] (e.g. 0x6060 or 0x1018:1)\n";
    return usage_error;
  }
  const auto idx = static_cast<std::uint16_t>(*index);
  const auto sb = static_cast<std::uint8_t>(*sub);
  // The size and sign of a CiA 402 object come from the one object table; others are 32 bits.
  const object_description* known = find_drive_object(idx, sb);
  const unsigned bytes = known != nullptr ? static_cast<unsigned>(type_size(known->type)) : 4u;
  const bool is_signed = known != nullptr && type_signed(known->type);
  std::int64_t value = 0;
  if (writing) {
    const auto v = parse_number(ops[2]);
    if (!v) {
      err << "cia402 master: '" << ops[2] << "' is not a number (decimal or 0x hex)\n";
      return usage_error;
    }
    value = *v;
    if (known != nullptr && (value < type_low(known->type) || value > type_high(known->type))) {
      err << "cia402 master: " << value << " does not fit " << hex(idx, 4) << " ("
          << known->name << "): " << type_low(known->type) << ".." << type_high(known->type) << "\n";
      return usage_error;
    }
  }
  canopen::sdo_client sdo(s.channel(), static_cast<std::uint8_t>(a.node), 500000);
  if (writing) {
    sdo.start_download(idx, sb, value, bytes);
  } else {
    sdo.start_upload(idx, sb);
  }
  (void)s.finish(sdo, a.timeout_ms * 1000ull);
  const std::string object = hex(idx, 4) + ":" + std::to_string(sb);
  if (sdo.state() != canopen::sdo_client::status::done) {
    const sdo_abort code = sdo.finished() ? sdo.abort_code() : sdo_abort::sdo_protocol_timed_out;
    if (a.json) {
      out << nlohmann::ordered_json{{"node", a.node}, {"object", object},
                                    {"abort", hex(static_cast<std::uint32_t>(code), 8)},
                                    {"text", sdo_abort_text(code)}}
                 .dump()
          << "\n";
    }
    err << "cia402 master: node " << a.node << (writing ? " refused writing " : " refused reading ")
        << object << ": SDO abort " << hex(static_cast<std::uint32_t>(code), 8) << " ("
        << sdo_abort_text(code) << ")\n";
    return failed;
  }
  if (!writing) value = sdo.value(is_signed);
  if (a.json) {
    out << nlohmann::ordered_json{{"node", a.node}, {"object", object}, {"value", value}}.dump()
        << "\n";
  } else {
    out << "node " << a.node << ": " << object << (writing ? " written: " : " = ") << value
        << " (" << hex(static_cast<std::uint64_t>(value) & ((bytes >= 8 ? 0 : (1ull << (8 * bytes))) - 1), 2 * static_cast<int>(bytes)) << ")\n";
  }
  return 0;
}

int run_nmt(bus_session& s, const master_args& a, std::ostream& out, std::ostream& err) {
  struct named { const char* name; canopen::nmt_command command; };
  constexpr named commands[] = {{"start", canopen::nmt_command::start},
                                {"stop", canopen::nmt_command::stop},
                                {"preop", canopen::nmt_command::enter_pre_operational},
                                {"reset", canopen::nmt_command::reset_node},
                                {"reset-communication", canopen::nmt_command::reset_communication}};
  for (const named& n : commands) {
    if (a.operands.size() == 1 && a.operands[0] == n.name) {
      if (const auto ec = s.channel().send(canopen::nmt_frame(n.command, static_cast<std::uint8_t>(a.node)))) {
        err << "cia402 master: sending NMT " << n.name << " failed: " << ec.message() << "\n";
        return failed;
      }
      s.settle();
      out << "node " << a.node << ": NMT " << n.name << " sent\n";
      return 0;
    }
  }
  err << "cia402 master: nmt start|stop|preop|reset|reset-communication\n";
  return usage_error;
}


// `mode`, `move` and `home`: the operation modes over the bus. Each writes what it needs by SDO,
// waits for 0x6061 to show the mode, enables the drive with the core's master step where it moves,
// and then runs the mode's handshake on the control word's mode bits (CiA 402-2): pp bit 4 (new
// set-point) until bit 12 (acknowledge), then bit 10 (target reached); homing bit 4 (start) until
// bits 12 and 10 (attained), or bit 13 (homing error).
int run_motion(bus_session& session, const master_args& a, const profile& p, std::ostream& out,
               std::ostream& err) {
  const bool moving = a.command != "mode";
  std::int8_t wanted_mode = 0;
  std::int64_t target = 0;
  if (a.command == "mode") {
    if (a.operands.size() != 1 || !mode::parse(a.operands[0], wanted_mode)) {
      err << "cia402 master: mode MODE: pp, pv, tq, hm, csp, csv, cst or the number of 0x6060\n";
      return usage_error;
    }
  } else if (a.command == "move") {
    const auto v = a.operands.size() == 1 ? parse_number(a.operands[0]) : std::nullopt;
    if (!v || *v < type_low(object_type::integer32) || *v > type_high(object_type::integer32)) {
      err << "cia402 master: move POSITION: one integer for 0x607A (target position, increments)\n";
      return usage_error;
    }
    target = *v;
    wanted_mode = mode::profile_position;
  } else {
    if (!a.operands.empty()) {
      err << "cia402 master: home takes no operands (--method, --offset)\n";
      return usage_error;
    }
    wanted_mode = mode::homing;
  }
  // What goes over SDO first (0x607A after enabling: entering OPERATION ENABLED clears set-points
  // on some profiles, 002's T4).
  struct write_job {
    std::uint16_t index;
    std::int64_t value;
    unsigned bytes;
  };
  std::vector<write_job> before{{0x6060, wanted_mode, 1}};
  if (a.homing_method) before.push_back({0x6098, *a.homing_method, 1});
  if (a.home_offset) before.push_back({0x607C, *a.home_offset, 4});
  if (a.profile_velocity) before.push_back({0x6081, *a.profile_velocity, 4});
  std::vector<write_job> after_enable;
  if (a.command == "move") after_enable.push_back({0x607A, target, 4});

  canopen::drive_master_config mc;
  mc.node_id = static_cast<std::uint8_t>(a.node);
  mc.cycle_us = a.cycle_ms * 1000;
  mc.drive_heartbeat_ms = a.heartbeat_ms;
  mc.master_heartbeat_ms = a.guard_ms;
  mc.drive_profile = &p;
  canopen::drive_master m(session.channel(), mc);
  const node_event event = node_events(a, out);
  print_states(m, event);

  enum class phase { write_before, confirm_mode, enable, write_after, offer, wait_ack, wait_done, read_position };
  phase now = phase::write_before;
  std::size_t next_job = 0;
  bool job_busy = false;
  bool failed_job = false;
  bool done = false;
  std::int64_t position = 0;
  const auto run_job = [&](const write_job& j) {
    job_busy = true;
    const bool queued = m.write(j.index, 0, j.value, j.bytes, [&, j](const canopen::sdo_result& r) {
      job_busy = false;
      if (r.ok()) return;
      failed_job = true;
      err << "cia402 master: node " << a.node << ": writing " << hex(j.index, 4) << " = " << j.value;
      if (r.cancelled) {
        err << " was cancelled (the link to the drive was lost)\n";
      } else {
        err << " refused: SDO abort " << hex(static_cast<std::uint32_t>(r.abort), 8) << " ("
            << sdo_abort_text(r.abort) << ")\n";
      }
    });
    if (!queued) {
      job_busy = false;
      failed_job = true;
      err << "cia402 master: could not queue the write of " << hex(j.index, 4) << "\n";
    }
  };
  const auto read_job = [&](std::uint16_t index, bool is_signed, std::function<void(std::int64_t)> use) {
    job_busy = true;
    const bool queued = m.read(index, 0, is_signed, [&, index, use](const canopen::sdo_result& r) {
      job_busy = false;
      if (r.ok()) {
        use(r.value);
        return;
      }
      failed_job = true;
      err << "cia402 master: node " << a.node << ": reading " << hex(index, 4) << " failed\n";
    });
    if (!queued) {
      job_busy = false;
      failed_job = true;
    }
  };
  constexpr std::uint16_t bit10 = 1u << 10, bit12 = 1u << 12, bit13 = 1u << 13;
  const std::uint16_t relative = a.relative ? 0x40 : 0;
  bool seen_busy = false;  // the mode showed it left "target reached" (or never had it)

  stop_requested = 0;
  int status = failed;
  std::uint64_t elapsed = 0;
  std::uint32_t next = 0;
  while (!done) {
    if (stop_requested != 0) {
      err << "cia402 master: interrupted\n";
      break;
    }
    if (const auto ec = session.failure()) {
      err << "cia402 master: the bus connection failed: " << ec.message() << "\n";
      break;
    }
    elapsed += session.pump(m, next);
    if (m.phase() == canopen::master_phase::failed) {
      err << "cia402 master: " << m.failure_text() << "\n";
      break;
    }
    if (failed_job) break;
    if (a.timeout_ms != 0 && elapsed >= a.timeout_ms * 1000ull) {
      err << "cia402 master: node " << a.node << ": " << a.command << " did not finish within " << a.timeout_ms
          << " ms (last statusword " << word(m.status_word()) << ")\n";
      break;
    }
    if (m.phase() != canopen::master_phase::running || job_busy) continue;
    if (m.status_known() && m.observed() == state::fault && now >= phase::enable) {
      err << "cia402 master: node " << a.node << " faulted, error code " << hex(m.error_code(), 4) << "\n";
      break;
    }
    const std::uint16_t sw = m.status_word();
    switch (now) {
      case phase::write_before:
        if (next_job < before.size()) {
          run_job(before[next_job++]);
        } else {
          now = phase::confirm_mode;
        }
        break;
      case phase::confirm_mode:
        read_job(0x6061, true, [&](std::int64_t shown) {
          if (shown != wanted_mode) return;  // not switched yet: read again
          event({{"event", "mode"}, {"mode", shown}, {"name", mode::short_name(shown)}},
                std::string("mode ") + std::to_string(shown) + " (" + mode::short_name(shown) + ")");
          if (!moving) {
            status = 0;
            done = true;
            return;
          }
          m.set_target(state::operation_enabled);
          now = phase::enable;
        });
        break;
      case phase::enable:
        if (m.observed() == state::operation_enabled && m.outcome() == master_outcome::reached) {
          now = phase::write_after;
          next_job = 0;
        }
        break;
      case phase::write_after:
        if (next_job < after_enable.size()) {
          run_job(after_enable[next_job++]);
        } else {
          // pp: bit 4 new set-point, 5 change immediately, 6 relative; homing: bit 4 start (5 and 6
          // are reserved there).
          m.set_mode_bits(static_cast<std::uint16_t>(a.command == "move" ? 0x10 | 0x20 | relative : 0x10));
          event({{"event", a.command == "move" ? "setpoint" : "homing_started"}},
                a.command == "move" ? "set-point " + std::to_string(target) + (a.relative ? " (relative)" : "")
                                    : std::string("homing started"));
          now = a.command == "move" ? phase::wait_ack : phase::wait_done;
        }
        break;
      case phase::offer: break;
      case phase::wait_ack:
        if (sw & bit12) {
          m.set_mode_bits(relative);  // bit 4 down: the handshake is done
          now = phase::wait_done;
        }
        break;
      case phase::wait_done:
        if (a.command == "home" && (sw & bit13)) {
          err << "cia402 master: node " << a.node << ": homing error (statusword " << word(sw) << ")\n";
          done = true;
          break;
        }
        if (!(sw & bit10)) seen_busy = true;
        if (a.command == "move" ? (seen_busy && (sw & bit10) && !(sw & bit12))
                                : ((sw & (bit10 | bit12)) == (bit10 | bit12))) {
          m.set_mode_bits(0);
          now = phase::read_position;
        }
        break;
      case phase::read_position:
        read_job(0x6064, true, [&](std::int64_t v) {
          position = v;
          event({{"event", a.command == "move" ? "reached" : "homed"}, {"position", position}},
                (a.command == "move" ? "target reached, position " : "homing attained, position ") +
                    std::to_string(position));
          status = 0;
          done = true;
        });
        break;
    }
  }
  return status;
}

// `csp-stream`: cyclic synchronous position (mode 8) over PDO 3 with SYNC, for tests. Reads the
// position (0x6064) and writes 0x607A = that position before it switches the mode by SDO (confirmed
// by 0x6061): a drive in csp follows 0x607A from its first cycle, and a stale one (a move's target,
// from before a homing run moved the zero) would send it there at full speed. Then it reads the
// encoder resolution (0x608F), enables with the core's master step, then
// before every SYNC moves the set-point RPDO3 carries on by one cycle of a ramp at --velocity until
// --to. TPDO3 brings 0x6064 at every SYNC: the following error is how far it is from the set-point of
// the SYNC before (the one the drive has had a cycle to reach). Done when the position is the target.
int run_csp_stream(bus_session& session, const master_args& a, const profile& p, std::ostream& out,
                   std::ostream& err) {
  if (!a.operands.empty() || !a.stream_to || !a.profile_velocity) {
    err << "cia402 master: csp-stream --to POSITION --velocity RPM [--sync-us US]: no operands, and "
           "both --to and --velocity\n";
    return usage_error;
  }
  if (*a.stream_to < type_low(object_type::integer32) || *a.stream_to > type_high(object_type::integer32)) {
    err << "cia402 master: --to " << *a.stream_to << " does not fit 0x607A (INTEGER32)\n";
    return usage_error;
  }
  const auto to = static_cast<std::int32_t>(*a.stream_to);
  const std::int64_t rpm = *a.profile_velocity;

  canopen::drive_master_config mc;
  mc.node_id = static_cast<std::uint8_t>(a.node);
  mc.cycle_us = a.sync_us;
  mc.drive_heartbeat_ms = a.heartbeat_ms;
  mc.master_heartbeat_ms = a.guard_ms;
  mc.drive_profile = &p;
  mc.map_position = true;
  canopen::drive_master m(session.channel(), mc);
  session.set_sync_period(a.sync_us);
  const node_event event = node_events(a, out);
  print_states(m, event);

  enum class phase { start_position, hold_position, write_mode, confirm_mode, resolution, enable, stream, done };
  phase now = phase::start_position;
  bool job_busy = false;
  bool failed_job = false;
  const auto on_refusal = [&](const std::string& what, const canopen::sdo_result& r) {
    failed_job = true;
    err << "cia402 master: node " << a.node << ": " << what;
    if (r.cancelled) {
      err << " was cancelled (the link to the drive was lost)\n";
    } else {
      err << " refused: SDO abort " << hex(static_cast<std::uint32_t>(r.abort), 8) << " ("
          << sdo_abort_text(r.abort) << ")\n";
    }
  };
  const auto write_job = [&](std::uint16_t index, std::int64_t value, unsigned bytes, std::function<void()> then) {
    job_busy = true;
    const bool queued = m.write(index, 0, value, bytes, [&, index, value, then](const canopen::sdo_result& r) {
      job_busy = false;
      if (!r.ok()) return on_refusal("writing " + hex(index, 4) + " = " + std::to_string(value), r);
      then();
    });
    if (!queued) {
      job_busy = false;
      failed_job = true;
      err << "cia402 master: could not queue the write of " << hex(index, 4) << "\n";
    }
  };
  const auto read_job = [&](std::uint16_t index, std::uint8_t sub, bool is_signed, bool optional,
                            std::function<void(std::optional<std::int64_t>)> use) {
    job_busy = true;
    const bool queued = m.read(index, sub, is_signed, [&, index, sub, optional, use](const canopen::sdo_result& r) {
      job_busy = false;
      if (r.ok()) return use(r.value);
      if (optional && !r.cancelled) return use(std::nullopt);
      on_refusal("reading " + hex(index, 4) + ":" + std::to_string(sub), r);
    });
    if (!queued) {
      job_busy = false;
      failed_job = true;
      err << "cia402 master: could not queue the read of " << hex(index, 4) << "\n";
    }
  };

  // The ramp: set-point k = start + direction x k cycles of travel at rpm, exact in integers (no
  // drift however long), until the target.
  std::int64_t increments = 10000;  // 0x608F sub 1 over sub 2: increments a revolution
  std::int64_t revolutions = 1;
  std::int32_t start = 0;
  std::uint64_t cycles = 0;
  std::uint64_t set_points = 0;
  std::optional<std::int32_t> previous_set_point;  // RPDO3 of the SYNC before the last
  std::int64_t max_error = 0;
  bool all_sent = false;
  const auto ramp_at = [&](std::uint64_t k) {
    const std::int64_t span = std::int64_t{to} - start;
    const std::int64_t distance = span < 0 ? -span : span;
    // rpm x increments x us x k / (60e6 x revolutions), as whole and remainder of one cycle's
    // travel: rpm x increments x us < 2^61 (1e5 x 2^24 x 1e6), the remainder x k stays small
    // because the ramp ends within |distance| / (one cycle's travel) cycles.
    const auto per_cycle = static_cast<std::uint64_t>(rpm) * static_cast<std::uint64_t>(increments) * a.sync_us;
    const std::uint64_t divisor = 60'000'000ull * static_cast<std::uint64_t>(revolutions);
    const std::uint64_t whole = per_cycle / divisor * k;
    if (whole >= static_cast<std::uint64_t>(distance)) return to;
    const auto travel = static_cast<std::int64_t>(whole + per_cycle % divisor * k / divisor);
    if (travel >= distance) return to;
    return static_cast<std::int32_t>(start + (span < 0 ? -travel : travel));
  };
  m.before_sync = [&] {
    previous_set_point = m.position_set_point();
    if (now != phase::stream || all_sent) return;
    const std::int32_t sp = ramp_at(++cycles);
    m.set_position_set_point(sp);
    ++set_points;
    all_sent = sp == to;
  };
  m.on_position = [&](std::int32_t actual) {
    if (now != phase::stream || !previous_set_point) return;
    max_error = std::max<std::int64_t>(max_error, std::abs(std::int64_t{actual} - *previous_set_point));
  };

  constexpr std::uint16_t bit12 = 1u << 12, bit13 = 1u << 13;
  stop_requested = 0;
  int status = failed;
  std::uint64_t elapsed = 0;
  std::uint32_t next = 0;
  while (now != phase::done) {
    if (stop_requested != 0) {
      err << "cia402 master: interrupted\n";
      break;
    }
    if (const auto ec = session.failure()) {
      err << "cia402 master: the bus connection failed: " << ec.message() << "\n";
      break;
    }
    elapsed += session.pump(m, next);
    if (m.phase() == canopen::master_phase::failed) {
      err << "cia402 master: " << m.failure_text() << "\n";
      break;
    }
    if (failed_job) break;
    if (a.timeout_ms != 0 && elapsed >= a.timeout_ms * 1000ull) {
      err << "cia402 master: node " << a.node << ": csp-stream did not finish within " << a.timeout_ms
          << " ms (last statusword " << word(m.status_word());
      if (m.position()) err << ", position " << *m.position();
      if (m.position_set_point()) err << ", set-point " << *m.position_set_point();
      err << ")\n";
      break;
    }
    if (m.phase() != canopen::master_phase::running || job_busy) continue;
    if (m.status_known() && m.observed() == state::fault && now >= phase::enable) {
      err << "cia402 master: node " << a.node << " faulted, error code " << hex(m.error_code(), 4);
      if (m.error_code() == 0x8611) err << " (following error: 0x6065 / 0x6066 exceeded)";
      err << "; max following error seen " << max_error << " increments\n";
      break;
    }
    switch (now) {
      case phase::write_mode:
        write_job(0x6060, mode::cyclic_synchronous_position, 1, [&] { now = phase::confirm_mode; });
        break;
      case phase::confirm_mode:
        read_job(0x6061, 0, true, false, [&](std::optional<std::int64_t> shown) {
          if (shown != mode::cyclic_synchronous_position) return;  // not switched yet: read again
          event({{"event", "mode"}, {"mode", *shown}, {"name", mode::short_name(static_cast<std::int8_t>(*shown))}},
                "mode " + std::to_string(*shown) + " (" + mode::short_name(static_cast<std::int8_t>(*shown)) + ")");
          now = phase::resolution;
        });
        break;
      case phase::resolution:
        // 0x608F is optional: without it, 10,000 increments a revolution.
        read_job(0x608F, 1, false, true, [&](std::optional<std::int64_t> v) {
          if (v && *v > 0) increments = std::min<std::int64_t>(*v, std::int64_t{1} << 26);
          read_job(0x608F, 2, false, true, [&](std::optional<std::int64_t> r) {
            if (r && *r > 0) revolutions = *r;
            m.set_target(state::operation_enabled);
            now = phase::enable;
          });
        });
        break;
      case phase::start_position:
        read_job(0x6064, 0, true, false, [&](std::optional<std::int64_t> v) {
          start = static_cast<std::int32_t>(*v);
          now = phase::hold_position;
        });
        break;
      case phase::hold_position:
        // Where it stands, so neither the switch to csp nor enabling moves it; RPDO3 keeps saying so
        // until the stream starts.
        write_job(0x607A, start, 4, [&] {
          m.set_position_set_point(start);
          now = phase::write_mode;
        });
        break;
      case phase::enable:
        if (m.observed() == state::operation_enabled && m.outcome() == master_outcome::reached &&
            (m.status_word() & bit12)) {
          event({{"event", "stream_started"}, {"from", start}, {"to", to}, {"velocity_rpm", rpm},
                 {"sync_us", a.sync_us}},
                "streaming 0x607A from " + std::to_string(start) + " to " + std::to_string(to) + " at " +
                    std::to_string(rpm) + " rpm by RPDO3, SYNC every " + std::to_string(a.sync_us) + " us");
          now = phase::stream;
        }
        break;
      case phase::stream:
        if (m.status_word() & bit13) {
          err << "cia402 master: node " << a.node << ": following error (statusword " << word(m.status_word())
              << ", max following error seen " << max_error << " increments)\n";
          now = phase::done;
          break;
        }
        if (all_sent && m.position() == to) {
          event({{"event", "streamed"}, {"position", *m.position()}, {"set_points", set_points},
                 {"max_following_error", max_error}},
                "reached " + std::to_string(*m.position()) + " after " + std::to_string(set_points) +
                    " set-points, max following error " + std::to_string(max_error) + " increments");
          status = 0;
          now = phase::done;
        }
        break;
      case phase::done: break;
    }
  }
  return status;
}

}  // namespace

CLI::App* add_master_subcommand(CLI::App& app, master_args& args) {
  auto* cmd = app.add_subcommand(
      "master",
      "Drive one CiA 402 drive over CANopen (NMT start, PDO set-up over SDO, then the master step over "
      "PDOs with SYNC), or the drives of an EtherCAT line with --ecat (scan, SII, OP, the master step over "
      "a cyclic LRW)");
  auto* can = cmd->add_option("--can", args.can,
                              "socketcand://HOST:PORT/BUS, socketcan://IFACE, or virtual (a virtual drive in-process)")
                   ->default_str("virtual");
  cmd->add_option("--ecat", args.ecat,
                  "a network interface: run our EtherCAT master there (raw socket, root) instead of CANopen; "
                  "COMMAND OPERANDS are then steps run in order: state, enable, disable, quick-stop, reset, "
                  "watch, wait MS, sdo read|write")
      ->excludes(can);
  cmd->add_option("--position", args.position, "--ecat: the drive's position on the line, 0 first (default: all)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--node", args.node, "the drive's node-ID")->check(CLI::Range(1, 127))->default_str("1");
  cmd->add_option("COMMAND", args.command,
                  "state, enable, disable, quick-stop, reset, watch, velocity, mode, move, home, csp-stream; "
                  "sdo, nmt (no set-up)")
      ->required()
      ->check(CLI::IsMember({"state", "enable", "disable", "quick-stop", "reset", "watch", "velocity", "mode",
                             "move", "home", "csp-stream", "sdo", "nmt"}));
  cmd->add_option("OPERANDS", args.operands,
                  "velocity RPM | mode pp|pv|tq|hm|csp|csv|cst | move POSITION | sdo read INDEX[:SUB] | "
                  "sdo write INDEX[:SUB] VALUE | "
                  "nmt start|stop|preop|reset");
  cmd->add_flag("--json", args.json,
                "one JSON object a line: state and sdo print one, the others one per event");
  add_profile_options(*cmd, args.profile, args.profile_file, "the drive's profile");
  cmd->add_option("--cycle", args.cycle_ms, "SYNC period in ms")->check(CLI::Range(1, 1000))->default_str("10");
  cmd->add_option("--timeout", args.timeout_ms, "give up after this many ms (watch: stop after it; 0 = never)")
      ->default_str("10000");
  cmd->add_option("--heartbeat", args.heartbeat_ms, "the drive's heartbeat period in ms, watched (0 = off)")
      ->default_str("100");
  cmd->add_option("--guard", args.guard_ms,
                  "send the master's heartbeat at this period in ms and have the drive watch it, so "
                  "0x6007 acts if the master stops (0 = off)")
      ->default_str("0");
  cmd->add_flag("--relative", args.relative, "move: POSITION adds to the last target (control-word bit 6)");
  cmd->add_option("--velocity", args.profile_velocity,
                  "move: the profile velocity 0x6081 in rpm; csp-stream: the ramp's speed in rpm")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--to", args.stream_to, "csp-stream: the position the ramp of 0x607A ends at, in increments");
  cmd->add_option("--sync-us", args.sync_us, "csp-stream: SYNC period in microseconds (one set-point each); --ecat: the cycle (one LRW each)")
      ->check(CLI::Range(100, 1000000))
      ->default_str("1000");
  cmd->add_option("--method", args.homing_method, "home: the homing method 0x6098 (3, 33, 34, 35, 37)");
  cmd->add_option("--offset", args.home_offset, "home: the home offset 0x607C, in increments");
  cmd->add_flag("--hold", args.hold, "after reaching the target, keep the drive there until SIGINT");
  return cmd;
}

int run_master(const master_args& a, std::ostream& out, std::ostream& err) {
  if (!a.ecat.empty()) return run_ecat_master(a, out, err);
  profile_choice choice;
  if (!choice.resolve(a.profile, a.profile_file, err)) return usage_error;
  const profile& p = choice.get();
  bus_session session;
  if (!session.open(a, p, err)) return session.open_failed_ ? failed : usage_error;
  if (a.command == "state") return read_state(session, a, p, out, err);
  if (a.command == "sdo") return run_sdo(session, a, out, err);
  if (a.command == "nmt") return run_nmt(session, a, out, err);
  if (a.command == "mode" || a.command == "move" || a.command == "home") {
    return run_motion(session, a, p, out, err);
  }
  if (a.command == "csp-stream") return run_csp_stream(session, a, p, out, err);
  const bool velocity_command = a.command == "velocity";
  std::int32_t rpm = 0;
  if (velocity_command) {
    const auto v = a.operands.size() == 1 ? parse_number(a.operands[0]) : std::nullopt;
    const object_description* target = find_drive_object(0x60FF, 0);
    // value_or: GCC 12 -O3 takes *v after the !v test for a read of an unset optional.
    const std::int64_t value = v.value_or(0);
    if (!v || target == nullptr || value < type_low(target->type) || value > type_high(target->type)) {
      err << "cia402 master: velocity RPM: one integer for 0x60FF (target velocity, rpm)\n";
      return usage_error;
    }
    rpm = static_cast<std::int32_t>(value);
  } else if (!a.operands.empty()) {
    err << "cia402 master: " << a.command << " takes no operands\n";
    return usage_error;
  }
  if (a.command == "reset") {
    // Look before touching: a drive that is not faulted keeps its PDOs and NMT state.
    std::uint16_t sw = 0;
    std::uint16_t code = 0;
    if (!read_status(session, a, sw, code, err)) return failed;
    state s = state::start;
    if (!decode_status(p, sw, s) || (s != state::fault && s != state::fault_reaction_active)) {
      out << describe(p, a.node, sw, code) << ": not in FAULT, nothing to reset\n";
      return 0;
    }
  }

  canopen::drive_master_config mc;
  mc.node_id = static_cast<std::uint8_t>(a.node);
  mc.cycle_us = a.cycle_ms * 1000;
  mc.drive_heartbeat_ms = a.heartbeat_ms;
  mc.master_heartbeat_ms = a.guard_ms;
  mc.drive_profile = &p;
  // `velocity` reports the actual velocity it reached; `watch` shows it as it changes.
  mc.map_velocity = velocity_command || a.command == "watch";
  canopen::drive_master m(session.channel(), mc);
  // One line per event: prose, or with --json one JSON object.
  const node_event event = node_events(a, out);
  print_states(m, event);
  m.on_emcy = [&](std::uint16_t code, std::uint8_t reg, const std::uint8_t*) {
    event({{"event", "emcy"}, {"error_code", hex(code, 4)}, {"error_register", hex(reg, 2)}},
          "EMCY " + hex(code, 4) + " error register " + hex(reg, 2) +
              (code == 0 ? " (error reset)" : ""));
  };
  const bool watching = a.command == "watch";
  if (watching) {
    // A line when the velocity moved by 10 rpm or more since the last one, or stopped: not one
    // per PDO while it ramps.
    m.on_velocity = [&, shown = std::optional<std::int32_t>()](std::int32_t v) mutable {
      if (shown && std::abs(std::int64_t{v} - *shown) < 10 && v != 0) return;
      if (shown && *shown == v) return;
      shown = v;
      event({{"event", "velocity"}, {"velocity_rpm", v}}, "velocity " + std::to_string(v) + " rpm");
    };
  }
  bool velocity_written = false;
  bool velocity_requested = false;
  if (a.command == "enable" || velocity_command) m.set_target(state::operation_enabled);
  if (a.command == "disable") m.set_target(state::switch_on_disabled);
  bool reset_decided = false;  // reset acts only on a drive seen in FAULT (T15)
  if (a.command == "quick-stop") m.set_command(command::quick_stop);

  stop_requested = 0;
  struct sigaction action {};
  action.sa_handler = request_master_stop;
  sigemptyset(&action.sa_mask);
  struct sigaction old_int {}, old_term {};
  sigaction(SIGINT, &action, &old_int);
  sigaction(SIGTERM, &action, &old_term);

  int status = failed;
  bool reported_running = false;
  std::uint64_t elapsed = 0;
  std::uint32_t next = 0;
  for (;;) {
    if (stop_requested == 1) {
      status = watching || a.hold ? 0 : failed;
      if (status != 0) err << "cia402 master: interrupted\n";
      break;
    }
    if (const auto ec = session.failure()) {
      err << "cia402 master: the bus connection failed: " << ec.message() << "\n";
      break;
    }
    elapsed += session.pump(m, next);

    if (m.phase() == canopen::master_phase::failed) {
      err << "cia402 master: " << m.failure_text() << "\n";
      break;
    }
    if (m.phase() == canopen::master_phase::running && !reported_running) {
      reported_running = true;
      event({{"event", "started"}, {"sync_ms", a.cycle_ms}},
            "configured and started (TPDO1 = statusword, RPDO1 = controlword, SYNC every " +
                std::to_string(a.cycle_ms) + " ms)");
    }
    // After T4: entering OPERATION ENABLED clears the set-points on some profiles (002's T4).
    if (velocity_command && !velocity_requested && m.phase() == canopen::master_phase::running &&
        m.status_known() && m.observed() == state::operation_enabled) {
      velocity_requested = true;
      const bool queued = m.write(0x60FF, 0, rpm, 4, [&](const canopen::sdo_result& r) {
        if (r.ok()) {
          velocity_written = true;
          event({{"event", "target_velocity"}, {"velocity_rpm", rpm}},
                "0x60FF target velocity = " + std::to_string(rpm) + " rpm");
        } else {
          err << "cia402 master: node " << a.node << ": writing 0x60FF = " << rpm;
          if (r.cancelled) {
            err << " was cancelled (the link to the drive was lost)\n";
          } else {
            err << " refused: SDO abort " << hex(static_cast<std::uint32_t>(r.abort), 8) << " ("
                << sdo_abort_text(r.abort) << ")\n";
          }
          stop_requested = 2;
        }
      });
      if (!queued) {
        err << "cia402 master: could not queue the write of 0x60FF\n";
        break;
      }
    }
    if (stop_requested == 2) break;
    if (a.timeout_ms != 0 && elapsed >= a.timeout_ms * 1000ull) {
      if (watching) {
        status = 0;
      } else {
        err << "cia402 master: node " << a.node << " did not get there within " << a.timeout_ms
            << " ms (last seen " << state_name(m.observed());
        if (m.error_code() != 0) err << ", error code " << hex(m.error_code(), 4);
        if (m.observed() == state::fault) err << "; is the fault cause still present?";
        err << ")\n";
      }
      break;
    }
    if (watching || !m.status_known()) continue;
    if (a.command == "reset" && !reset_decided) {
      reset_decided = true;
      const state s = m.observed();
      if (s != state::fault && s != state::fault_reaction_active) {
        event({{"event", "nothing_to_reset"}, {"state", state_name(s)}},
              std::string("not in FAULT (") + state_name(s) + "), nothing to reset");
        status = 0;
        break;
      }
      m.set_target(state::switch_on_disabled);
      continue;
    }
    if (a.command == "quick-stop") {
      // Done when the stop has ended as 0x605A says (S5): 1..4 in SWITCH ON DISABLED (T12), 5..8 in
      // QUICK STOP ACTIVE at standstill (bit 10), 0 in QUICK STOP ACTIVE (coasting). A drive that was
      // not running goes to SWITCH ON DISABLED at once (T7, T10).
      const state s = m.observed();
      const int code = m.option_code(option::quick_stop);
      const bool held = s == state::quick_stop_active &&
                        (code == 0 || (code >= 5 && (m.status_word() & status_bit::target_reached)));
      if (status != 0 && (held || s == state::switch_on_disabled)) {
        event({{"event", "quick_stop_done"}, {"state", state_name(s)}},
              std::string("quick stop done, ") + state_name(s));
        status = 0;
        if (!a.hold) break;
      }
      continue;
    }
    switch (m.outcome()) {
      case master_outcome::reached:
        if (velocity_command) {
          // Reached when the actual velocity is within 1 % (at least 1 rpm) of the target.
          const auto v = m.velocity();
          const std::int64_t tolerance = std::max<std::int64_t>(1, std::abs(std::int64_t{rpm}) / 100);
          if (!velocity_written || !v || std::abs(std::int64_t{*v} - rpm) > tolerance) break;
          if (status != 0) {
            event({{"event", "reached"}, {"state", state_name(m.observed())}, {"velocity_rpm", *v}},
                  "running at " + std::to_string(*v) + " rpm in " + state_name(m.observed()));
          }
        } else if (status != 0) {
          event({{"event", "reached"}, {"state", state_name(m.observed())}},
                std::string("reached ") + state_name(m.observed()));
        }
        status = 0;
        if (!a.hold) goto done;
        break;
      case master_outcome::fault:
        err << "cia402 master: node " << a.node << " faulted, error code " << hex(m.error_code(), 4) << "\n";
        status = failed;
        goto done;
      case master_outcome::timed_out:
        err << "cia402 master: node " << a.node << ": transition T" << int(m.core_master().transition())
            << " did not happen in time (in " << state_name(m.observed());
        if (m.error_code() != 0) err << ", error code " << hex(m.error_code(), 4);
        if (m.observed() == state::fault) err << "; is the fault cause still present?";
        err << ")\n";
        status = failed;
        goto done;
      case master_outcome::unreachable:
        err << "cia402 master: node " << a.node << ": no command sequence leads from "
            << state_name(m.observed()) << " to the target in profile " << p.name << "\n";
        status = failed;
        goto done;
      case master_outcome::not_remote:
      case master_outcome::bad_status_word:
      case master_outcome::idle:
      case master_outcome::in_progress: break;
    }
  }
done:
  if (a.guard_ms != 0 && m.phase() == canopen::master_phase::running) {
    // Left armed, the drive would watch a master that is gone and apply 0x6007 (a fault, by
    // default) a few heartbeats after this process ends.
    bool ended = false;
    bool cleared = false;
    (void)m.write(0x1016, 1, 0, 4, [&](const canopen::sdo_result& r) {
      ended = true;
      cleared = r.ok();
    });
    for (std::uint64_t waited = 0; !ended && waited < 2000000 && !session.failure();) {
      waited += session.pump(m, next);
    }
    if (cleared) {
      out << "node " << a.node << ": no longer watching this master (0x1016 sub 1 = 0)\n";
    } else {
      err << "cia402 master: node " << a.node << " may still watch this master's heartbeat: "
          << "clearing 0x1016 sub 1 failed; any master command without --guard clears it\n";
      status = failed;
    }
  }
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  return status;
}

}  // namespace cia402::cli
