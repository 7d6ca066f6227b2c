// `cia402 ecat-slave --iface IF [--nodes N] [--profile NAME] [--realtime PRIO] [--lock-memory]`: N virtual CiA 402 drives as a chain
// of EtherCAT CoE slaves on a network interface (apps/ethercat_host.hpp), until SIGINT or SIGTERM.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

namespace CLI {
class App;
}

namespace cia402::cli {

struct ecat_slave_args {
  std::string iface;
  int nodes = 1;
  std::string profile = "cia402";
  std::string profile_file;
  std::uint32_t cycle_us = 1000;
  int realtime_priority = 0;  ///< SCHED_FIFO priority 1..99 for the host's thread; 0: the default policy
  bool lock_memory = false;   ///< mlockall(MCL_CURRENT | MCL_FUTURE): no page fault in the answer path
};

CLI::App* add_ecat_slave_subcommand(CLI::App& app, ecat_slave_args& args);
/// Exit status 0 after a signal; 1 when the interface cannot be opened or real-time scheduling or
/// locked memory is not permitted; 2 for a refused option.
int run_ecat_slave(const ecat_slave_args& args, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
