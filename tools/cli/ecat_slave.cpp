#include "cli/ecat_slave.hpp"

#include <CLI/CLI.hpp>
#include <optional>
#include <ostream>

#include "cia402/apps/ethercat_host.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {


}  // namespace

CLI::App* add_ecat_slave_subcommand(CLI::App& app, ecat_slave_args& args) {
  auto* cmd = app.add_subcommand(
      "ecat-slave", "Run virtual CiA 402 drives as EtherCAT CoE slaves on a network interface (raw socket, root)");
  cmd->add_option("--iface", args.iface, "the network interface the master is on (e.g. a veth end)")->required();
  cmd->add_option("--nodes", args.nodes, "drives chained on the interface")->check(CLI::Range(1, 64))->default_str("1");
  add_profile_options(*cmd, args.profile, args.profile_file, "the drives' profile");
  cmd->add_option("--cycle-us", args.cycle_us, "the drives' application cycle in microseconds")
      ->check(CLI::Range(100, 100000))
      ->default_str("1000");
  return cmd;
}

int run_ecat_slave(const ecat_slave_args& args, std::ostream& out, std::ostream& err) {
  profile_choice choice;
  if (!choice.resolve(args.profile, args.profile_file, err)) return 2;
  apps::ethercat_host host(choice.get(), args.nodes, args.cycle_us);
  if (const std::error_code ec = host.open(args.iface)) {
    err << "cia402 ecat-slave: cannot open " << args.iface << ": " << ec.message()
        << (ec.value() == EPERM ? " (a raw socket needs root or CAP_NET_RAW)" : "") << "\n";
    return 1;
  }
  std::optional<stop_signals> stop(std::in_place);
  out << "cia402 ecat-slave: " << args.nodes << " drive(s) on " << args.iface << " (profile " << choice.get().name
      << ", cycle " << args.cycle_us << " us)" << std::endl;
  host.run(stop_signals::flag());
  stop.reset();
  out << "cia402 ecat-slave: stopped after " << host.frames_answered() << " frame(s), " << host.frames_refused()
      << " refused" << std::endl;
  return 0;
}

}  // namespace cia402::cli
