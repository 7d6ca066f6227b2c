#include "cli/eds.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <ctime>
#include <fstream>
#include <ostream>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/306/eds.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cli/common.hpp"

namespace cia402::cli {

CLI::App* add_eds_subcommand(CLI::App& app, eds_args& args) {
  auto* cmd = app.add_subcommand("eds", "Write the CiA 306 EDS of the virtual drive (the objects `cia402 bus` serves)");
  add_profile_options(*cmd, args.profile, args.profile_file);
  cmd->add_option("--node", args.node,
                  "node-ID the file is written for: its values, and a [DeviceComissioning] section")
      ->check(CLI::Range(1, 127))
      ->default_str("1")
      ->each([&args](const std::string&) { args.node_given = true; });
  cmd->add_option("-o,--output", args.output, "write to this file instead of standard output");
  return cmd;
}

int run_eds(const eds_args& args, std::ostream& out, std::ostream& err) {
  profile_choice choice;
  if (!choice.resolve(args.profile, args.profile_file, err)) return 2;
  canopen::virtual_bus bus;
  auto ch = bus.attach();
  drive402::sim_device dev(choice.get());
  canopen::slave node(dev, *ch, apps::drive_node_config(static_cast<std::uint8_t>(args.node)));

  canopen::eds_info info;
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char date[16];
  char time[16];
  std::strftime(date, sizeof date, "%m-%d-%Y", &tm);
  std::strftime(time, sizeof time, "%I:%M%p", &tm);
  info.date = date;
  info.time = time;
  info.description += std::string(", profile ") + choice.get().name;
  if (args.node_given) info.node_id = static_cast<std::uint8_t>(args.node);
  if (args.output.empty()) {
    canopen::write_eds(node, info, out);
    return 0;
  }
  std::ofstream file;
  if (!open_output(file, args.output, "eds", err)) return 2;
  info.file_name = args.output.substr(args.output.find_last_of('/') + 1);
  canopen::write_eds(node, info, file);
  return file ? 0 : 2;
}

}  // namespace cia402::cli
