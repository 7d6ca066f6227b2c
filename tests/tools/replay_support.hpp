// Runs `cia402 replay` through the tool's own entry point, with string streams.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include "cli/app.hpp"

namespace cia402::test {

struct tool_run {
  int exit_code = 0;
  std::vector<std::string> lines;  ///< standard output, one entry per line
  std::string out;
  std::string err;
};

inline tool_run run_tool(const std::vector<std::string>& args, const std::string& input = "") {
  std::istringstream in(input);
  std::ostringstream out;
  std::ostringstream err;
  tool_run r;
  r.exit_code = cli::run(args, in, out, err);
  r.out = out.str();
  r.err = err.str();
  std::istringstream split(r.out);
  for (std::string line; std::getline(split, line);) r.lines.push_back(line);
  return r;
}

/// Line `n` of the run's standard output holds every one of `parts` (a step of `cia402 path`: its
/// control word, its transition; a replay line: its state, its transitions). When not, the message
/// names the missing part and shows the line, or the whole output when there is no line `n`.
inline ::testing::AssertionResult line_names(const tool_run& r, std::size_t n, std::initializer_list<const char*> parts) {
  if (n >= r.lines.size()) return ::testing::AssertionFailure() << "no line " << n << " in:\n" << r.out;
  for (const char* part : parts) {
    if (r.lines[n].find(part) == std::string::npos) {
      return ::testing::AssertionFailure() << "line " << n << " does not name \"" << part << "\": " << r.lines[n];
    }
  }
  return ::testing::AssertionSuccess();
}

/// A replay line with only the fields the first replay interface printed (state, statusword,
/// transitions): those stay exactly as they were, and most tests are about them.
inline std::string first_fields(const std::string& line) {
  const std::string marker = "],\"torque\":";
  const std::size_t at = line.find(marker);
  return at == std::string::npos ? line : line.substr(0, at + 1) + "}";
}

/// `cia402 replay --profile NAME [--set ...]` on the input. `lines` holds the first fields of each
/// line (first_fields), `out` the whole output.
inline tool_run replay(const std::string& profile, const std::string& input,
                       const std::vector<std::string>& sets = {}) {
  std::vector<std::string> args = {"replay", "--profile", profile};
  for (const std::string& s : sets) {
    args.push_back("--set");
    args.push_back(s);
  }
  tool_run r = run_tool(args, input);
  for (std::string& line : r.lines) line = first_fields(line);
  return r;
}

/// Every line of a replay, whole.
inline std::vector<std::string> whole_lines(const tool_run& r) {
  std::vector<std::string> lines;
  std::istringstream split(r.out);
  for (std::string line; std::getline(split, line);) lines.push_back(line);
  return lines;
}

/// The line replay prints for a settled drive.
inline std::string settled(const std::string& state, const std::string& statusword,
                           const std::string& transitions) {
  return "{\"state\":\"" + state + "\",\"statusword\":\"" + statusword + "\",\"transitions\":[" +
         transitions + "]}";
}

/// Status words of the standard states (cia402-reference.md §1.1, S11) with DC link (bit 4) and
/// remote (bit 9), as the ideal plant shows them.
inline constexpr const char* sod = "0x0250";
inline constexpr const char* rtso = "0x0231";
inline constexpr const char* so = "0x0233";
inline constexpr const char* oe = "0x0237";
inline constexpr const char* qsa_standstill = "0x0617";  ///< 0x605A 5..8: bit 10 too (S5)
inline constexpr const char* qsa = "0x0217";
inline constexpr const char* fault = "0x0218";

inline const std::string power_up = settled("SWITCH_ON_DISABLED", sod, "0,1");

}  // namespace cia402::test
