#include "cia402/page/remote_drive.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "cia402/canopen/drive_objects.hpp"
#include "cia402/canopen/frame.hpp"
#include "cia402/canopen/nmt.hpp"
#include "cia402/canopen/pdo.hpp"
#include "cia402/canopen/sdo_client.hpp"
#include "cia402/canopen/timing.hpp"
#include "cia402/master.hpp"
#include "cia402/objects.hpp"
#include "cia402/page/transition_inference.hpp"
#include "cia402/words.hpp"
#include "action_log.hpp"
#include "page_json.hpp"
#include "page_names.hpp"
#include "snapshot_board.hpp"
#include "word_change.hpp"

namespace cia402::page {
namespace {

namespace co = cia402::canopen;
using json = nlohmann::ordered_json;
using detail::abort_text;
using detail::hex;

constexpr std::uint16_t bit7 = control_bit::fault_reset;
constexpr const char* not_remote = "not available on a remote drive";

// The objects the page writes on a remote drive: the writable ones of the one object table, but
// the control word, which commands and bit toggles set. The CANopen download needs their sizes, and
// a value outside the type is refused here rather than cut to fit.
const object_description* type_of(std::uint16_t index) {
  const object_description* o = find_drive_object(index);
  if (o == nullptr || o->access != object_access::read_write || index == 0x6040) return nullptr;
  return o;
}

// Nothing if the value fits the object's type, else the abort code the drive would give.
std::optional<sdo_abort> out_of_type(const object_description& t, std::int64_t v) {
  if (v < type_low(t.type)) return sdo_abort::value_too_low;
  if (v > type_high(t.type)) return sdo_abort::value_too_high;
  return std::nullopt;
}

// An HTTP request waiting for its SDO transfer.
struct user_wait {
  bool done = false;
  bool cancelled = false;  // the link was lost before the transfer ran
  sdo_abort abort = sdo_abort::none;
  // A plant change is tracked from the moment the drive accepted it (in the cycle thread), so the
  // transitions it causes are its own even when they arrive in the same batch of frames.
  std::optional<std::string> track_action;
  std::uint64_t id = 0;
};

struct sdo_job {
  bool write = false;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::function<std::int64_t()> value;  // evaluated when the transfer starts
  unsigned bytes = 0;
  bool is_signed = false;
  bool optional = false;  // set-up: a refusal does not end it (a timeout does)
  int group = 0;          // set-up: a refusal skips the rest of the group
  std::function<bool()> wanted;  // set-up: the job runs only if this says so
  std::function<void(const co::sdo_client&)> then;  // after a done transfer (or an optional abort)
  std::shared_ptr<user_wait> waiter;
  bool nmt_start = false;  // not a transfer: NMT start, then running
};

struct transition_seen {
  std::optional<int> number;  // none: no chain of rows connects the two states
  state from = state::start;
  state to = state::start;
};

enum class heartbeat_event : std::uint8_t { none, lost, back };

}  // namespace

const char* remote_status_name(remote_status s) noexcept {
  switch (s) {
    case remote_status::configuring: return "configuring";
    case remote_status::running: return "running";
    case remote_status::no_answer: return "no_answer";
    case remote_status::refused: return "refused";
    case remote_status::bus_failed: return "bus_failed";
  }
  return "unknown";
}

struct remote_drive::impl {
  impl(const profile& p, co::channel& b, const remote_config& c)
      : table(p),
        bus(b),
        config(c),
        sdo(b, c.node_id, c.sdo_timeout_us),
        log({c.results_kept, c.settle_quiet_us, c.settle_limit_us,
             "still busy when the page stopped waiting", " (numbers inferred)"},
            [this] { return how_it_stands(); }) {
    if (config.cycle_us == 0) config.cycle_us = 1000;
    if (config.publish_us == 0) config.publish_us = config.cycle_us;
    consumer.on_change = [this](std::uint8_t, bool lost) {
      hb_event = lost ? heartbeat_event::lost : heartbeat_event::back;
    };
    build_setup();
    restart_setup("configuring node " + node_text());
  }

  const profile& table;
  co::channel& bus;
  remote_config config;

  mutable std::mutex mutex;  // guards all here but the board, which has a lock of its own
  std::condition_variable job_done;

  co::sdo_client sdo;
  std::optional<sdo_job> current;
  std::vector<sdo_job> setup;
  std::size_t setup_step = 0;
  int skipped_group = 0;
  std::deque<sdo_job> user_jobs;
  co::heartbeat_consumer consumer;
  heartbeat_event hb_event = heartbeat_event::none;

  remote_status status = remote_status::configuring;
  std::string status_text;
  std::uint64_t now_us = 0;
  std::uint64_t retry_at_us = 0;
  std::uint64_t next_poll_us = 0;
  std::size_t poll_index = 0;
  std::uint64_t next_publish_us = 0;

  // What set-up found out.
  std::string device_name;
  bool fault_injection = false;
  bool error_mapped = false;
  bool velocity_mapped = false;
  bool heartbeat_watched = false;
  std::optional<std::uint8_t> nmt_seen;

  // What the drive reports.
  bool status_known = false;
  std::uint16_t status_word = 0;
  bool state_known = false;
  state observed = state::start;
  std::uint16_t error_code = 0;
  std::uint8_t error_register = 0;
  std::optional<std::int32_t> velocity;
  std::int32_t target_velocity = 0;
  std::optional<std::uint16_t> last_emcy;
  std::uint16_t injected_fault = 0;  // what the page wrote to 0x2001 (0: none)
  std::map<std::uint16_t, std::int64_t> objects;
  std::optional<transition_seen> last_transition;

  // What the page sends.
  std::uint16_t control_word = 0;
  std::uint16_t last_sent = 0;
  bool reset_sent_since_change = false;
  std::deque<std::pair<std::uint16_t, std::uint64_t>> outbox;  // word, not before (us)

  detail::action_log log;
  detail::snapshot_board board;

  // --- set-up ---------------------------------------------------------------------------------

  std::string node_text() const { return "node " + std::to_string(config.node_id); }

  static sdo_job read(std::uint16_t index, std::uint8_t sub, bool optional, bool is_signed = false) {
    sdo_job j;
    j.index = index;
    j.sub = sub;
    j.optional = optional;
    j.is_signed = is_signed;
    return j;
  }
  static sdo_job write(std::uint16_t index, std::uint8_t sub, std::int64_t value, unsigned bytes,
                       int group = 0) {
    sdo_job j;
    j.write = true;
    j.index = index;
    j.sub = sub;
    j.value = [value] { return value; };
    j.bytes = bytes;
    j.group = group;
    j.optional = group != 0;
    return j;
  }

  // A `then` for an optional step of set-up: whether it worked decides what comes later.
  static std::function<void(const co::sdo_client&)> note_done(bool& worked) {
    return [&worked](const co::sdo_client& c) {
      worked = c.state() == co::sdo_client::status::done;
    };
  }

  void build_setup() {
    const std::uint8_t node = config.node_id;
    sdo_job type = read(0x1000, 0, false);
    type.then = [this](const co::sdo_client& c) {
      if ((c.value() & 0xFFFF) != 0x0192) {
        refuse_setup(node_text() + " is not a CiA 402 drive (0x1000 = " +
                     hex(static_cast<std::uint32_t>(c.value()), 8) +
                     ", low word not 0x0192)");
      }
    };
    setup.push_back(type);

    sdo_job name = read(0x1008, 0, true);
    name.then = [this](const co::sdo_client& c) {
      if (c.state() == co::sdo_client::status::done) {
        device_name.assign(c.data().begin(), c.data().end());
        while (!device_name.empty() && device_name.back() == '\0') device_name.pop_back();
      }
    };
    setup.push_back(name);

    // 0x2001 exists on a `cia402 bus` node as write-only: reading it says so and changes nothing.
    sdo_job probe = read(co::fault_injection_index, 0, true);
    probe.wanted = [this] { return device_name == co::virtual_drive_device_name; };
    probe.then = [this](const co::sdo_client& c) {
      fault_injection = c.state() == co::sdo_client::status::aborted &&
                        c.abort_code() == sdo_abort::write_only_object;
    };
    setup.push_back(probe);

    for (const object_name& o : object_names(table)) {
      const object_description* t = find_drive_object(o.index);
      sdo_job j = read(o.index, 0, true, t != nullptr && type_signed(t->type));
      const std::uint16_t index = o.index;
      j.then = [this, index](const co::sdo_client& c) {
        if (c.state() == co::sdo_client::status::done) {
          const object_description* ty = find_drive_object(index);
          objects[index] = c.value(ty != nullptr && type_signed(ty->type));
        } else {
          objects.erase(index);
        }
      };
      setup.push_back(j);
    }

    sdo_job cw = read(0x6040, 0, true);
    cw.then = [this](const co::sdo_client& c) {
      if (c.state() != co::sdo_client::status::done) return;
      control_word = static_cast<std::uint16_t>(c.value());
      last_sent = control_word;
    };
    setup.push_back(cw);

    if (config.heartbeat_ms != 0) {
      sdo_job hb = write(0x1017, 0, config.heartbeat_ms, 2, 1);
      hb.then = note_done(heartbeat_watched);
      setup.push_back(hb);
    }

    // TPDO1: status word (+ error code), on every change.
    const std::int64_t tpdo1 = co::cob::tpdo1 + node;
    setup.push_back(write(0x1800, 1, co::pdo_cob_invalid | tpdo1, 4));
    setup.push_back(write(0x1A00, 0, 0, 1));
    setup.push_back(write(0x1A00, 1, 0x60410010, 4));
    sdo_job err_entry = write(0x1A00, 2, 0x603F0010, 4);
    err_entry.optional = true;
    err_entry.then = note_done(error_mapped);
    setup.push_back(err_entry);
    sdo_job count = write(0x1A00, 0, 0, 1);
    count.value = [this] { return std::int64_t{error_mapped ? 2 : 1}; };
    setup.push_back(count);
    setup.push_back(write(0x1800, 2, 255, 1));
    setup.push_back(write(0x1800, 3, 0, 2, 2));  // no inhibit time: every state arrives
    setup.push_back(write(0x1800, 1, tpdo1, 4));

    // TPDO2: actual velocity, on change, at most every velocity_inhibit. Optional as a whole.
    const std::int64_t tpdo2 = co::cob::tpdo1 + 0x100 + node;
    constexpr int velocity_group = 3;
    setup.push_back(write(0x1801, 1, co::pdo_cob_invalid | tpdo2, 4, velocity_group));
    setup.push_back(write(0x1A01, 0, 0, 1, velocity_group));
    setup.push_back(write(0x1A01, 1, 0x606C0020, 4, velocity_group));
    setup.push_back(write(0x1A01, 0, 1, 1, velocity_group));
    setup.push_back(write(0x1801, 2, 255, 1, velocity_group));
    setup.push_back(write(0x1801, 3, config.velocity_inhibit_100us, 2, velocity_group));
    sdo_job enable2 = write(0x1801, 1, tpdo2, 4, velocity_group);
    enable2.then = note_done(velocity_mapped);
    setup.push_back(enable2);

    // RPDO1: the control word, acting on receipt.
    const std::int64_t rpdo1 = co::cob::rpdo1 + node;
    setup.push_back(write(0x1400, 1, co::pdo_cob_invalid | rpdo1, 4));
    setup.push_back(write(0x1600, 0, 0, 1));
    setup.push_back(write(0x1600, 1, 0x60400010, 4));
    setup.push_back(write(0x1600, 0, 1, 1));
    setup.push_back(write(0x1400, 2, 255, 1));
    setup.push_back(write(0x1400, 1, rpdo1, 4));

    // The drive's present values last, just before NMT start, so the page starts from them.
    sdo_job target = read(0x60FF, 0, true, true);
    target.then = [this](const co::sdo_client& c) {
      if (c.state() == co::sdo_client::status::done) {
        target_velocity = static_cast<std::int32_t>(c.value(true));
      }
    };
    setup.push_back(target);

    sdo_job sw = read(0x6041, 0, false);
    sw.then = [this](const co::sdo_client& c) { on_status(static_cast<std::uint16_t>(c.value())); };
    setup.push_back(sw);

    sdo_job err = read(0x603F, 0, true);
    err.then = [this](const co::sdo_client& c) {
      if (c.state() == co::sdo_client::status::done) {
        error_code = static_cast<std::uint16_t>(c.value());
      }
    };
    setup.push_back(err);

    sdo_job vel = read(0x606C, 0, true, true);
    vel.then = [this](const co::sdo_client& c) {
      if (c.state() == co::sdo_client::status::done) {
        on_velocity(static_cast<std::int32_t>(c.value(true)));
      }
    };
    setup.push_back(vel);

    sdo_job start;
    start.nmt_start = true;
    setup.push_back(start);
  }

  // Drops the transfer in flight and every queued request, as when the link goes.
  void drop_jobs() {
    if (current) {
      if (sdo.state() == co::sdo_client::status::busy) sdo.cancel();
      if (current->waiter) current->waiter->cancelled = current->waiter->done = true;
      current.reset();
    }
    sdo.clear();
    for (sdo_job& j : user_jobs) {
      if (j.waiter) j.waiter->cancelled = j.waiter->done = true;
    }
    user_jobs.clear();
    job_done.notify_all();
  }

  void restart_setup(std::string why) {
    drop_jobs();
    status = remote_status::configuring;
    status_text = std::move(why);
    setup_step = 0;
    skipped_group = 0;
    device_name.clear();
    fault_injection = false;
    error_mapped = false;
    velocity_mapped = false;
    heartbeat_watched = false;
    consumer.configure({});
    hb_event = heartbeat_event::none;
    outbox.clear();
  }

  // The node went silent (or its set-up failed): nothing is known about it until set-up ran again.
  void stop_link(remote_status s, std::string why) {
    drop_jobs();
    status = s;
    status_text = std::move(why);
    retry_at_us = now_us + config.retry_us;
    state_known = false;
    outbox.clear();
    consumer.configure({});
    hb_event = heartbeat_event::none;
    log.finish_pending(status_text.c_str());
  }

  void lose(std::string why) { stop_link(remote_status::no_answer, std::move(why)); }
  void refuse_setup(std::string why) { stop_link(remote_status::refused, std::move(why)); }

  void go_running() {
    status = remote_status::running;
    status_text.clear();
    if (heartbeat_watched) {
      consumer.configure({{config.node_id, static_cast<std::uint16_t>(std::min<std::uint32_t>(
                                               3u * config.heartbeat_ms, 0xFFFF))}});
    }
    next_poll_us = now_us + config.poll_us;
  }

  std::string object_text(const sdo_job& j) const {
    return hex(j.index, 4) + ":" + std::to_string(j.sub);
  }

  // --- SDO jobs -------------------------------------------------------------------------------

  void start_transfer(const sdo_job& j) {
    sdo.clear();
    if (j.write) {
      (void)sdo.start_download(j.index, j.sub, j.value(), j.bytes);
    } else {
      (void)sdo.start_upload(j.index, j.sub);
    }
  }

  std::optional<sdo_job> next_poll() {
    // What no PDO carries, one object per poll period in turn.
    std::vector<std::uint16_t> list{0x1001};
    if (!velocity_mapped) list.push_back(0x606C);
    if (!error_mapped) list.push_back(0x603F);
    if (!heartbeat_watched) list.push_back(0x6041);
    const std::uint16_t index = list[poll_index++ % list.size()];
    sdo_job j = read(index, 0, true, index == 0x606C);
    j.then = [this, index](const co::sdo_client& c) {
      if (c.state() != co::sdo_client::status::done) return;
      switch (index) {
        case 0x1001: error_register = static_cast<std::uint8_t>(c.value()); break;
        case 0x606C: on_velocity(static_cast<std::int32_t>(c.value(true))); break;
        case 0x603F: error_code = static_cast<std::uint16_t>(c.value()); break;
        case 0x6041: on_status(static_cast<std::uint16_t>(c.value())); break;
        default: break;
      }
    };
    return j;
  }

  bool start_next_job() {
    if (status == remote_status::configuring) {
      while (status == remote_status::configuring && setup_step < setup.size()) {
        const sdo_job& j = setup[setup_step];
        if ((j.group != 0 && j.group == skipped_group) || (j.wanted && !j.wanted())) {
          ++setup_step;
          continue;
        }
        if (j.nmt_start) {
          ++setup_step;
          (void)bus.send(co::nmt_frame(co::nmt_command::start, config.node_id));
          go_running();
          return false;
        }
        current = j;
        start_transfer(*current);
        return true;
      }
      return false;
    }
    if (status != remote_status::running) return false;
    if (!user_jobs.empty()) {
      current = std::move(user_jobs.front());
      user_jobs.pop_front();
      start_transfer(*current);
      return true;
    }
    if (now_us >= next_poll_us) {
      next_poll_us = now_us + config.poll_us;
      current = next_poll();
      start_transfer(*current);
      return true;
    }
    return false;
  }

  void complete_current() {
    sdo_job job = std::move(*current);
    current.reset();
    const bool ok = sdo.state() == co::sdo_client::status::done;
    const sdo_abort abort = ok ? sdo_abort::none : sdo.abort_code();
    const bool timed_out = abort == sdo_abort::sdo_protocol_timed_out;
    const std::string what = std::string(job.write ? "writing " : "reading ") + object_text(job);

    if (job.waiter) {
      job.waiter->done = true;
      job.waiter->abort = abort;
      if (ok && job.then) job.then(sdo);
      if (ok && job.waiter->track_action) job.waiter->id = track(*job.waiter->track_action, false);
      job_done.notify_all();
      // A node that lets an SDO request time out is silent, whatever its heartbeat did last.
      if (timed_out) lose(node_text() + " does not answer (SDO timeout " + what + ")");
      return;
    }
    if (status == remote_status::running) {  // a poll
      if (job.then) job.then(sdo);
      if (timed_out) lose(node_text() + " does not answer (SDO timeout " + what + ")");
      return;
    }
    if (status != remote_status::configuring) return;
    if (timed_out) {
      lose(node_text() + " does not answer (SDO timeout " + what + ")");
      return;
    }
    if (!ok && !job.optional) {
      refuse_setup(node_text() + " refused " + what + ": " + abort_text(abort));
      return;
    }
    if (!ok && job.group != 0) skipped_group = job.group;
    if (job.then) job.then(sdo);
    ++setup_step;
  }

  void drive_jobs() {
    for (int guard = 0; guard < 64; ++guard) {
      if (!current && !start_next_job()) return;
      if (!current || !sdo.finished()) return;
      complete_current();
    }
  }

  // --- what the drive reports -------------------------------------------------------------------

  void on_status(std::uint16_t sw) {
    status_known = true;
    status_word = sw;
    state s = state::start;
    if (!decode_status(table, sw, s)) {
      state_known = false;
      return;
    }
    if (state_known && s != observed) {
      const std::vector<inferred_transition> chain = infer_transitions(
          table, observed, s, observer_facts(table, last_sent, reset_sent_since_change));
      transition_seen seen;
      seen.from = observed;
      seen.to = s;
      if (!chain.empty()) {
        seen.number = chain.back().number;
        seen.from = chain.back().from;
      }
      last_transition = seen;
      if (auto* a = log.pending()) {
        for (const inferred_transition& t : chain) a->transitions.push_back(t.number);
        a->busy_until = now_us;
      }
      reset_sent_since_change = false;
    }
    observed = s;
    state_known = true;
  }

  void on_velocity(std::int32_t v) {
    if (velocity && *velocity != v && log.pending()) log.pending()->busy_until = now_us;
    velocity = v;
  }

  void on_frame(const co::frame& f) {
    if (f.extended || f.rtr) return;
    if (sdo.on_frame(f)) return;
    const std::uint8_t node = config.node_id;
    if (f.id == co::cob::heartbeat + node && f.len >= 1) {
      nmt_seen = f.data[0];
      if (f.data[0] == static_cast<std::uint8_t>(co::nmt_state::initialising)) {
        // Boot-up: the node starts afresh with its default PDOs; set it up again.
        injected_fault = 0;
        state_known = false;
        restart_setup(node_text() + " restarted (boot-up message): configuring it again");
        return;
      }
      consumer.on_frame(f);
      return;
    }
    if (status != remote_status::running) return;
    if (f.id == co::cob::emcy + node && f.len >= 3) {
      const auto code = static_cast<std::uint16_t>(co::get_le(f.data.data(), 2));
      last_emcy = code;
      error_register = f.data[2];
      if (!error_mapped) error_code = code;
      return;
    }
    if (f.id == co::cob::tpdo1 + node && f.len >= 2) {
      if (error_mapped && f.len >= 4) {
        error_code = static_cast<std::uint16_t>(co::get_le(f.data.data() + 2, 2));
      }
      on_status(static_cast<std::uint16_t>(co::get_le(f.data.data(), 2)));
      return;
    }
    if (velocity_mapped && f.id == co::cob::tpdo1 + 0x100 + node && f.len >= 4) {
      on_velocity(static_cast<std::int32_t>(static_cast<std::uint32_t>(co::get_le(f.data.data(), 4))));
    }
  }

  void send_word(std::uint16_t w) {
    co::frame f;
    f.id = co::cob::rpdo1 + config.node_id;
    f.len = 2;
    co::put_le(f.data.data(), w, 2);
    if ((w & bit7) != 0 && (last_sent & bit7) == 0) reset_sent_since_change = true;
    last_sent = w;
    (void)bus.send(f);
  }

  void process(std::uint32_t elapsed_us) {
    now_us += elapsed_us;
    if (status != remote_status::bus_failed) {
      if (const std::error_code ec = bus.failure()) {
        stop_link(remote_status::bus_failed, "the bus connection failed: " + ec.message());
      }
    }
    if (status != remote_status::bus_failed) {
      // One frame at a time: an SDO answer ends its transfer before the next frame (a TPDO the
      // write caused) is looked at.
      co::frame f;
      for (int n = 0; n < 4096 && bus.receive(f); ++n) {
        on_frame(f);
        if (current && sdo.finished()) drive_jobs();
      }
      (void)consumer.process(elapsed_us);
      if (hb_event == heartbeat_event::lost && status == remote_status::running) {
        lose(node_text() + " does not answer (no heartbeat for " +
             std::to_string(3u * config.heartbeat_ms) + " ms)");
      }
      hb_event = heartbeat_event::none;
      if (current) (void)sdo.process(elapsed_us);
      drive_jobs();
      if ((status == remote_status::no_answer || status == remote_status::refused) &&
          now_us >= retry_at_us) {
        restart_setup(status_text + "; trying again");
        drive_jobs();
      }
      if (status == remote_status::running) {
        while (!outbox.empty() && outbox.front().second <= now_us) {
          send_word(outbox.front().first);
          outbox.pop_front();
        }
      }
    }
    if (log.pending()) settle();
    if (now_us >= next_publish_us) {
      next_publish_us = now_us + config.publish_us;
      board.publish([this](bool with_time) { return snapshot(with_time); });
    }
  }

  // --- actions and results --------------------------------------------------------------------

  std::string shown_state() const {
    return state_known ? state_name(observed) : "UNKNOWN";
  }

  std::string conditions() const {
    std::string s;
    auto add = [&s](const std::string& what) { s += (s.empty() ? " (" : ", ") + what; };
    if (error_code != 0) add("the drive reports error code " + hex(error_code, 4));
    if (status_known && (status_word & status_bit::voltage_enabled) == 0) {
      add("no DC-link voltage: status bit 4 is 0");
    }
    if (status_known && (status_word & status_bit::remote) == 0) {
      add("status bit 9 (remote) is 0: the drive does not process the control word");
    }
    if (!s.empty()) s += ")";
    return s;
  }

  detail::action_log::standing how_it_stands() const {
    return {observed, shown_state(), conditions()};
  }

  std::uint64_t track(std::string action, bool refuse_without_transition) {
    return log.track(std::move(action), refuse_without_transition,
                     state_known ? std::optional<state>(observed) : std::nullopt, now_us);
  }

  // Settled: nothing left to send, no transition and no change of velocity for settle_quiet. A
  // stop the state runs (QUICK STOP ACTIVE, FAULT REACTION ACTIVE) counts as busy while the shaft
  // turns, so the transition that ends it is reported with the action.
  void settle() {
    const bool stopping =
        state_known && velocity && *velocity != 0 &&
        (table.info(observed).activity == state_activity::quick_stop ||
         table.info(observed).activity == state_activity::fault_reaction);
    log.settle(now_us, !outbox.empty() || stopping || (current && current->waiter));
  }

  // Logs a command or bit toggle and queues its word for RPDO1.
  std::uint64_t change_word(const detail::word_change& w) {
    const std::uint64_t id =
        w.tracked ? track(w.action, true) : log.report_now(w.action, "done", w.text);
    outbox.clear();
    if (w.fault_reset_edge) {
      // Each level of the edge held for reset_pulse_us, so the drive steps on both.
      std::uint64_t at = now_us;
      if ((last_sent & bit7) != 0) {
        queue_word(w.word, at);
        at += config.reset_pulse_us;
      }
      queue_word(static_cast<std::uint16_t>(w.word | bit7), at);
      queue_word(w.word, at + config.reset_pulse_us);
    } else {
      queue_word(w.word, now_us);
    }
    control_word = w.word;
    return id;
  }

  void queue_word(std::uint16_t word, std::uint64_t at) { outbox.emplace_back(word, at); }

  std::optional<refused> not_running() const {
    if (status == remote_status::running) return std::nullopt;
    std::string why = status_text.empty() ? node_text() + " is not ready" : status_text;
    return refused{503, why};
  }

  // Queues an SDO download for the cycle thread and waits for its end. `lock` holds the mutex.
  std::shared_ptr<user_wait> download(std::unique_lock<std::mutex>& lock, std::uint16_t index,
                                      std::int64_t value, unsigned bytes,
                                      std::function<void()> on_done,
                                      std::optional<std::string> track_action = std::nullopt) {
    auto w = std::make_shared<user_wait>();
    w->track_action = std::move(track_action);
    sdo_job j = write(index, 0, value, bytes);
    j.waiter = w;
    if (on_done) j.then = [on_done](const co::sdo_client&) { on_done(); };
    user_jobs.push_back(std::move(j));
    job_done.wait_for(lock, config.request_timeout, [&] { return w->done || board.closed(); });
    return w;
  }

  // The reply for a finished (or abandoned) download; refusals are reported to the page too.
  reply download_reply(const std::shared_ptr<user_wait>& w, const std::string& action) {
    if (!w->done) {
      log.report_now(action, "refused", "refused: no answer in time");
      return refused{504, action + ": no answer from " + node_text() + " in time"};
    }
    if (w->cancelled) {
      const std::string why = status_text.empty() ? node_text() + " does not answer" : status_text;
      log.report_now(action, "refused", "refused: " + why);
      return refused{503, action + ": " + why};
    }
    if (w->abort != sdo_abort::none) {
      std::string text = "refused: " + abort_text(w->abort);
      if (w->abort == sdo_abort::sdo_protocol_timed_out) {
        text = "refused: " + node_text() + " does not answer (" + abort_text(w->abort) + ")";
      }
      log.report_now(action, "refused", text);
      return refused{w->abort == sdo_abort::sdo_protocol_timed_out ? 504 : 422,
                     action + ": " + text.substr(std::string("refused: ").size()), w->abort};
    }
    if (w->track_action) return accepted{w->id};
    return accepted{log.report_now(action, "done", "done")};
  }

  // --- snapshots ------------------------------------------------------------------------------

  json capabilities() const {
    json reasons = json::object();
    if (!fault_injection) {
      reasons["fault"] = std::string(not_remote) +
                         " (only a cia402 bus node offers fault injection, object 0x2001)";
    }
    reasons["dc_link"] = not_remote;
    reasons["sto"] = not_remote;
    return {{"fault", fault_injection}, {"dc_link", false}, {"sto", false}, {"reasons", reasons}};
  }

  json remote_json() const {
    json r;
    r["node"] = config.node_id;
    r["bus"] = config.bus_name;
    r["status"] = remote_status_name(status);
    r["text"] = status_text;
    r["nmt"] = nmt_seen ? json(co::nmt_state_name(static_cast<co::nmt_state>(*nmt_seen)))
                        : json(nullptr);
    r["device_name"] = device_name;
    r["heartbeat_watched"] = heartbeat_watched;
    r["error_code_in_pdo"] = error_mapped;
    r["velocity_in_pdo"] = velocity_mapped;
    r["last_emcy"] = last_emcy ? json(hex(*last_emcy, 4)) : json(nullptr);
    return r;
  }

  json snapshot(bool with_time) const {
    json j;
    const bool live = status == remote_status::running || status == remote_status::configuring;
    j["state"] = live ? shown_state() : "UNKNOWN";
    j["status_word"] = hex(status_word, 4);
    j["control_word"] = hex(control_word, 4);
    j["decodes_to"] = command_name(table.decode(control_word));
    if (last_transition) {
      j["last_transition"] = {{"number", last_transition->number ? json(*last_transition->number)
                                                                 : json(nullptr)},
                              {"from", state_name(last_transition->from)},
                              {"to", state_name(last_transition->to)},
                              {"inferred", true}};
    } else {
      j["last_transition"] = nullptr;
    }
    // Not visible from the bus: the page shows them as unknown.
    j["stop_running"] = nullptr;
    j["ramp"] = nullptr;
    j["error_code"] = hex(error_code, 4);
    j["error_register"] = hex(error_register, 2);
    // A silent node's last values are history: what is shown live says "unknown" instead.
    j["velocity"] = live && velocity ? json(*velocity) : json(nullptr);
    j["target_velocity"] = target_velocity;
    j["effective_target"] = target_velocity;
    j["torque"] = nullptr;
    j["brake_engaged"] = nullptr;
    // S11: status bit 4 is the DC-link voltage.
    j["dc_link"] = live && status_known ? json((status_word & status_bit::voltage_enabled) != 0)
                                        : json(nullptr);
    j["sto"] = nullptr;
    j["fault_cause"] = fault_injection ? json(hex(injected_fault, 4)) : json(nullptr);
    json objs = json::object();
    for (const auto& [index, value] : objects) objs[hex(index, 4)] = value;
    j["objects"] = std::move(objs);
    j["results"] = log.results_json();
    j["remote"] = remote_json();
    j["capabilities"] = capabilities();
    if (with_time) {
      j["cycle"] = now_us / config.cycle_us;
      j["time_ms"] = now_us / 1000;
    }
    return j;
  }
};

remote_drive::remote_drive(const profile& p, canopen::channel& bus, const remote_config& config)
    : impl_(std::make_unique<impl>(p, bus, config)) {}

remote_drive::~remote_drive() { close(); }

void remote_drive::step() { process(impl_->config.cycle_us); }

void remote_drive::process(std::uint32_t elapsed_us) {
  std::lock_guard lock(impl_->mutex);
  impl_->process(elapsed_us);
}

reply remote_drive::command(page_command c) {
  std::lock_guard lock(impl_->mutex);
  if (auto no = impl_->not_running()) return *no;
  const auto change = detail::press_button(impl_->table, c, impl_->control_word);
  if (const refused* no = std::get_if<refused>(&change)) return *no;
  return accepted{impl_->change_word(std::get<detail::word_change>(change))};
}

reply remote_drive::toggle_control_bit(int bit) {
  if (bit < 0 || bit > 15) return refused{400, "bit must be 0..15"};
  std::lock_guard lock(impl_->mutex);
  if (auto no = impl_->not_running()) return *no;
  return accepted{impl_->change_word(detail::flip_bit(impl_->table, impl_->control_word, bit))};
}

reply remote_drive::write_object(std::uint16_t index, std::int64_t value) {
  if (index == 0x6040) {
    return refused{400, "the control word is set by commands and bit toggles, not written here"};
  }
  const object_description* t = type_of(index);
  if (t == nullptr) {
    return refused{400, "object " + hex(index, 4) +
                            " is not one the page writes on a remote drive (option codes, "
                            "0x6060, 0x6083..0x6085, 0x60FF)"};
  }
  const std::string action = "WRITE " + hex(index, 4) + " = " + std::to_string(value);
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (const auto a = out_of_type(*t, value)) {
    const std::string text = "refused: " + abort_text(*a) + ", checked before sending";
    m.log.report_now(action, "refused", text);
    return refused{422, action + ": " + abort_text(*a), *a};
  }
  if (auto no = m.not_running()) return *no;
  const auto w = m.download(lock, index, value, static_cast<unsigned>(type_size(t->type)), [&m, index, value] {
    m.objects[index] = value;
    if (index == 0x60FF) m.target_velocity = static_cast<std::int32_t>(value);
  });
  return m.download_reply(w, action);
}

reply remote_drive::change_plant(const plant_change& change) {
  if (change.dc_link || change.sto) {
    return refused{409, std::string("DC-link voltage and STO are ") + not_remote};
  }
  if (change.target_velocity && change.fault) {
    return refused{400, "on a remote drive the target velocity and a fault go in separate requests"};
  }
  if (!change.target_velocity && !change.fault) return refused{400, "nothing to change"};
  if (change.fault && *change.fault && change.fault_code == 0) {
    return refused{400, "a fault needs a code 0x0001..0xFFFF and a class 0..4"};
  }
  std::unique_lock lock(impl_->mutex);
  impl& m = *impl_;
  if (change.target_velocity) {
    const std::int64_t v = *change.target_velocity;
    const std::string action = "TARGET_VELOCITY=" + std::to_string(v);
    if (const auto a = out_of_type(*type_of(0x60FF), v)) {
      m.log.report_now("WRITE 0x60FF = " + std::to_string(v), "refused", "refused: " + abort_text(*a));
      return refused{422, "WRITE 0x60FF = " + std::to_string(v) + ": " + abort_text(*a), *a};
    }
    if (auto no = m.not_running()) return *no;
    const auto w = m.download(
        lock, 0x60FF, v, 4,
        [&m, v] {
          m.objects[0x60FF] = v;
          m.target_velocity = static_cast<std::int32_t>(v);
        },
        action);
    return m.download_reply(w, action);
  }
  if (!m.fault_injection) {
    return refused{409, std::string("fault injection is ") + not_remote + " (" + m.node_text() +
                            " has no fault-injection object 0x2001 of cia402 bus)"};
  }
  if (auto no = m.not_running()) return *no;
  const std::uint16_t code = *change.fault ? change.fault_code : 0;
  std::string action = *change.fault ? "FAULT " + hex(code, 4) + " ON" : std::string("FAULT OFF");
  // 0x2001 takes an error code only; the drive raises it with its default class.
  if (*change.fault && m.table.error_classes) action += " (class not sent: 0x2001 takes a code)";
  const auto w = m.download(
      lock, co::fault_injection_index, code, 2, [&m, code] { m.injected_fault = code; }, action);
  return m.download_reply(w, action);
}

std::string remote_drive::info_json(bool control, bool token_required) const {
  std::lock_guard lock(impl_->mutex);
  const impl& m = *impl_;
  json j = detail::profile_info(m.table);
  j["backend"] = "remote";
  j["remote"] = {{"node", m.config.node_id}, {"bus", m.config.bus_name}};
  j["transitions_inferred"] = true;
  j["control"] = control;
  j["token_required"] = token_required;
  j["cycle_us"] = m.config.cycle_us;
  j["publish_ms"] = m.config.publish_us / 1000.0;
  j["capabilities"] = m.capabilities();
  return j.dump();
}

std::string remote_drive::snapshot_json() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->board.present_json(impl_->snapshot(true));
}

std::optional<published> remote_drive::wait_for_update(std::uint64_t seen,
                                                       std::chrono::milliseconds timeout) {
  return impl_->board.wait_for_update(seen, timeout);
}

published remote_drive::latest() const { return impl_->board.latest(); }

void remote_drive::close() {
  {
    // Under the drive's lock, so a request waiting for its transfer cannot miss it.
    std::lock_guard lock(impl_->mutex);
    impl_->board.close();
  }
  impl_->job_done.notify_all();
}

bool remote_drive::closed() const { return impl_->board.closed(); }

remote_status remote_drive::status() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->status;
}

std::string remote_drive::status_text() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->status_text;
}

bool remote_drive::fault_injection_available() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->fault_injection;
}

}  // namespace cia402::page
