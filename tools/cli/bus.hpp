// `cia402 bus`: a socketcand server (a virtual CAN bus on TCP) with N virtual drives, each a CiA 301
// slave around the simulator's drive, stepping its plant in real time. Any socketcand client joins
// (python-can's socketcand interface, `cia402 master --can socketcand://...`). Stops cleanly on
// SIGINT / SIGTERM.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace cia402::cli {

struct bus_args {
  std::string listen = "127.0.0.1:29536";  ///< HOST:PORT; port 0 = any free port (printed)
  bool allow_remote = false;  ///< listen beyond loopback (socketcand has no authentication)
  std::string nodes = "1-4";               ///< "1-4", "2", "1,5,9"
  std::string profile = "cia402";
  std::string profile_file;
  std::string bus_name = "can0";
  std::uint16_t heartbeat_ms = 0;          ///< default of every drive's 0x1017
  std::string log;                         ///< candump log of every frame; "" = none
};

CLI::App* add_bus_subcommand(CLI::App& app, bus_args& args);

/// Runs until SIGINT or SIGTERM. Exit status 0 after a signal (1 if the log could not be written to
/// the end); 2 for a refused option (bad node list, unknown profile, address in use, a log file that
/// cannot be created).
int run_bus(const bus_args& args, std::ostream& out, std::ostream& err);

/// "1-4" -> {1,2,3,4}; "1,5" -> {1,5}. False with a reason for anything outside 1..127 or repeated.
bool parse_node_list(const std::string& text, std::vector<std::uint8_t>& out, std::string& why);

}  // namespace cia402::cli
