// `cia402 master --can URL --node N COMMAND`: a CANopen master for one CiA 402 drive on a real or
// virtual bus: NMT start, PDO set-up over SDO, then the core's master step over PDOs with SYNC
// (canopen/drive_master.hpp). COMMAND: state (read 0x6041 over SDO and print), enable, disable,
// quick-stop, reset (fault reset), watch (print state changes, velocity and EMCYs), velocity RPM
// (enable, write 0x60FF, wait until the shaft turns at it), mode MODE (0x6060, confirmed by 0x6061),
// move POSITION (profile position: enable, 0x607A, the set-point handshake, wait for target
// reached), home (homing with --method / --offset, wait for homing attained), csp-stream --to POSITION
// --velocity RPM (cyclic synchronous position: a ramp of 0x607A in RPDO3 before every SYNC, 0x6064
// from TPDO3, the largest following error reported); for test benches, without
// any set-up: sdo read INDEX[:SUB], sdo write INDEX[:SUB] VALUE, nmt start|stop|preop|reset.
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
  std::string command;
  std::vector<std::string> operands;  ///< after sdo / nmt: what to read, write or send
  bool json = false;                  ///< one JSON object a line (state, sdo: one; others: per event)
  std::string profile = "cia402";
  std::string profile_file;
  std::uint32_t cycle_ms = 10;       ///< SYNC period
  std::uint32_t timeout_ms = 10000;  ///< the whole command; watch: how long to watch (0 = until a signal)
  std::uint16_t heartbeat_ms = 100;  ///< the drive's heartbeat, watched by the master
  std::uint16_t guard_ms = 0;        ///< the master's heartbeat, watched by the drive (0x6007)
  bool hold = false;                 ///< after reaching the target, keep cycling until a signal
  bool relative = false;             ///< move: the position adds to the last target
  std::optional<std::int64_t> profile_velocity;  ///< move: 0x6081; csp-stream: the ramp's speed
  std::optional<std::int64_t> stream_to;         ///< csp-stream: where the ramp ends
  std::uint32_t sync_us = 1000;                  ///< csp-stream: SYNC period
  std::optional<std::int64_t> homing_method;     ///< home: 0x6098
  std::optional<std::int64_t> home_offset;       ///< home: 0x607C
};

CLI::App* add_master_subcommand(CLI::App& app, master_args& args);

/// Exit status: 0 done; 1 the drive or the bus failed (missing node, SDO abort, lost heartbeat,
/// fault, timeout); 2 a refused option.
int run_master(const master_args& args, std::ostream& out, std::ostream& err);
/// `--ecat IF`: the EtherCAT master (master_ecat.cpp); COMMAND and OPERANDS are steps run in order.
int run_ecat_master(const master_args& args, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
