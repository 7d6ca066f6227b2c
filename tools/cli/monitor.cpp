#include "cli/monitor.hpp"

#include <poll.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <variant>

#include "cia402/apps/elapsed_clock.hpp"
#include "cia402/canopen/306/eds_reader.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/monitor/decoder.hpp"
#include "cia402/canopen/transport/candump_log.hpp"
#include "cia402/canopen/transport/channel_url.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

constexpr int usage_error = 2;
constexpr int failed = 1;

using canopen::monitor::decoded_frame;

// Prints each record, as a line or a JSON object, with the time since the first frame.
class printer {
 public:
  printer(const monitor_args& a, std::ostream& out) : args_(a), out_(out) {}

  void print(const decoded_frame& d) {
    if (!started_) {
      first_us_ = d.time_us;
      started_ = true;
    }
    const double since = static_cast<double>(d.time_us - std::min(d.time_us, first_us_)) / 1e6;
    if (args_.json) {
      out_ << json(d, since).dump() << "\n";
    } else {
      char head[32];
      std::snprintf(head, sizeof head, "%10.6f  ", since);
      out_ << head;
      if (args_.raw) {
        const std::string frame_text = canopen::candump::format_frame(d.raw);
        out_ << frame_text << std::string(frame_text.size() < 22 ? 22 - frame_text.size() : 1, ' ');
      }
      const std::string who = d.node == 0 ? (d.kind == canopen::monitor::frame_kind::nmt ? "all" : "-")
                                          : "node " + std::to_string(d.node);
      out_ << who << std::string(who.size() < 9 ? 9 - who.size() : 1, ' ') << d.text << "\n";
    }
    if (!args_.url.empty()) out_.flush();  // a live bus: each frame as it comes
  }

 private:
  static nlohmann::ordered_json json(const decoded_frame& d, double since) {
    using canopen::monitor::frame_kind;
    nlohmann::ordered_json j;
    j["time"] = static_cast<double>(d.time_us) / 1e6;
    j["time_us"] = d.time_us;
    j["t"] = since;
    char id[16];
    std::snprintf(id, sizeof id, d.raw.extended ? "0x%08X" : "0x%03X", static_cast<unsigned>(d.raw.id));
    j["id"] = id;
    std::string data;
    for (std::size_t i = 0; i < d.raw.len && i < 8; ++i) {
      char b[4];
      std::snprintf(b, sizeof b, "%02X", d.raw.data[i]);
      data += b;
    }
    j["data"] = d.raw.rtr ? "R" : data;
    j["kind"] = canopen::monitor::kind_name(d.kind);
    j["node"] = d.node;
    if (!d.event.empty()) j["event"] = d.event;
    if (d.has_object) {
      char object[16];
      std::snprintf(object, sizeof object, "0x%04X:%u", d.index, d.sub);
      j["object"] = object;
    }
    const bool coded = d.kind == frame_kind::nmt || d.kind == frame_kind::emcy ||
                       d.kind == frame_kind::heartbeat || d.event == "abort";
    if (coded) {
      char code[16];
      std::snprintf(code, sizeof code, d.kind == frame_kind::sdo ? "0x%08X" : d.kind == frame_kind::emcy ? "0x%04X" : "0x%02X",
                    d.code);
      j["code"] = code;
      if (!d.code_text.empty()) j["code_text"] = d.code_text;
    }
    if (!d.values.empty()) {
      nlohmann::ordered_json values = nlohmann::ordered_json::array();
      for (const auto& v : d.values) {
        char object[16];
        std::snprintf(object, sizeof object, "0x%04X:%u", v.index, v.sub);
        nlohmann::ordered_json e{{"object", object}, {"shown", v.shown}};
        if (v.is_number) e["value"] = v.number;
        if (!v.name.empty()) e["name"] = v.name;
        if (!v.unit.empty()) e["unit"] = v.unit;
        if (!v.meaning.empty()) e["meaning"] = v.meaning;
        values.push_back(std::move(e));
      }
      j["values"] = std::move(values);
    }
    j["text"] = d.text;
    return j;
  }

  const monitor_args& args_;
  std::ostream& out_;
  bool started_ = false;
  std::uint64_t first_us_ = 0;
};

// --eds FILE --node N: each file describes its node (the N at its place, or the file's NodeID).
bool describe_nodes(const monitor_args& a, canopen::monitor::decoder& dec, std::ostream& err) {
  if (!a.nodes.empty() && a.nodes.size() != a.eds.size()) {
    err << "cia402 monitor: give one --node per --eds (or none, when each file names its node)\n";
    return false;
  }
  for (std::size_t i = 0; i < a.eds.size(); ++i) {
    std::ifstream file(a.eds[i]);
    if (!file) {
      err << "cia402 monitor: --eds " << a.eds[i] << ": cannot read the file\n";
      return false;
    }
    const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    auto read = canopen::read_eds(text);
    if (const auto* e = std::get_if<canopen::eds_error>(&read)) {
      err << "cia402 monitor: --eds " << a.eds[i] << ":" << e->line << ": " << e->reason << "\n";
      return false;
    }
    auto& eds = std::get<canopen::eds_contents>(read);
    const int node = a.nodes.empty() ? eds.node_id : a.nodes[i];
    if (node < 1 || node > 127) {
      err << "cia402 monitor: --eds " << a.eds[i] << ": "
          << (a.nodes.empty() ? "the file names no node (NodeID); add --node N"
                              : "--node " + std::to_string(node) + " is not 1..127")
          << "\n";
      return false;
    }
    dec.describe_node(static_cast<std::uint8_t>(node), std::move(eds.objects));
  }
  return true;
}

int decode_log(const monitor_args& a, std::istream& in, canopen::monitor::decoder& dec, printer& p,
               std::ostream& err) {
  std::ifstream file;
  if (a.log != "-") {
    file.open(a.log);
    if (!file) {
      err << "cia402 monitor: --log " << a.log << ": cannot read the file\n";
      return usage_error;
    }
  }
  std::istream& source = a.log == "-" ? in : file;
  std::uint64_t frames = 0, refused = 0, number = 0;
  std::uint64_t first_us = 0;
  for (std::string line; std::getline(source, line);) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    canopen::candump::log_entry e;
    std::string why;
    if (!canopen::candump::parse_line(line, e, why)) {
      err << "cia402 monitor: " << a.log << ":" << number << ": " << why << "\n";
      ++refused;
      continue;
    }
    if (frames == 0) first_us = e.time_us;
    if (a.duration_ms != 0 && e.time_us - std::min(e.time_us, first_us) > a.duration_ms * 1000) break;
    p.print(dec.decode(e.f, e.time_us));
    if (++frames == a.count) break;
  }
  return refused == 0 ? 0 : usage_error;
}

int watch_bus(const monitor_args& a, canopen::monitor::decoder& dec, printer& p, std::ostream& err) {
  canopen::channel_url url;
  std::string why;
  if (!canopen::parse_channel_url(a.url, url, why) || url.type == canopen::channel_url::kind::virtual_bus) {
    err << "cia402 monitor: " << a.url << ": "
        << (why.empty() ? "expected socketcand://HOST:PORT/BUS or socketcan://IFACE" : why) << "\n";
    return usage_error;
  }
  const auto channel = canopen::open_channel(url, why);
  if (!channel) {
    err << "cia402 monitor: " << why << "\n";
    return failed;
  }
  err << "cia402 monitor: watching " << a.url << std::endl;
  const stop_signals stop;
  apps::elapsed_clock clock;
  std::uint64_t waited_us = 0, frames = 0;
  int status = 0;
  while (!stop.requested() && (a.duration_ms == 0 || waited_us < a.duration_ms * 1000) &&
         (a.count == 0 || frames < a.count)) {
    pollfd fd{channel->native_handle(), POLLIN, 0};
    const std::uint64_t left_ms = a.duration_ms == 0 ? 100 : a.duration_ms - waited_us / 1000;
    (void)::poll(&fd, 1, static_cast<int>(std::min<std::uint64_t>(left_ms + 1, 100)));
    waited_us += clock.take();
    canopen::frame f;
    while ((a.count == 0 || frames < a.count) && channel->receive(f)) {
      p.print(dec.decode(f, apps::unix_time_us()));
      ++frames;
    }
    if (const auto ec = channel->failure()) {
      err << "cia402 monitor: " << a.url << ": the bus went away: " << ec.message() << "\n";
      status = failed;
      break;
    }
  }
  return status;
}

}  // namespace

CLI::App* add_monitor_subcommand(CLI::App& app, monitor_args& args) {
  auto* cmd = app.add_subcommand(
      "monitor",
      "Print the frames of a CAN bus decoded as CANopen (NMT, SYNC, heartbeat, EMCY, SDO, PDOs by "
      "each node's mapping), from a socketcand server or SocketCAN interface, or from a candump log");
  cmd->add_option("URL", args.url, "socketcand://HOST:PORT/BUS or socketcan://IFACE");
  cmd->add_option("--log", args.log, "decode a candump log (cia402 bus --log, candump -l; - for standard input)")
      ->type_name("FILE");
  cmd->add_option("--eds", args.eds, "a node's EDS or DCF: names, types and its PDOs at power-up (repeatable)")
      ->type_name("FILE");
  cmd->add_option("--node", args.nodes, "the node-ID of the --eds at the same place (repeatable)")
      ->type_name("N");
  cmd->add_flag("--no-drive-defaults", args.no_drive_defaults,
                "nodes without --eds are not taken for cia402 drives (whose PDOs are CiA 402's predefined "
                "set): their PDOs decode once their mapping goes over the bus");
  cmd->add_flag("--json", args.json, "one JSON object per frame");
  cmd->add_flag("--raw", args.raw, "the frame as ID#DATA beside its text");
  cmd->add_option("--count", args.count, "stop after N frames")->type_name("N");
  cmd->add_option("--duration", args.duration_ms, "stop after MS milliseconds (of the log's time with --log)")
      ->type_name("MS");
  return cmd;
}

int run_monitor(const monitor_args& args, std::istream& in, std::ostream& out, std::ostream& err) {
  if (args.url.empty() == args.log.empty()) {
    err << "cia402 monitor: give a bus URL (socketcand://HOST:PORT/BUS, socketcan://IFACE) or --log FILE, "
           "not both\n";
    return usage_error;
  }
  canopen::monitor::decoder dec;
  if (!args.no_drive_defaults) dec.describe_other_nodes(canopen::node_objects(apps::drive_node_config(0)));
  if (!describe_nodes(args, dec, err)) return usage_error;
  printer p(args, out);
  const int status = args.log.empty() ? watch_bus(args, dec, p, err) : decode_log(args, in, dec, p, err);
  out.flush();
  return status;
}

}  // namespace cia402::cli
