#include <deque>
#include <optional>

#include "cia402/manufacturer_objects.hpp"
#include "cia402/objects.hpp"
#include "cia402/page/ecat_drive.hpp"
#include "cia402/words.hpp"
#include "page_json.hpp"
#include "page_names.hpp"
#include "remote_link.hpp"

namespace cia402::page {
namespace {

using json = nlohmann::ordered_json;
using detail::hex;

// Frames lost in a row before the line counts as gone (each waits for its answer: with the 20 ms
// of `cia402 serve` about half a second).
constexpr int lost_cycles_limit = 25;

// The link over EtherCAT: our master, set up in the page's cycle thread, one SDO transfer at most
// between two cycles so the process data keeps flowing.
class ecat_link final : public detail::remote_link {
 public:
  ecat_link(const profile& p, ethercat::master_link& line, std::uint16_t position, std::string interface,
            const remote_config& c)
      : table_(p), master_(line, p, c.cycle_us == 0 ? 1000 : c.cycle_us), position_(position),
        interface_(std::move(interface)), config_(c) {}

  void poll(std::uint32_t elapsed_us) override {
    now_us_ += elapsed_us;
    if (!up_) {
      if (now_us_ >= next_try_us_) bring_up();
      return;
    }
    while (!outbox_.empty() && outbox_.front().second <= now_us_) {
      send(outbox_.front().first);
      outbox_.pop_front();
    }
    if (!jobs_.empty()) {
      job j = std::move(jobs_.front());
      jobs_.pop_front();
      run(j);
      if (!up_) return;
    }
    if (master_.cycle()) {
      lost_ = 0;
    } else if (++lost_ > lost_cycles_limit) {
      return go_down("the line does not answer (" + master_.error() + ")");
    }
    const ethercat::ecat_slave& s = slave();
    if (s.al_state != static_cast<std::uint8_t>(ethercat::line_state::operational)) {
      std::string why = drive_text() + " left OP: AL state " + ethercat::line_state_name(s.al_state);
      if (s.al_code != 0) why += ", AL status code " + hex(s.al_code, 4) + " (" + ethercat::al_status_code_text(s.al_code) + ")";
      return go_down(why);
    }
    status_known_ = true;
    if (s.last_error_code != error_code_) {
      error_code_ = s.last_error_code;
      jobs_.push_back({false, 0x1001, 0, 1, false, [this](const detail::link_transfer& t) {
                         if (t.ok) error_register_ = static_cast<std::uint8_t>(t.value);
                       }});
    }
    if (on_status) on_status(s.last_status);
    if (const auto v = master_.input(position_, 0x606C)) {
      if (on_velocity) on_velocity(static_cast<std::int32_t>(*v));
    }
  }

  bool running() const override { return up_; }
  bool failed() const override { return !up_ && tried_; }
  remote_status status() const override { return up_ ? remote_status::running : status_; }
  std::string phase_text() const override { return up_ ? std::string() : text_; }
  std::string drive_text() const override { return "slave " + std::to_string(position_); }

  bool request_pending() const override { return !jobs_.empty(); }
  bool read(std::uint16_t index, bool is_signed, std::function<void(const detail::link_transfer&)> done) override {
    if (!up_) return false;
    jobs_.push_back({false, index, 0, 0, is_signed, std::move(done)});
    return true;
  }
  bool write(std::uint16_t index, std::int64_t value, unsigned bytes,
             std::function<void(const detail::link_transfer&)> done) override {
    if (!up_) return false;
    jobs_.push_back({true, index, value, bytes, false, std::move(done)});
    return true;
  }
  const std::map<std::uint16_t, std::int64_t>& start_values() const override { return start_values_; }

  std::uint16_t last_sent() const override { return last_sent_; }
  void send_control_word(std::uint16_t word, bool fault_reset_edge) override {
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
  bool words_queued() const override { return !outbox_.empty(); }

  bool status_known() const override { return up_ && status_known_; }
  std::uint16_t status_word() const override { return up_ ? slave().last_status : 0; }
  std::uint16_t error_code() const override { return error_code_; }
  std::uint8_t error_register() const override { return error_register_; }
  bool fault_injection() const override { return fault_injection_; }
  std::optional<std::int64_t> cyclic(std::uint16_t index) const override {
    if (!up_) return std::nullopt;
    return master_.input(position_, index);
  }

  json describe() const override {
    json r;
    r["node"] = position_;
    r["bus"] = "EtherCAT " + interface_;
    r["where"] = "slave " + std::to_string(position_) + " on EtherCAT " + interface_;
    r["status"] = remote_status_name(status());
    r["text"] = phase_text();
    r["nmt"] = nullptr;
    const bool known = !master_.slaves().empty() && position_ < master_.slaves().size();
    r["al_state"] = known ? json(ethercat::line_state_name(slave().al_state)) : json(nullptr);
    r["device_name"] = known ? json(slave().sii.device_name) : json(nullptr);
    r["mapping"] = known ? json(slave().mapping_source) : json(nullptr);
    r["working_counter"] = master_.last_working_counter();
    r["lost_frames"] = master_.lost_frames();
    const bool any_emcy = known && !slave().emergencies.empty();
    r["last_emcy"] = any_emcy ? json(hex(slave().emergencies.back(), 4)) : json(nullptr);
    return r;
  }
  json where() const override { return {{"node", position_}, {"bus", "EtherCAT " + interface_}}; }

 private:
  struct job {
    bool writing = false;
    std::uint16_t index = 0;
    std::int64_t value = 0;
    unsigned bytes = 0;
    bool is_signed = false;
    std::function<void(const detail::link_transfer&)> done;
  };

  const ethercat::ecat_slave& slave() const { return master_.slaves()[position_]; }

  void send(std::uint16_t word) {
    master_.send_control_word(position_, word);
    last_sent_ = word;
    if (on_sent) on_sent(word);
  }

  // A page write of an object the drive maps in its outputs goes there (an SDO would be overwritten
  // by the next cycle); anything else by SDO.
  void run(job& j) {
    detail::link_transfer t;
    if (j.writing && master_.set_output(position_, j.index, j.value)) {
      t.ok = true;
    } else {
      const ethercat::ecat_sdo_result r = j.writing ? master_.sdo_write(position_, j.index, 0, j.value, j.bytes)
                                                    : master_.sdo_read(position_, j.index, 0);
      t.ok = r.ok;
      // No answer at all reads as the SDO time-out a CANopen master would report.
      t.abort = r.ok ? sdo_abort::none : r.aborted ? r.abort : sdo_abort::sdo_protocol_timed_out;
      t.value = r.ok ? r.value(j.is_signed) : 0;
    }
    if (j.done) j.done(t);
  }

  void bring_up() {
    tried_ = true;
    next_try_us_ = now_us_ + (config_.retry_us == 0 ? 1000000 : config_.retry_us);
    status_ = remote_status::configuring;
    if (!master_.scan()) {
      status_ = remote_status::no_answer;
      text_ = "EtherCAT " + interface_ + ": " + master_.error();
      return;
    }
    if (position_ >= master_.slaves().size()) {
      status_ = remote_status::refused;
      text_ = "EtherCAT " + interface_ + ": no slave at position " + std::to_string(position_) + " (the line has " +
              std::to_string(master_.slaves().size()) + ")";
      return;
    }
    if (!master_.bring_to_operational()) {
      status_ = master_.error().find("refused") != std::string::npos ? remote_status::refused : remote_status::no_answer;
      text_ = master_.error();
      return;
    }
    // What the page shows from the start: its objects, the target velocity, the supported modes.
    start_values_.clear();
    std::vector<std::uint16_t> wanted;
    for (const object_name& o : object_names(table_)) wanted.push_back(o.index);
    wanted.push_back(0x60FF);
    wanted.push_back(object_index::supported_drive_modes);
    for (std::uint16_t index : wanted) {
      const object_description* d = find_drive_object(index);
      const ethercat::ecat_sdo_result r = master_.sdo_read(position_, index, 0);
      if (r.ok) start_values_[index] = r.value(d != nullptr && type_signed(d->type));
    }
    // 0x2001 of this project's virtual drive is write-only: that is how it is told from others.
    const ethercat::ecat_sdo_result probe = master_.sdo_read(position_, fault_injection_index, 0);
    fault_injection_ = probe.aborted && probe.abort == sdo_abort::write_only_object;
    last_sent_ = slave().last_control;
    error_code_ = slave().last_error_code;
    const ethercat::ecat_sdo_result reg = master_.sdo_read(position_, 0x1001, 0);
    error_register_ = reg.ok ? static_cast<std::uint8_t>(reg.value(false)) : 0;
    outbox_.clear();
    lost_ = 0;
    up_ = true;
    text_.clear();
    if (on_phase) on_phase(detail::link_event::running);
  }

  void go_down(std::string why) {
    up_ = false;
    status_known_ = false;
    status_ = remote_status::no_answer;
    text_ = std::move(why);
    next_try_us_ = now_us_ + (config_.retry_us == 0 ? 1000000 : config_.retry_us);
    for (job& j : jobs_) {
      detail::link_transfer t;
      t.cancelled = true;
      if (j.done) j.done(t);
    }
    jobs_.clear();
    outbox_.clear();
    if (on_phase) on_phase(detail::link_event::failed);
  }

  const profile& table_;
  ethercat::ecat_master master_;
  std::size_t position_;
  std::string interface_;
  remote_config config_;
  std::uint64_t now_us_ = 0;
  std::uint64_t next_try_us_ = 0;
  bool up_ = false;
  bool tried_ = false;
  bool status_known_ = false;
  remote_status status_ = remote_status::configuring;
  std::string text_;
  int lost_ = 0;
  std::deque<job> jobs_;
  std::deque<std::pair<std::uint16_t, std::uint64_t>> outbox_;  // word, not before (us)
  std::map<std::uint16_t, std::int64_t> start_values_;
  std::uint16_t last_sent_ = 0;
  std::uint16_t error_code_ = 0;
  std::uint8_t error_register_ = 0;
  bool fault_injection_ = false;
};

}  // namespace

std::unique_ptr<remote_drive> make_ecat_drive(const profile& p, ethercat::master_link& link, std::uint16_t position,
                                              const std::string& interface, const remote_config& config) {
  return std::make_unique<remote_drive>(p, std::make_unique<ecat_link>(p, link, position, interface, config), config);
}

}  // namespace cia402::page
