#include "cli/app.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <functional>
#include <istream>
#include <ostream>
#include <utility>
#include <variant>

#include "cia402/profile_file.hpp"
#include "cli/common.hpp"
#include "cli/demo.hpp"
#include "cli/bus.hpp"
#include "cli/diagram.hpp"
#include "cli/eds.hpp"
#include "cli/ecat_slave.hpp"
#include "cli/esi.hpp"
#include "cli/master.hpp"
#include "cli/monitor.hpp"
#include "cli/path.hpp"
#include "cli/replay.hpp"
#include "cli/serve.hpp"
#include "cli/simulate.hpp"
#include "cli/decode.hpp"

namespace cia402::cli {
namespace {

constexpr int usage_error = 2;

int list_profiles(std::ostream& out) {
  std::size_t width = 4;
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    width = std::max(width, std::string_view(builtin_profile(i).name).size());
  }
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    const profile& p = builtin_profile(i);
    const std::string name = p.name;
    out << name << std::string(width + 2 - name.size(), ' ') << p.seed << "  " << p.title << "\n";
  }
  return 0;
}

// `cia402 profiles [--dump NAME]`.
int run_profiles(const std::string& dump_name, std::ostream& out, std::ostream& err) {
  if (dump_name.empty()) return list_profiles(out);
  const profile* p = find_builtin_profile(dump_name);
  if (p == nullptr) {
    err << "cia402 profiles: unknown profile '" << dump_name
        << "' (built-in: " << builtin_profile_names() << ")\n";
    return usage_error;
  }
  out << dump_profile_toml(*p);
  return 0;
}

// `cia402 decode WORD [--controlword] [--json]`.
int run_decode(const profile& p, const std::string& word_text, bool as_control_word, bool as_json,
               std::ostream& out, std::ostream& err) {
  const auto word = parse_number(word_text);
  if (!word || *word < 0 || *word > 0xFFFF) {
    err << "cia402 decode: '" << word_text << "' is not a 16-bit word (decimal or 0x hex)\n";
    return usage_error;
  }
  const auto w = static_cast<std::uint16_t>(*word);
  if (as_json) {
    out << (as_control_word ? control_word_json(p, w) : status_word_json(p, w)) << "\n";
  } else {
    out << (as_control_word ? describe_control_word(p, w) : describe_status_word(p, w));
  }
  return 0;
}

}  // namespace

int run(const std::vector<std::string>& args, std::istream& in, std::ostream& out,
        std::ostream& err) {
  CLI::App app{"Tools for the CiA 402 drive state machine.", "cia402"};
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", std::string("cia402 ") + CIA402_VERSION);

  std::string profile_name = "cia402";
  std::string profile_file;

  auto* replay = app.add_subcommand(
      "replay",
      "Run one drive on an ideal plant, reading events from standard input (cw VALUE, "
      "fault [CODE [CLASS]], clear, set INDEX VALUE, voltage on|off, sto on|off) and printing one "
      "JSON line per event");
  add_profile_options(*replay, profile_name, profile_file);
  std::vector<std::string> sets;
  replay->add_option("--set", sets, "write an option code before power-up, e.g. 0x605A=6")
      ->type_name("INDEX=VALUE");

  auto* decode = app.add_subcommand("decode",
                                    "Name the state and every bit of a status word, or "
                                    "the command and every bit of a control word");
  std::string word_text;
  decode->add_option("WORD", word_text, "the word, decimal or 0x hex")->required();
  bool as_control_word = false;
  decode->add_flag("--controlword", as_control_word, "WORD is a control word (0x6040)");
  bool decode_json = false;
  decode->add_flag("--json", decode_json, "one JSON object instead of the report, for scripts");
  add_profile_options(*decode, profile_name, profile_file);

  auto* profiles =
      app.add_subcommand("profiles", "List the built-in profiles, or dump one as TOML");
  std::string dump_name;
  profiles->add_option("--dump", dump_name, "print this built-in profile as a profile file")
      ->type_name("NAME");

  auto* demo = app.add_subcommand(
      "demo",
      "Take one drive through power-up, enable, quick stop, fault and reset, cycle by cycle");
  add_profile_options(*demo, profile_name, profile_file);

  auto* path = app.add_subcommand(
      "path", "Print the fewest-cycles command sequence from one state to another");
  std::string path_from;
  std::string path_to;
  path->add_option("FROM", path_from, "the state the drive is in, e.g. SWITCH_ON_DISABLED")
      ->required();
  path->add_option("TO", path_to, "the target state, e.g. OPERATION_ENABLED")->required();
  add_profile_options(*path, profile_name, profile_file);
  path->add_option("--set", sets, "option code the plan assumes, e.g. 0x605A=6")
      ->type_name("INDEX=VALUE");

  auto* diagram = app.add_subcommand(
      "diagram", "Draw the profile's state machine from its transition table");
  add_profile_options(*diagram, profile_name, profile_file);
  std::string diagram_format = "dot";
  diagram->add_option("--format", diagram_format, "dot, mermaid or svg (svg needs Graphviz)")
      ->check(CLI::IsMember({"dot", "mermaid", "svg"}))
      ->default_str("dot");

  // The commands with a file of their own: each entry adds the command's options and runs it once
  // parsed, so a new command is one entry here.
  simulate_args simulate_options;
  serve_args serve_options;
  bus_args bus_options;
  master_args master_options;
  master_options.raw = args;  // its steps and their options are read in order from here
  monitor_args monitor_options;
  eds_args eds_options;
  esi_args esi_options;
  ecat_slave_args ecat_slave_options;
  const std::pair<CLI::App*, std::function<int()>> own_file_commands[] = {
      {add_simulate_subcommand(app, simulate_options), [&] { return run_simulate(simulate_options, out, err); }},
      {add_serve_subcommand(app, serve_options), [&] { return run_serve(serve_options, out, err); }},
      {add_bus_subcommand(app, bus_options), [&] { return run_bus(bus_options, out, err); }},
      {add_master_subcommand(app, master_options), [&] { return run_master(master_options, out, err); }},
      {add_monitor_subcommand(app, monitor_options), [&] { return run_monitor(monitor_options, in, out, err); }},
      {add_eds_subcommand(app, eds_options), [&] { return run_eds(eds_options, out, err); }},
      {add_esi_subcommand(app, esi_options), [&] { return run_esi(esi_options, out, err); }},
      {add_ecat_slave_subcommand(app, ecat_slave_options), [&] { return run_ecat_slave(ecat_slave_options, out, err); }},
  };

  // A word that is not a command gets the list of commands, not CLI11's "subcommand required".
  const std::string first = args.empty() ? std::string() : args.front();
  const auto known = app.get_subcommands([&first](CLI::App* c) { return c->check_name(first); });
  if (!first.empty() && first.front() != '-' && known.empty()) {
    err << "cia402: unknown command '" << first << "'\n\n" << app.help();
    return usage_error;
  }
  try {
    std::vector<std::string> reversed(args.rbegin(), args.rend());
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every refused argument exits 2, as the tool's own refusals do.
    return app.exit(e, out, err) == 0 ? 0 : usage_error;
  }
  if (app.get_subcommands().empty()) {
    err << app.help();
    return usage_error;
  }

  for (const auto& [command, run] : own_file_commands) {
    if (command->parsed()) return run();
  }
  if (profiles->parsed()) return run_profiles(dump_name, out, err);

  profile_choice choice;
  if (!choice.resolve(profile_name, profile_file, err)) return usage_error;

  std::vector<option_write> writes;
  for (const std::string& s : sets) {
    option_write w;
    std::string why;
    if (!parse_option_write(s, w, why)) {
      err << "cia402 " << (path->parsed() ? "path" : "replay") << ": --set " << s << ": " << why
          << "\n";
      return usage_error;
    }
    writes.push_back(w);
  }
  if (replay->parsed()) return run_replay(choice.get(), writes, in, out, err);
  if (path->parsed()) return run_path(choice.get(), writes, path_from, path_to, out, err);
  if (diagram->parsed()) return run_diagram(choice.get(), diagram_format, out, err);
  if (decode->parsed()) return run_decode(choice.get(), word_text, as_control_word, decode_json, out, err);
  if (demo->parsed()) {
    run_demo(choice.get(), out);
    return 0;
  }
  return usage_error;
}

}  // namespace cia402::cli
