// `cia402 monitor`: the frames of a CAN bus decoded as CANopen, one line (or one JSON object) per
// frame, from a socketcand server or a SocketCAN interface as they come, or from a candump log.
// The decoding is canopen/monitor's; this file reads the options, the source and the clock.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace cia402::cli {

struct monitor_args {
  std::string url;                 ///< socketcand://HOST:PORT/BUS or socketcan://IFACE
  std::string log;                 ///< a candump log to decode instead ("-": standard input)
  std::vector<std::string> eds;    ///< EDS files, one per --node (or naming their node)
  std::vector<int> nodes;
  bool no_drive_defaults = false;  ///< nodes without --eds are not taken for the cia402 drive
  bool json = false;
  bool raw = false;                ///< the frame as ID#DATA beside the text
  std::uint64_t count = 0;         ///< stop after this many frames; 0 = no limit
  std::uint64_t duration_ms = 0;   ///< stop after this long; 0 = no limit
};

CLI::App* add_monitor_subcommand(CLI::App& app, monitor_args& args);

/// Exit status 0 at the end of the log, after --count or --duration, or on SIGINT / SIGTERM; 1 when
/// the bus cannot be joined or goes away; 2 for a refused option (a bad URL, an EDS that does not
/// parse, a log that cannot be read) and when lines of the log were refused (each is named on
/// standard error, the rest is decoded).
int run_monitor(const monitor_args& args, std::istream& in, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
