#include "cli/master_buses.hpp"

#include <poll.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <sstream>
#include <variant>

#include "cia402/apps/elapsed_clock.hpp"
#include "cia402/apps/ethercat_link.hpp"
#include "cia402/canopen/306/eds_reader.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/canopen/transport/channel_url.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/ethercat/axis/ecat_link.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

constexpr int usage_error = 2;
constexpr int failed = 1;

// CANopen: a real channel in real time, or an in-process bus holding one virtual drive, run in
// virtual time (no waiting).
class can_bus final : public master_bus {
 public:
  bool open(const master_args& a, const profile& p, bool streaming, master_output& out, int& status) {
    canopen::channel_url url;
    std::string why;
    if (!canopen::parse_channel_url(a.can, url, why)) {
      out.error("--can " + a.can + ": " + why);
      status = usage_error;
      return false;
    }
    canopen::can_link_config c;
    c.node_id = static_cast<std::uint8_t>(a.node);
    c.bus_name = a.can;
    c.cycle_us = streaming || a.sync_us_given ? a.sync_us : a.cycle_ms * 1000;
    c.drive_heartbeat_ms = a.heartbeat_ms;
    c.master_heartbeat_ms = a.guard_ms;
    c.drive_profile = &p;
    c.map_position = streaming;
    c.known_objects = canopen::node_objects(apps::drive_node_config(static_cast<std::uint8_t>(a.node)));
    if (!a.eds.empty() && !read_eds_file(a.eds, c, out)) {
      status = usage_error;
      return false;
    }
    // A SYNC period that a millisecond's rounding would stretch is waited for to the microsecond.
    precise_ = c.cycle_us % 1000 != 0 || streaming;
    virtual_step_us_ = std::clamp<std::uint32_t>(c.cycle_us, 1, 1000);
    if (url.type == canopen::channel_url::kind::virtual_bus) {
      virtual_ = true;
      drive_ = std::make_unique<apps::virtual_drive_node>(p, bus_.attach(),
                                                         apps::drive_node_config(static_cast<std::uint8_t>(a.node)));
      master_ch_ = bus_.attach();
      channel_ = master_ch_.get();
      for (int i = 0; i < 10; ++i) drive_->poll(1000);  // past power-up (T0, T1)
      canopen::frame f;
      while (master_ch_->receive(f)) {}  // its boot-up message
    } else {
      real_ = canopen::open_channel(url, why);
      if (!real_) {
        out.error(why);
        status = failed;
        return false;
      }
      channel_ = real_.get();
    }
    link_ = std::make_unique<canopen::can_link>(*channel_, std::move(c));
    drives_.push_back({link_.get(), {"node", a.node}});
    return true;
  }

  std::vector<drive>& drives() override { return drives_; }

  std::uint32_t wait(std::uint32_t next_us) override {
    if (virtual_) {
      drive_->poll(virtual_step_us_);
      return virtual_step_us_;
    }
    pollfd p{channel_->native_handle(), POLLIN, 0};
    if (precise_) {
      const std::uint32_t us = std::clamp<std::uint32_t>(next_us, 50, 10000);
      const timespec ts{0, static_cast<long>(us) * 1000};
      if (p.fd >= 0) ::ppoll(&p, 1, &ts, nullptr);
      return clock_.take();
    }
    const int ms = static_cast<int>(std::min<std::uint32_t>(next_us / 1000 + 1, 10));
    if (p.fd >= 0) ::poll(&p, 1, ms);
    return clock_.take();
  }

  void settle() override {
    if (virtual_) drive_->poll(0);
  }

  std::string stream_words(std::uint32_t cycle_us) const override {
    return "by RPDO3, SYNC every " + std::to_string(cycle_us) + " us";
  }

  std::optional<std::string> nmt(const drive&, const std::string& command) override {
    struct named {
      const char* name;
      canopen::nmt_command command;
    };
    constexpr named commands[] = {{"start", canopen::nmt_command::start},
                                  {"stop", canopen::nmt_command::stop},
                                  {"preop", canopen::nmt_command::enter_pre_operational},
                                  {"reset", canopen::nmt_command::reset_node},
                                  {"reset-communication", canopen::nmt_command::reset_communication}};
    for (const named& n : commands) {
      if (command != n.name) continue;
      if (const auto ec = link_->send_nmt(n.command)) return "sending NMT " + command + " failed: " + ec.message();
      settle();
      return std::nullopt;
    }
    return "no NMT command " + command;
  }

 private:
  static bool read_eds_file(const std::string& path, canopen::can_link_config& c, master_output& out) {
    std::ifstream in(path);
    if (!in) {
      out.error("--eds " + path + ": cannot read the file");
      return false;
    }
    std::stringstream text;
    text << in.rdbuf();
    auto parsed = canopen::read_eds(text.str());
    if (const auto* e = std::get_if<canopen::eds_error>(&parsed)) {
      out.error("--eds " + path + ":" + std::to_string(e->line) + ": " + e->reason);
      return false;
    }
    c.eds = std::move(std::get<canopen::eds_contents>(parsed).objects);
    return true;
  }

  bool virtual_ = false;
  bool precise_ = false;
  std::uint32_t virtual_step_us_ = 1000;
  canopen::virtual_bus bus_;
  std::unique_ptr<apps::virtual_drive_node> drive_;
  std::unique_ptr<canopen::virtual_channel> master_ch_;
  std::unique_ptr<canopen::channel> real_;
  canopen::channel* channel_ = nullptr;
  apps::elapsed_clock clock_;
  std::unique_ptr<canopen::can_link> link_;
  std::vector<drive> drives_;
};

// EtherCAT: our master on a raw socket, the line brought to OP before the first step; one link a
// drive chosen.
class ecat_bus final : public master_bus {
 public:
  bool open(const master_args& a, const profile& p, master_output& out, int& status) {
    status = failed;
    if (const std::error_code ec = raw_.open(a.ecat)) {
      out.error("cannot open " + a.ecat + ": " + ec.message() +
                (ec.value() == EPERM ? " (a raw socket needs root or CAP_NET_RAW)" : ""));
      return false;
    }
    line_ = std::make_unique<ethercat::ecat_line>(raw_, p, a.sync_us, a.ecat);
    if (!line_->scan()) {
      out.error(a.ecat + ": " + line_->error());
      return false;
    }
    const auto& slaves = line_->master().slaves();
    if (a.position && *a.position >= static_cast<int>(slaves.size())) {
      out.error("--position " + std::to_string(*a.position) + ": the line has " + std::to_string(slaves.size()) + " slave(s)");
      return false;
    }
    out.line({{"event", "scan"}, {"slaves", slaves.size()}}, "found " + std::to_string(slaves.size()) + " slave(s) on " + a.ecat);
    for (const auto& s : slaves) {
      const drive_tag tag{"slave", s.position};
      out.drive(tag,
                {{"event", "slave"}, {"station", hex(s.station, 4)}, {"vendor_id", hex(s.sii.vendor_id, 8)},
                 {"product_code", hex(s.sii.product_code, 8)}, {"revision", hex(s.sii.revision, 8)},
                 {"serial", s.sii.serial}, {"name", s.sii.device_name}},
                "station " + hex(s.station, 4) + ", " + s.sii.device_name + ", vendor " + hex(s.sii.vendor_id, 8) +
                    ", product " + hex(s.sii.product_code, 8) + ", revision " + hex(s.sii.revision, 8) + ", serial " +
                    std::to_string(s.sii.serial));
    }
    if (!line_->bring_to_operational()) {
      out.error(line_->error());
      return false;
    }
    const auto& m = line_->master();
    out.line({{"event", "operational"}, {"slaves", slaves.size()}, {"working_counter", m.expected_working_counter()},
              {"cycle_us", m.cycle_us()}},
             "line in OP: LRW every " + std::to_string(m.cycle_us()) + " us, working counter " +
                 std::to_string(m.expected_working_counter()));
    for (const auto& s : slaves) {
      out.drive({"slave", s.position},
                {{"event", "mapping"}, {"source", s.mapping_source}, {"output_bytes", s.output_bytes}, {"input_bytes", s.input_bytes}},
                std::to_string(s.output_bytes) + " bytes out, " + std::to_string(s.input_bytes) + " bytes in (" +
                    s.mapping_source + ")");
      if (a.position && *a.position != s.position) continue;
      links_.push_back(std::make_unique<ethercat::ecat_link>(*line_, s.position));
      drives_.push_back({links_.back().get(), {"slave", s.position}});
    }
    status = 0;
    return true;
  }

  std::vector<drive>& drives() override { return drives_; }

  std::uint32_t wait(std::uint32_t next_us) override {
    const std::uint32_t us = std::min<std::uint32_t>(next_us, line_->master().cycle_us());
    if (us > 0) raw_.wait_us(us);
    return clock_.take();
  }

  std::string stream_words(std::uint32_t cycle_us) const override {
    return "in the process data, LRW every " + std::to_string(cycle_us) + " us";
  }

  std::optional<std::string> nmt(const drive&, const std::string&) override {
    return std::string("nmt is CANopen's: on EtherCAT the master keeps the line in OP (AL states), no NMT");
  }

  void finish(master_output& out) override {
    const auto& m = line_->master();
    out.line({{"event", "done"}, {"cycles", m.cycles()}, {"lost_frames", m.lost_frames()}},
             "done after " + std::to_string(m.cycles()) + " cycles, " + std::to_string(m.lost_frames()) + " frame(s) lost");
  }

 private:
  apps::ethercat_link raw_;
  std::unique_ptr<ethercat::ecat_line> line_;
  std::vector<std::unique_ptr<ethercat::ecat_link>> links_;
  std::vector<drive> drives_;
  apps::elapsed_clock clock_;
};

}  // namespace

std::unique_ptr<master_bus> open_can_bus(const master_args& a, const profile& p, const std::vector<master_step>& steps,
                                         master_output& out, int& status) {
  const bool streaming = std::any_of(steps.begin(), steps.end(), [](const master_step& s) { return s.verb == "csp-stream"; });
  auto bus = std::make_unique<can_bus>();
  if (!bus->open(a, p, streaming, out, status)) return nullptr;
  return bus;
}

std::unique_ptr<master_bus> open_ecat_bus(const master_args& a, const profile& p, master_output& out, int& status) {
  auto bus = std::make_unique<ecat_bus>();
  if (!bus->open(a, p, out, status)) return nullptr;
  return bus;
}

}  // namespace cia402::cli
