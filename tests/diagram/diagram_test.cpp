// Diagrams are drawn from the table: every row's arrow is there with its number, nothing else is.
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <string>

#include "cia402/diagram.hpp"

namespace {

// A row leaving 3 or more states is one arrow from the frame around them ("ANY").
std::set<std::string> expected_arrows(const cia402::profile& p) {
  std::set<std::string> arrows;
  for (std::size_t r = 0; r < p.row_count; ++r) {
    if (__builtin_popcount(p.row(r).from) >= 3) {
      arrows.insert("t" + std::to_string(p.row(r).number) + ".ANY." +
                    cia402::state_name(p.row(r).to));
      continue;
    }
    for (int s = 0; s < cia402::state_count; ++s) {
      if ((p.row(r).from >> s) & 1u) {
        arrows.insert("t" + std::to_string(p.row(r).number) + "." +
                      cia402::state_name(static_cast<cia402::state>(s)) + "." +
                      cia402::state_name(p.row(r).to));
      }
    }
  }
  return arrows;
}

TEST(diagram, dot_has_one_arrow_per_row_source_with_its_number_on_every_profile) {
  for (std::size_t i = 0; i < cia402::builtin_profile_count(); ++i) {
    const cia402::profile& p = cia402::builtin_profile(i);
    const std::string dot = cia402::diagram_dot(p);
    std::set<std::string> drawn;
    const std::regex edge(
        R"re("(\w+)" -> "(\w+)" \[id="(t(\d+)\.(\w+)\.\w+)", class="transition t(\d+)", label="(\d+)")re");
    for (auto it = std::sregex_iterator(dot.begin(), dot.end(), edge); it != std::sregex_iterator(); ++it) {
      const std::smatch& m = *it;
      EXPECT_EQ(m[4].str(), m[7].str()) << p.name << ": the label is the transition number";
      EXPECT_EQ(m[4].str(), m[6].str()) << p.name << ": the class names the transition number";
      const std::string from = m[5].str() == "ANY" ? "ANY" : m[1].str();
      EXPECT_EQ(m[3].str(), "t" + m[4].str() + "." + from + "." + m[2].str());
      drawn.insert(m[3].str());
    }
    EXPECT_EQ(drawn, expected_arrows(p)) << p.name;
  }
}

TEST(diagram, no_quick_stop_draws_no_quick_stop_state) {
  const auto* p = cia402::find_builtin_profile("no-quick-stop");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(cia402::diagram_dot(*p).find("QUICK_STOP_ACTIVE"), std::string::npos);
  EXPECT_NE(cia402::diagram_dot(cia402::standard_profile()).find("state.QUICK_STOP_ACTIVE"),
            std::string::npos);
}

TEST(diagram, ax2000_draws_t17_from_operation_enabled_and_quick_stop_active) {
  const auto* p = cia402::find_builtin_profile("ax2000-profibus");
  ASSERT_NE(p, nullptr);
  const std::string dot = cia402::diagram_dot(*p);
  EXPECT_NE(dot.find("t17.OPERATION_ENABLED.SWITCH_ON_DISABLED"), std::string::npos);
  EXPECT_NE(dot.find("t17.QUICK_STOP_ACTIVE.SWITCH_ON_DISABLED"), std::string::npos);
}

TEST(diagram, mermaid_lists_every_arrow) {
  const cia402::profile& p = cia402::standard_profile();
  const std::string m = cia402::diagram_mermaid(p);
  EXPECT_EQ(m.rfind("stateDiagram-v2", 0), 0u);
  EXPECT_NE(m.find("[*] --> NOT_READY_TO_SWITCH_ON : 0"), std::string::npos);
  EXPECT_NE(m.find("QUICK_STOP_ACTIVE --> OPERATION_ENABLED : 16"), std::string::npos);
  EXPECT_NE(m.find("FAULT --> SWITCH_ON_DISABLED : 15"), std::string::npos);
  std::size_t lines = 0;
  for (char c : m) lines += c == '\n';
  // Header, one line per state (8), one per arrow from each source state.
  std::size_t arrows = 0;
  for (std::size_t r = 0; r < p.row_count; ++r) arrows += __builtin_popcount(p.row(r).from);
  EXPECT_LE(lines, 1 + 8 + arrows);  // rows differing only in trigger share one line
  EXPECT_GE(lines, 1 + 8 + arrows - 1);
}

}  // namespace
