// `cia402 esi`: the ETG.2000 ESI file of the virtual drive as an EtherCAT CoE slave, from the same
// description its SII EEPROM image is built from (apps/virtual_drive_slave.hpp), like `cia402 eds` for CANopen.
#pragma once

#include <iosfwd>
#include <string>

namespace CLI {
class App;
}

namespace cia402::cli {

struct esi_args {
  std::string output;  ///< file, or standard output when empty
};

CLI::App* add_esi_subcommand(CLI::App& app, esi_args& args);
/// Exit status 0; 2 for an output file that cannot be written.
int run_esi(const esi_args& args, std::ostream& out, std::ostream& err);

}  // namespace cia402::cli
