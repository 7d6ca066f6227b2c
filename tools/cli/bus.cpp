#include "cli/bus.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <optional>
#include <memory>
#include <ostream>

#include "cia402/apps/bus_host.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/transport/socketcand.hpp"
#include "cia402/page/server.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

constexpr int usage_error = 2;


bool split_host_port(const std::string& text, std::string& host, std::uint16_t& port,
                     std::string& why) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    why = "expected HOST:PORT, e.g. 127.0.0.1:29536";
    return false;
  }
  const auto p = parse_number(text.substr(colon + 1));
  if (!p || *p < 0 || *p > 65535) {
    why = "port '" + text.substr(colon + 1) + "' is not 0..65535";
    return false;
  }
  host = text.substr(0, colon);
  port = static_cast<std::uint16_t>(*p);
  return true;
}

}  // namespace

bool parse_node_list(const std::string& text, std::vector<std::uint8_t>& out, std::string& why) {
  std::vector<std::uint8_t> ids;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto dash = part.find('-');
    const auto first = parse_number(part.substr(0, dash));
    const auto last = dash == std::string::npos ? first : parse_number(part.substr(dash + 1));
    if (!first || !last || *first < 1 || *last > 127 || *first > *last) {
      why = "'" + part + "' is not a node-ID 1..127 or a range like 1-4";
      return false;
    }
    for (auto id = *first; id <= *last; ++id) {
      for (std::uint8_t seen : ids) {
        if (seen == id) {
          why = "node " + std::to_string(id) + " is listed twice";
          return false;
        }
      }
      ids.push_back(static_cast<std::uint8_t>(id));
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  out = ids;
  return true;
}

CLI::App* add_bus_subcommand(CLI::App& app, bus_args& args) {
  auto* cmd = app.add_subcommand(
      "bus",
      "Serve a virtual CAN bus over socketcand (TCP) with virtual CiA 402 drives as CANopen nodes, "
      "stepping in real time until SIGINT/SIGTERM");
  cmd->add_option("--listen", args.listen,
                  "HOST:PORT to listen on; port 0 picks a free one; anything but loopback needs "
                  "--allow-remote")
      ->default_str("127.0.0.1:29536");
  cmd->add_flag("--allow-remote", args.allow_remote,
                "listen beyond loopback although socketcand has no authentication: whoever reaches "
                "the port controls the drives");
  cmd->add_option("--nodes", args.nodes, "node-IDs of the drives: 1-4, 2, 1,5,9")->default_str("1-4");
  add_profile_options(*cmd, args.profile, args.profile_file);
  cmd->add_option("--bus-name", args.bus_name, "the bus name clients open")->default_str("can0");
  cmd->add_option("--heartbeat", args.heartbeat_ms, "each drive's heartbeat period in ms (0x1017), 0 = off")
      ->default_str("0");
  cmd->add_option("--log", args.log,
                  "write every frame on the bus to FILE in candump's log format "
                  "((SECONDS.MICROS) BUS ID#DATA), readable by canplayer, python-can and "
                  "`cia402 monitor --log`")
      ->type_name("FILE");
  return cmd;
}

int run_bus(const bus_args& args, std::ostream& out, std::ostream& err) {
  std::string why;
  std::vector<std::uint8_t> ids;
  if (!parse_node_list(args.nodes, ids, why)) {
    err << "cia402 bus: --nodes " << args.nodes << ": " << why << "\n";
    return usage_error;
  }
  canopen::socketcand::server_config config;
  if (!split_host_port(args.listen, config.host, config.port, why)) {
    err << "cia402 bus: --listen " << args.listen << ": " << why << "\n";
    return usage_error;
  }
  if (!page::is_loopback_address(config.host) && !args.allow_remote) {
    err << "cia402 bus: --listen " << args.listen
        << ": socketcand has no authentication, so whoever reaches that address controls every "
           "drive on the bus; listen on loopback (127.0.0.1), or add --allow-remote on a network "
           "you trust\n";
    return usage_error;
  }
  config.bus_name = args.bus_name;
  profile_choice choice;
  if (!choice.resolve(args.profile, args.profile_file, err)) return usage_error;

  apps::bus_host host(config);
  // The log first: a path that cannot be written is refused before anything listens, and the
  // drives' boot-up messages are on it.
  if (!args.log.empty()) {
    if (const auto ec = host.log_frames(args.log, args.bus_name)) {
      err << "cia402 bus: --log " << args.log << ": cannot create the file: " << ec.message() << "\n";
      return usage_error;
    }
  }
  for (std::uint8_t id : ids) {
    canopen::slave_config sc = apps::drive_node_config(id);
    sc.heartbeat_ms = args.heartbeat_ms;
    host.add_drive(choice.get(), sc);
  }
  if (const auto ec = host.open()) {
    err << "cia402 bus: cannot listen on " << args.listen << ": " << ec.message() << "\n";
    return usage_error;
  }
  // Handlers before the line that tells a parent the bus is up, so a stop right after it counts.
  std::optional<stop_signals> stop(std::in_place);

  out << "cia402 bus: socketcand on " << config.host << ":" << host.server().port() << " bus "
      << config.bus_name << ", " << host.drives().size() << " drive(s) (profile " << choice.get().name
      << "), nodes " << args.nodes << (args.log.empty() ? "" : ", log " + args.log) << std::endl;

  host.run(stop_signals::flag());
  stop.reset();
  if (const auto ec = host.log_failure()) {
    err << "cia402 bus: --log " << args.log << ": writing failed after " << host.frames_logged()
        << " frames: " << ec.message() << "\n";
    out << "cia402 bus: stopped" << std::endl;
    return 1;
  }
  out << "cia402 bus: stopped" << std::endl;
  return 0;
}

}  // namespace cia402::cli
