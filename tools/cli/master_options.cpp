// The options of `cia402 master` (CLI11). The steps and the options that belong to a step are read
// again in order by the step parser (master_steps.cpp).
#include <CLI/CLI.hpp>

#include "cli/common.hpp"
#include "cli/master.hpp"

namespace cia402::cli {

CLI::App* add_master_subcommand(CLI::App& app, master_args& args) {
  auto* cmd = app.add_subcommand(
      "master",
      "Drive CiA 402 drives over CANopen (--can URL --node N: SDO, then PDOs with SYNC) or EtherCAT (--ecat IF: "
      "scan, SII, OP, a cyclic LRW), running STEPS in order: state, enable, disable, quick-stop, reset, halt on|off, "
      "mode MODE, move POS, velocity RPM, torque PERMILLE, home [METHOD], jog RPM MS, csp-stream, wait MS, watch, "
      "sdo read|write, nmt (CANopen)");
  auto* can = cmd->add_option("--can", args.can,
                              "socketcand://HOST:PORT/BUS, socketcan://IFACE, or virtual (a virtual drive in-process)")
                   ->default_str("virtual");
  cmd->add_option("--ecat", args.ecat, "a network interface: our EtherCAT master there (raw socket, root)")->excludes(can);
  cmd->add_option("--position", args.position, "--ecat: the drive's position on the line, 0 first (default: all)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--node", args.node, "--can: the drive's node-ID")->check(CLI::Range(1, 127))->default_str("1");
  cmd->add_option("STEPS", args.words,
                  "the steps, in order, e.g. enable mode pp move 20000 velocity 300 wait 500 sdo read 0x1008")
      ->required();
  cmd->add_flag("--json", args.json, "one JSON object a line: every event and every step's result");
  add_profile_options(*cmd, args.profile, args.profile_file, "the drive's profile");
  cmd->add_option("--eds", args.eds, "--can: the node's EDS or DCF (CiA 306), for the types of its objects");
  cmd->add_option("--cycle", args.cycle_ms, "--can: the SYNC period in ms")->check(CLI::Range(1, 1000))->default_str("10");
  cmd->add_option("--timeout", args.timeout_ms, "each step must end within this many ms (watch: how long; 0 = no limit)")
      ->default_str("10000");
  cmd->add_option("--heartbeat", args.heartbeat_ms, "--can: the drive's heartbeat period in ms, watched (0 = off)")
      ->default_str("100");
  cmd->add_option("--guard", args.guard_ms,
                  "--can: send the master's heartbeat at this period in ms and have the drive watch it, so 0x6007 "
                  "acts if the master stops (0 = off)")
      ->default_str("0");
  cmd->add_flag("--hold", args.hold, "after the steps, keep the drives as they are until SIGINT or SIGTERM");
  cmd->add_option("--sync-us", args.sync_us,
                  "--can: the SYNC period in microseconds for csp-stream (one set-point each); --ecat: the cycle")
      ->check(CLI::Range(100, 1000000))
      ->default_str("1000")
      ->each([&args](const std::string&) { args.sync_us_given = true; });
  // A step's options: taken here wherever they stand, given to their step by the step parser.
  for (const char* name : {"--velocity", "--to", "--offset", "--method"}) {
    cmd->add_option(name, args.step_values)
        ->description(std::string(name) == "--velocity" ? "move: 0x6081 in rpm; csp-stream: the ramp's speed in rpm"
                      : std::string(name) == "--to"     ? "csp-stream: where the ramp of 0x607A ends, in increments"
                      : std::string(name) == "--offset" ? "home: the home offset 0x607C, in increments"
                                                        : "home: the homing method 0x6098 (one of 0x60E3: 1..14, 17..30, 33, 34, 35, 37)")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  }
  cmd->add_flag("--relative", args.relative_flags, "move: POSITION adds to the last target (control bit 6)");
  return cmd;
}

}  // namespace cia402::cli
