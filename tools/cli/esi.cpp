#include "cli/esi.hpp"

#include <CLI/CLI.hpp>
#include <fstream>
#include <ostream>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "cli/common.hpp"

namespace cia402::cli {

CLI::App* add_esi_subcommand(CLI::App& app, esi_args& args) {
  auto* cmd = app.add_subcommand(
      "esi", "Write the EtherCAT ESI file (ETG.2000 XML) of the virtual drive as a CoE slave");
  cmd->add_option("-o,--output", args.output, "write to this file instead of standard output");
  return cmd;
}

int run_esi(const esi_args& args, std::ostream& out, std::ostream& err) {
  const std::string xml =
      ethercat::esi_xml(ethercat::coe_slave_description(apps::drive_slave_config()));
  if (args.output.empty()) {
    out << xml;
    return 0;
  }
  std::ofstream file;
  if (!open_output(file, args.output, "esi", err)) return 2;
  file << xml;
  return file ? 0 : 2;
}

}  // namespace cia402::cli
