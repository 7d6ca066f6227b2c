#include "cli/serve.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <fstream>
#include <sstream>
#include <memory>
#include <vector>
#include <ostream>
#include <pthread.h>

#include "cia402/apps/elapsed_clock.hpp"
#include "cia402/apps/ethercat_link.hpp"
#include "cia402/apps/local_link.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/306/eds_reader.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/canopen/transport/channel_url.hpp"
#include "cia402/ethercat/axis/ecat_link.hpp"
#include "cia402/page/axis_page.hpp"
#include "cia402/page/runner.hpp"
#include "cia402/page/server.hpp"
#include "cli/common.hpp"
#include "cli/parameter_file.hpp"

namespace cia402::cli {
namespace {

constexpr int refused = 2;
constexpr int unreachable = 1;

// A virtual drive in this process behind the session, under the profile the page runs (again at
// each profile switch): the page sets its plant inputs through the simulator.
page::drive_connection virtual_drive(const profile& p) {
  auto link = std::make_unique<apps::local_link>(p);
  sim::virtual_drive* plant = &link->drive();
  return {std::move(link), plant};
}

// The drives behind the page, each an axis session's link: virtual drives here (local_link), or
// drives on a bus (can_link on a channel of its own, so each sees every frame; ecat_link on a line
// brought to OP here). The page itself holds no fieldbus code.
struct served_drives {
  // Declared before the drives, whose links use them: they go after the drives.
  std::unique_ptr<apps::ethercat_link> line;
  std::unique_ptr<ethercat::ecat_line> ecat;
  std::vector<std::unique_ptr<canopen::channel>> channels;
  std::vector<std::unique_ptr<page::axis_page>> drives;
  std::vector<page::axis> axes;
};

// The drive at --position on the line --ecat names; 0 or the exit status.
int open_ecat(const serve_args& args, const profile& p, page::axis_page_config pc, served_drives& d, std::ostream& err) {
  // A line answers in microseconds: 20 ms without an answer is a lost frame.
  d.line = std::make_unique<apps::ethercat_link>(20000);
  if (const std::error_code ec = d.line->open(args.ecat)) {
    err << "cia402 serve: cannot open " << args.ecat << ": " << ec.message()
        << (ec.value() == EPERM ? " (a raw socket needs root or CAP_NET_RAW)" : "") << "\n";
    return unreachable;
  }
  d.ecat = std::make_unique<ethercat::ecat_line>(*d.line, p, 1000, args.ecat);
  if (!d.ecat->scan() || !d.ecat->bring_to_operational()) {
    err << "cia402 serve: EtherCAT " << args.ecat << ": " << d.ecat->error() << "\n";
    return unreachable;
  }
  d.ecat->set_retry_us(1000000);  // a line that answers again is brought to OP again
  if (static_cast<std::size_t>(args.position) >= d.ecat->master().slaves().size()) {
    err << "cia402 serve: --position " << args.position << ": the line has " << d.ecat->master().slaves().size()
        << " slave(s)\n";
    return refused;
  }
  // The parameter list from the drive itself, as over CANopen: every object its SDO information
  // describes. A slave without it still shows the CiA 402 table.
  const ethercat::ecat_dictionary_result objects = d.ecat->master().read_dictionary(static_cast<std::size_t>(args.position));
  if (objects.ok) {
    pc.parameters = parameter_entries(objects.objects);
  } else {
    err << "cia402 serve: slave " << args.position << ": no SDO information (" << objects.error
        << "): the parameter list shows the CiA 402 objects only\n";
  }
  pc.reset_pulse_us = 20000;
  pc.settle_quiet_us = 150000;
  pc.node = args.position;
  pc.bus = "EtherCAT " + args.ecat;
  pc.where = "slave " + std::to_string(args.position) + " on EtherCAT " + args.ecat;
  auto* on_line = d.ecat.get();
  const auto position = static_cast<std::size_t>(args.position);
  d.drives.push_back(std::make_unique<page::axis_page>(
      p,
      [on_line, position](const profile&) {
        return page::drive_connection{std::make_unique<ethercat::ecat_link>(*on_line, position), nullptr};
      },
      pc));
  d.axes.push_back({"slave " + std::to_string(args.position), d.drives.back().get()});
  return 0;
}

// The nodes --node names on the bus --can names, a channel each; 0 or the exit status.
int open_can(const serve_args& args, const profile& p, page::axis_page_config pc, served_drives& d, std::ostream& err) {
  canopen::channel_url url;
  std::string why;
  if (!canopen::parse_channel_url(args.can, url, why)) {
    err << "cia402 serve: --can " << args.can << ": " << why << "\n";
    return refused;
  }
  if (url.type == canopen::channel_url::kind::virtual_bus) {
    err << "cia402 serve: --can virtual: without --can, serve runs a virtual drive here; for one "
           "on a CAN bus start `cia402 bus` and give its socketcand:// URL\n";
    return refused;
  }
  // The nodes' EDS or DCF: what their objects are, for the link and the page's parameter list.
  std::vector<dictionary::object_entry> eds;
  if (!args.eds.empty()) {
    std::ifstream in(args.eds);
    if (!in) {
      err << "cia402 serve: --eds " << args.eds << ": cannot read the file\n";
      return refused;
    }
    std::stringstream text;
    text << in.rdbuf();
    auto parsed = canopen::read_eds(text.str());
    if (const auto* e = std::get_if<canopen::eds_error>(&parsed)) {
      err << "cia402 serve: --eds " << args.eds << ":" << e->line << ": " << e->reason << "\n";
      return refused;
    }
    eds = std::move(std::get<canopen::eds_contents>(parsed).objects);
  }
  pc.reset_pulse_us = 20000;
  pc.settle_quiet_us = 150000;
  for (const int node : args.nodes) {
    for (const page::axis& a : d.axes) {
      if (a.label == "node " + std::to_string(node)) {
        err << "cia402 serve: --node " << node << " is given twice\n";
        return refused;
      }
    }
    d.channels.push_back(canopen::open_channel(url, why));
    if (!d.channels.back()) {
      err << "cia402 serve: cannot reach the bus " << args.can << ": " << why << "\n";
      return unreachable;
    }
    canopen::can_link_config c;
    c.node_id = static_cast<std::uint8_t>(node);
    c.bus_name = args.can;
    c.drive_profile = &p;
    // The page's own heartbeat, watched by the drive (0x1016), on the wall clock: a page slowed
    // down by a loaded machine must still send it every 100 ms of wall time.
    c.master_heartbeat_ms = 100;
    c.retry_us = 1000000;  // a node that comes back (or restarts) is set up again
    c.known_objects = canopen::node_objects(apps::drive_node_config(static_cast<std::uint8_t>(node)));
    c.heartbeat_clock_us = [] {
      return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(
                                            std::chrono::steady_clock::now().time_since_epoch())
                                            .count());
    };
    canopen::channel* bus = d.channels.back().get();
    pc.node = node;
    pc.bus = args.can;
    c.eds = eds;
    pc.parameters = parameter_entries(eds.empty() ? c.known_objects : eds, node);
    d.drives.push_back(std::make_unique<page::axis_page>(
        p,
        [bus, c](const profile&) {
          return page::drive_connection{std::make_unique<canopen::can_link>(*bus, c), nullptr};
        },
        pc));
    d.axes.push_back({"node " + std::to_string(node), d.drives.back().get()});
  }
  return 0;
}

}  // namespace

CLI::App* add_serve_subcommand(CLI::App& app, serve_args& args) {
  auto* cmd = app.add_subcommand(
      "serve",
      "Run a virtual drive in real time, or with --can show a drive on a CAN bus, or with --ecat one on "
      "an EtherCAT line, and serve its "
      "instrument control page (control and status word bits, the state machine, the plant) on "
      "http://127.0.0.1:8402/; Ctrl-C stops");
  add_profile_options(*cmd, args.profile_name, args.profile_file,
                      "built-in profile (with --can: the drive's, to read its words)");
  cmd->add_option("--bind", args.bind,
                  "address to listen on; anything but loopback makes control need the token "
                  "printed at start")
      ->type_name("ADDRESS")
      ->default_str("127.0.0.1");
  cmd->add_option("--port", args.port, "TCP port; 0 picks a free one")
      ->type_name("PORT")
      ->check(CLI::Range(0, 65535))
      ->default_str("8402");
  cmd->add_flag("--token-required", args.token_required,
                "require the printed token for control even on loopback");
  auto* can = cmd->add_option("--can", args.can,
                              "show a drive on a CAN bus instead of running a virtual drive here: "
                              "socketcand://HOST:PORT/BUS (e.g. a cia402 bus) or socketcan://IFACE")
                  ->type_name("URL");
  auto* node = cmd->add_option("--node", args.nodes,
                               "with --can: the drive's node-ID; repeat it for several drives, one "
                               "axis of the page each")
                   ->type_name("N")
                   ->check(CLI::Range(1, 127))
                   ->default_str("1")
                   ->needs(can);
  cmd->add_option("--eds", args.eds,
                  "with --can: the nodes' EDS or DCF (CiA 306): their objects' types for the link, "
                  "and the entries of the page's parameter list beyond the CiA 402 table")
      ->type_name("FILE")
      ->needs(can);
  cmd->add_option("--nodes", args.virtual_axes,
                  "without --can: run this many virtual drives, one axis of the page each")
      ->type_name("N")
      ->check(CLI::Range(1, 16))
      ->default_str("1")
      ->excludes(can)
      ->excludes(node);
  auto* ecat = cmd->add_option("--ecat", args.ecat,
                               "show a drive on an EtherCAT line: the network interface our master runs "
                               "the line on (raw socket, root)")
                   ->type_name("IFACE")
                   ->excludes(can)
                   ->excludes(node);
  cmd->add_option("--position", args.position, "with --ecat: the drive's position on the line, 0 first")
      ->type_name("N")
      ->check(CLI::Range(0, 65535))
      ->default_str("0")
      ->needs(ecat);
  cmd->add_option("--lease", args.lease_ms,
                  "the page's sign of life: when no open page (its event stream) or request renewed it "
                  "for this long, a drive left enabled is stopped as its 0x6007 says; 0: never")
      ->type_name("MS")
      ->check(CLI::Range(0, 600000))
      ->default_str("1000");
  return cmd;
}

int run_serve(const serve_args& args, std::ostream& out, std::ostream& err) {
  profile_choice choice;
  if (!choice.resolve(args.profile_name, args.profile_file, err)) return refused;

  page::server_options options;
  options.bind = args.bind;
  options.port = args.port;
  const bool loopback = page::is_loopback_address(args.bind);
  options.token_required = args.token_required || !loopback;

  served_drives served;
  page::axis_page_config pc;
  pc.lease_us = static_cast<std::uint64_t>(args.lease_ms) * 1000;
  pc.wall_clock_us = apps::unix_time_us;
  pc.parameter_file = dcf_parameter_file();
  if (!args.ecat.empty()) {
    if (const int status = open_ecat(args, choice.get(), pc, served, err)) return status;
  } else if (!args.can.empty()) {
    if (const int status = open_can(args, choice.get(), pc, served, err)) return status;
  } else {
    for (int k = 1; k <= args.virtual_axes; ++k) {
      // Selectable on the page: the built-in profiles and this one (axis_page_config's default).
      served.drives.push_back(std::make_unique<page::axis_page>(choice.get(), virtual_drive, pc));
      served.axes.push_back({"axis " + std::to_string(k), served.drives.back().get()});
    }
  }
  auto& drives = served.drives;
  auto& axes = served.axes;
  page::server http(axes, options);

  // SIGINT and SIGTERM are blocked in every thread (the server's and the cycle thread inherit the
  // mask) and taken here by sigwait, so stopping is ordinary code, not a signal handler.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  sigset_t previous;
  pthread_sigmask(SIG_BLOCK, &stop_signals, &previous);
  // A client that goes away mid-write must not kill the process.
  std::signal(SIGPIPE, SIG_IGN);

  if (!http.bind()) {
    pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    err << "cia402 serve: " << http.error() << "\n";
    return refused;
  }
  std::vector<std::unique_ptr<page::cycle_runner>> runners;
  for (auto& d : drives) {
    runners.push_back(std::make_unique<page::cycle_runner>(*d, std::chrono::microseconds(1000)));
    runners.back()->start();
  }
  http.start();

  std::string what;
  for (const page::axis& a : axes) what += (what.empty() ? "" : ", ") + a.label;
  if (!args.ecat.empty()) {
    out << "cia402 serve: " << what << " on EtherCAT " << args.ecat << " (profile " << choice.get().name
        << "), instrument page at " << http.url() << "\n";
  } else if (args.can.empty()) {
    out << "cia402 serve: profile " << choice.get().name
        << (axes.size() > 1 ? ", " + std::to_string(axes.size()) + " virtual drives" : std::string())
        << ", instrument page at " << http.url() << "\n";
  } else {
    out << "cia402 serve: " << what << " on " << args.can << " (profile " << choice.get().name
        << "), instrument page at " << http.url() << "\n";
  }
  if (!loopback) {
    out << "cia402 serve: listening on " << args.bind
        << ", not loopback: control needs the token in that URL, without it the page is "
           "view-only\n";
  } else if (options.token_required) {
    out << "cia402 serve: control needs the token in that URL; without it the page is view-only\n";
  }
  out << "cia402 serve: Ctrl-C stops" << std::endl;

  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  out << "cia402 serve: stopping (" << (signal_number == SIGINT ? "SIGINT" : "SIGTERM") << ")"
      << std::endl;
  for (auto& d : drives) d->close();
  http.stop();
  for (auto& r : runners) r->stop();
  // Each link puts back what it changed on its node (a drive left enabled stops first, as 0x6007
  // says).
  for (auto& d : served.drives) d->shut_down(std::chrono::seconds(2));
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return 0;
}

}  // namespace cia402::cli
