// The tool as a new user meets it: no command, an unknown command, --version, --help, and argument
// errors that exit 2 like every refusal of the tool (not CLI11's own codes 105..109).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "replay_support.hpp"

namespace {

using cia402::test::run_tool;

TEST(app, no_command_lists_the_commands_and_exits_2) {
  const auto r = run_tool({});
  EXPECT_EQ(r.exit_code, 2);
  for (const char* command : {"replay", "decode", "path", "simulate", "serve", "bus", "master", "eds"}) {
    EXPECT_NE(r.err.find(command), std::string::npos) << command;
  }
}

TEST(app, an_unknown_command_is_named_and_the_commands_listed) {
  const auto r = run_tool({"frobnicate"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown command 'frobnicate'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("replay"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("A subcommand is required"), std::string::npos) << r.err;
}

TEST(app, version_and_help_exit_0) {
  const auto version = run_tool({"--version"});
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_EQ(version.out.rfind("cia402 ", 0), 0u) << version.out;
  EXPECT_EQ(run_tool({"--help"}).exit_code, 0);
  EXPECT_EQ(run_tool({"decode", "--help"}).exit_code, 0);
}

TEST(app, argument_errors_exit_2) {
  EXPECT_EQ(run_tool({"decode"}).exit_code, 2);                        // a required argument
  EXPECT_EQ(run_tool({"decode", "0x0237", "--nosuch"}).exit_code, 2);  // an unknown option
  EXPECT_EQ(run_tool({"diagram", "--format", "png"}).exit_code, 2);    // a value not allowed
  EXPECT_EQ(run_tool({"eds", "--node", "0"}).exit_code, 2);            // out of range
  EXPECT_EQ(run_tool({"path", "SOD"}).exit_code, 2);
}

TEST(app, an_output_file_that_cannot_be_written_exits_2_and_names_the_path) {
  const std::string nowhere = "/nonexistent-cia402-dir/out";
  const std::string scenario = CIA402_EXAMPLE_PROFILES_DIR "/../scenarios/quick-stop-2.toml";
  struct refusal {
    std::vector<std::string> args;
    std::string message;
  };
  for (const refusal& c : {refusal{{"eds", "-o", nowhere}, "cia402 eds: cannot write " + nowhere},
                           refusal{{"esi", "-o", nowhere}, "cia402 esi: cannot write " + nowhere},
                           refusal{{"simulate", scenario, "--trace", nowhere + ".csv"},
                                   "cia402 simulate: cannot write " + nowhere + ".csv"},
                           refusal{{"simulate", scenario, "--plot", nowhere + ".svg"},
                                   "cia402 simulate: cannot write " + nowhere + ".svg"}}) {
    const auto r = run_tool(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.message;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
}

}  // namespace
