#include "cli/ecat_slave.hpp"

#include <sched.h>
#include <sys/mman.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <optional>
#include <string>
#include <ostream>

#include "cia402/apps/ethercat_host.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

// Real-time scheduling and locked memory, asked for before the drives are made, so their memory is
// locked too; each refusal says what it takes.
bool apply_real_time_options(const ecat_slave_args& args, std::ostream& err) {
  if (args.realtime_priority > 0) {
    sched_param param{};
    param.sched_priority = args.realtime_priority;
    if (::sched_setscheduler(0, SCHED_FIFO, &param) != 0) {
      const int e = errno;
      err << "cia402 ecat-slave: --realtime " << args.realtime_priority << ": SCHED_FIFO refused: " << std::strerror(e)
          << (e == EPERM ? " (it needs root or CAP_SYS_NICE, or an RLIMIT_RTPRIO of at least the priority;"
                           " in a container or cgroup, real-time runtime granted to it)"
                         : "")
          << "\n";
      return false;
    }
  }
  if (args.lock_memory && ::mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    const int e = errno;
    err << "cia402 ecat-slave: --lock-memory: mlockall refused: " << std::strerror(e)
        << (e == EPERM || e == ENOMEM ? " (it needs root or CAP_IPC_LOCK, or an RLIMIT_MEMLOCK (ulimit -l) large"
                                        " enough for the whole process)"
                                      : "")
        << "\n";
    return false;
  }
  return true;
}

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
  cmd->add_option("--realtime", args.realtime_priority,
                  "run under SCHED_FIFO at this priority (1..99; needs root or CAP_SYS_NICE), so load on the "
                  "host does not delay answers")
      ->check(CLI::Range(1, 99));
  cmd->add_flag("--lock-memory", args.lock_memory,
                "lock the process's memory (mlockall; needs root or CAP_IPC_LOCK), so no answer waits for a page "
                "fault");
  return cmd;
}

int run_ecat_slave(const ecat_slave_args& args, std::ostream& out, std::ostream& err) {
  profile_choice choice;
  if (!choice.resolve(args.profile, args.profile_file, err)) return 2;
  if (!apply_real_time_options(args, err)) return 1;
  apps::ethercat_host host(choice.get(), args.nodes, args.cycle_us);
  if (const std::error_code ec = host.open(args.iface)) {
    err << "cia402 ecat-slave: cannot open " << args.iface << ": " << ec.message()
        << (ec.value() == EPERM ? " (a raw socket needs root or CAP_NET_RAW)" : "") << "\n";
    return 1;
  }
  std::optional<stop_signals> stop(std::in_place);
  out << "cia402 ecat-slave: " << args.nodes << " drive(s) on " << args.iface << " (profile " << choice.get().name
      << ", cycle " << args.cycle_us << " us"
      << (args.realtime_priority > 0 ? ", SCHED_FIFO " + std::to_string(args.realtime_priority) : std::string())
      << (args.lock_memory ? ", memory locked" : "") << ")" << std::endl;
  host.run(stop_signals::flag());
  stop.reset();
  out << "cia402 ecat-slave: stopped after " << host.frames_answered() << " frame(s), " << host.frames_refused()
      << " refused" << std::endl;
  return 0;
}

}  // namespace cia402::cli
