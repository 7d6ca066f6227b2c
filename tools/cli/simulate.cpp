#include "cli/simulate.hpp"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <variant>

#include "cia402/sim/scenario.hpp"
#include "cia402/sim/trace.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

constexpr int refused = 2;

enum class trace_format { none, csv, jsonl, vcd };

trace_format format_of(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".csv") return trace_format::csv;
  if (ext == ".jsonl") return trace_format::jsonl;
  if (ext == ".vcd") return trace_format::vcd;
  return trace_format::none;
}

}  // namespace

CLI::App* add_simulate_subcommand(CLI::App& app, simulate_args& args) {
  auto* cmd = app.add_subcommand(
      "simulate",
      "Run a scenario file (TOML: profile, plant, timed events, expectations) on a virtual drive; "
      "print its log and exit 1 if an expectation fails, 2 if the file is refused");
  cmd->add_option("FILE", args.file, "the scenario, e.g. examples/scenarios/quick-stop-2.toml")
      ->required();
  cmd->add_option("--trace", args.trace, "write one row per cycle to a .csv, .jsonl or .vcd file")
      ->type_name("FILE");
  cmd->add_option("--plot", args.plot, "draw velocity, states and transitions to an .svg file")
      ->type_name("FILE");
  cmd->add_option("--every", args.every,
                  "CSV/JSONL: keep every N-th cycle (rows where anything but the velocity "
                  "changes are always kept)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--quiet", args.quiet, "print only failures and the summary");
  cmd->add_flag("--vcd-standard", args.vcd_standard,
                "VCD: state and ramp as integer codes (IEEE 1364) instead of GTKWave's strings");
  return cmd;
}

int run_simulate(const simulate_args& args, std::ostream& out, std::ostream& err) {
  using namespace cia402::sim;
  const trace_format format = args.trace.empty() ? trace_format::none : format_of(args.trace);
  if (!args.trace.empty() && format == trace_format::none) {
    err << "cia402 simulate: --trace " << args.trace
        << ": the extension must be .csv, .jsonl or .vcd\n";
    return refused;
  }
  if (!args.plot.empty() && std::filesystem::path(args.plot).extension() != ".svg") {
    err << "cia402 simulate: --plot " << args.plot << ": the extension must be .svg\n";
    return refused;
  }

  scenario_load_result loaded = load_scenario_file(args.file);
  if (const auto* e = std::get_if<scenario_error>(&loaded)) {
    err << "cia402 simulate: scenario refused: " << e->message() << "\n";
    return refused;
  }
  const scenario& s = std::get<scenario>(loaded);

  // Open the outputs before running, so a path that cannot be written refuses the run.
  std::ofstream trace_file;
  std::ofstream plot_file;
  if (!args.trace.empty() && !open_output(trace_file, args.trace, "simulate", err, std::ios::binary)) return refused;
  if (!args.plot.empty() && !open_output(plot_file, args.plot, "simulate", err, std::ios::binary)) return refused;

  const std::uint64_t duration_us = (s.cycles - 1) * s.plant.cycle_us;
  if (!args.quiet) {
    out << "cia402 simulate " << args.file << "\n"
        << "scenario: " << s.name << "\n"
        << "profile " << s.drive_profile.get().name << ", cycle " << s.plant.cycle_us << " us, "
        << s.cycles << " cycles (0 .. " << format_seconds(duration_us) << " s), "
        << (s.plant.brake_fitted ? "brake fitted" : "no brake") << "\n\n";
  }
  const run_result r =
      run_scenario(s, run_options{!args.trace.empty() || !args.plot.empty()});
  for (const log_entry& e : r.log) {
    if (args.quiet && !e.failed) continue;
    out << format_log_entry(e) << "\n";
  }

  trace_info info;
  info.title = s.name;
  info.profile_name = s.drive_profile.get().name;
  info.cycle_us = s.plant.cycle_us;
  info.brake_fitted = s.plant.brake_fitted;
  info.vcd_standard = args.vcd_standard;
  switch (format) {
    case trace_format::csv: write_csv(trace_file, r.trace, args.every); break;
    case trace_format::jsonl: write_jsonl(trace_file, r.trace, args.every); break;
    case trace_format::vcd: write_vcd(trace_file, r.trace, info); break;
    case trace_format::none: break;
  }
  if (!args.plot.empty()) write_svg_plot(plot_file, r.trace, info);
  if ((trace_file.is_open() && !trace_file.flush()) || (plot_file.is_open() && !plot_file.flush())) {
    err << "cia402 simulate: writing the output failed\n";
    return refused;
  }

  out << (args.quiet ? "" : "\n") << s.name << ": " << (r.checks - r.failures) << " of "
      << r.checks << " checks passed" << (r.passed() ? "" : ", " + std::to_string(r.failures) + " FAILED")
      << "\n";
  return r.passed() ? 0 : 1;
}

}  // namespace cia402::cli
