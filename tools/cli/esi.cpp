#include "cli/esi.hpp"

#include <CLI/CLI.hpp>
#include <fstream>
#include <ostream>

#include "cia402/ethercat/402/drive_description.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"

namespace cia402::cli {

CLI::App* add_esi_subcommand(CLI::App& app, esi_args& args) {
  auto* cmd = app.add_subcommand(
      "esi", "Write the EtherCAT ESI file (ETG.2000 XML) of the virtual drive as a CoE slave");
  cmd->add_option("-o,--output", args.output, "write to this file instead of standard output");
  return cmd;
}

int run_esi(const esi_args& args, std::ostream& out, std::ostream& err) {
  const std::string xml =
      ethercat::esi_xml(ethercat::drive_slave_description(ethercat::coe_drive_objects()));
  if (args.output.empty()) {
    out << xml;
    return 0;
  }
  std::ofstream file(args.output);
  if (!file) {
    err << "cia402 esi: cannot write " << args.output << "\n";
    return 2;
  }
  file << xml;
  return file ? 0 : 2;
}

}  // namespace cia402::cli
