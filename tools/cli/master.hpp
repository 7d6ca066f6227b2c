// `cia402 master`: one command set for a CiA 402 drive over CANopen (`--can URL --node N`) or the
// drives of an EtherCAT line (`--ecat IF [--position N]`). The words after the options are steps
// run in order in one session per drive (the axis layer, include/cia402/axis/session.hpp): state,
// enable, disable, quick-stop, reset, halt on|off, mode MODE, move POS [--relative] [--velocity RPM],
// velocity RPM, torque PERMILLE, home [METHOD] [--offset INC], jog RPM MS, csp-stream --to POS
// --velocity RPM, wait MS, watch, sdo read INDEX[:SUB], sdo write INDEX[:SUB] VALUE, and on CANopen
// nmt start|stop|preop|reset|reset-communication. docs/master.md has every step, option, JSON shape
// and exit status.
//
// The files: master_options.cpp (the options), master_steps.cpp (the step parser), master_buses.cpp
// (the buses: a CAN channel or the virtual bus, an EtherCAT line), master_run.cpp (the runner),
// master_output.cpp (prose and JSON lines).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace cia402::cli {

struct master_args {
  std::string can = "virtual";  ///< socketcand://HOST:PORT/BUS, socketcan://IFACE, or virtual
  std::string ecat;             ///< a network interface: our EtherCAT master there instead of CANopen
  std::optional<int> position;  ///< --ecat: the slave's position on the line (all when not given)
  int node = 1;
  std::vector<std::string> words;  ///< the steps as CLI11 collected them (checked, not used)
  /// The whole command line from "master" on: the steps and their options are read from it in
  /// order (CLI11 keeps positionals and options apart).
  std::vector<std::string> raw;
  bool json = false;  ///< one JSON object a line
  std::string profile = "cia402";
  std::string profile_file;
  std::string eds;                   ///< CANopen: the node's EDS or DCF, for the types of its objects
  std::uint32_t cycle_ms = 10;       ///< CANopen: the SYNC period
  std::uint32_t timeout_ms = 10000;  ///< each step; watch: how long (0 = until a signal)
  std::uint16_t heartbeat_ms = 100;  ///< CANopen: the drive's heartbeat, watched by the master
  std::uint16_t guard_ms = 0;        ///< CANopen: the master's heartbeat, watched by the drive (0x6007)
  bool hold = false;                 ///< after the steps, keep the drives as they are until a signal
  std::uint32_t sync_us = 1000;      ///< csp-stream's SYNC period on CANopen; the LRW cycle on EtherCAT
  bool sync_us_given = false;
  // Step options: CLI11 takes them anywhere; the step parser gives each to the step before it.
  std::vector<std::string> step_values;
  int relative_flags = 0;
};

CLI::App* add_master_subcommand(CLI::App& app, master_args& args);

/// Exit status: 0 every step done; 1 a step failed (the drive, the bus, a time-out); 2 refused
/// input (an option, a step, a value outside its object's type).
int run_master(const master_args& args, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
