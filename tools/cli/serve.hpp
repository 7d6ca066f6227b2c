// `cia402 serve`: the instrument control page (seed 003_83442f2f4b0b2bb9.txt) for virtual drives
// run in real time (--nodes N: N axes), or with --can URL --node N [--node M ...] for drives on a
// CAN bus (a `cia402 bus` node or a real drive), or with --ecat IF --position N for a drive on an
// EtherCAT line; each drive an axis session over the link built here (src/page/include/cia402/page/
// axis_page.hpp), served over HTTP; see src/page/include/cia402/page/server.hpp.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace cia402::cli {

struct serve_args {
  std::string profile_name = "cia402";
  std::string profile_file;
  std::string bind = "127.0.0.1";
  int port = 8402;              ///< 0: any free port (the URL printed names it)
  bool token_required = false;  ///< also on for any --bind address that is not loopback
  std::string can;              ///< socketcand://HOST:PORT/BUS or socketcan://IFACE; "" = virtual drive
  std::vector<int> nodes{1};    ///< with --can: the drives' node-IDs, one axis each
  std::string eds;              ///< with --can: the nodes' EDS or DCF (CiA 306), "" for none
  int virtual_axes = 1;         ///< without --can: how many virtual drives (--nodes N)
  std::string ecat;             ///< a network interface: the drive on that EtherCAT line instead
  int position = 0;             ///< with --ecat: the drive's position on the line, 0 first
  /// The page's sign of life: a drive left enabled stops as its 0x6007 says when no page renewed it
  /// for this long (ms); 0: never.
  int lease_ms = 1000;
};

/// Registers the subcommand on `app`, filling `args` when it is parsed.
CLI::App* add_serve_subcommand(CLI::App& app, serve_args& args);

/// Serves until SIGINT or SIGTERM, then stops the server and the cycle thread and returns 0.
/// Returns 2 without serving if the profile or the --can URL is refused or the address cannot be
/// bound, 1 if the bus cannot be reached.
int run_serve(const serve_args& args, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
