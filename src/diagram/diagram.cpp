#include "cia402/diagram.hpp"

#include <set>
#include <sstream>
#include <tuple>

namespace cia402 {
namespace {

// One arrow per (from, to, number): rows that differ only in their trigger draw once.
using arrow = std::tuple<int, int, int>;

std::set<arrow> arrows_of(const profile& p) {
  std::set<arrow> arrows;
  for (std::size_t r = 0; r < p.row_count; ++r) {
    const transition_row row = p.row(r);
    for (int s = 0; s < state_count; ++s) {
      if ((row.from >> s) & 1u) arrows.insert({s, static_cast<int>(row.to), row.number});
    }
  }
  return arrows;
}

// Human labels: "OPERATION\nENABLED".
std::string label_of(state s) {
  std::string name = state_name(s);
  for (char& c : name) {
    if (c == '_') c = ' ';
  }
  // Break the longer names in two so the boxes stay narrow.
  if (name.size() > 12) {
    const auto mid = name.find(' ', name.size() / 2 - 2);
    if (mid != std::string::npos) name[mid] = '\n';
  }
  return name;
}

std::string dot_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\n') {
      out += "\\n";
    } else if (c == '"') {
      out += "\\\"";
    } else {
      out += c;
    }
  }
  return out;
}

bool state_used(const std::set<arrow>& arrows, int s) {
  for (const auto& [from, to, number] : arrows) {
    if (from == s || to == s) return true;
  }
  return false;
}

}  // namespace

std::string diagram_dot(const profile& p) {
  const auto arrows = arrows_of(p);
  // A row leaving many states (T13, "any state but FAULT") is drawn as the standard draws it: one
  // arrow leaving a frame around all of them.
  std::uint16_t group = 0;
  for (std::size_t r = 0; r < p.row_count; ++r) {
    const std::uint16_t from = p.row(r).from;
    if (__builtin_popcount(from) >= 3 && __builtin_popcount(from) > __builtin_popcount(group)) {
      group = from;
    }
  }
  std::ostringstream out;
  out << "digraph \"" << p.name << "\" {\n"
      << "  graph [rankdir=TB, nodesep=0.5, ranksep=0.45, compound=true, fontname=\"Helvetica\"];\n"
      << "  node [shape=box, style=\"rounded\", fontname=\"Helvetica\", fontsize=11, "
         "width=1.6];\n"
      << "  edge [fontname=\"Helvetica\", fontsize=10, arrowsize=0.7];\n";
  const auto node = [&](int s) {
    const state st = static_cast<state>(s);
    if (st == state::start) {
      out << "  \"START\" [id=\"state.START\", class=\"state\", shape=point, width=0.15, "
             "label=\"\"];\n";
      return;
    }
    out << "  \"" << state_name(st) << "\" [id=\"state." << state_name(st)
        << "\", class=\"state\", label=\"" << dot_escape(label_of(st)) << "\"];\n";
  };
  int group_member = -1;
  if (group != 0) {
    out << "  subgraph cluster_group {\n  id=\"group\"; label=\"\"; style=dashed; color=gray60;\n";
    for (int s = 0; s < state_count; ++s) {
      if (((group >> s) & 1u) && state_used(arrows, s)) {
        node(s);
        if (group_member < 0 || static_cast<state>(s) == state::switch_on_disabled) group_member = s;
      }
    }
    if (((group >> static_cast<int>(state::quick_stop_active)) & 1u) &&
        state_used(arrows, static_cast<int>(state::quick_stop_active))) {
      out << "  { rank=same; \"OPERATION_ENABLED\"; \"QUICK_STOP_ACTIVE\"; }\n";
    }
    out << "  }\n";
  }
  for (int s = 0; s < state_count; ++s) {
    if (!((group >> s) & 1u) && state_used(arrows, s)) node(s);
  }
  std::set<std::pair<int, int>> grouped_drawn;  // (number, to)
  for (std::size_t r = 0; r < p.row_count; ++r) {
    const transition_row row = p.row(r);
    if (group == 0 || row.from != group) continue;
    const int to = static_cast<int>(row.to);
    if (!grouped_drawn.insert({row.number, to}).second) continue;
    const char* t = state_name(row.to);
    out << "  \"" << state_name(static_cast<state>(group_member)) << "\" -> \"" << t << "\" [id=\"t"
        << int{row.number} << ".ANY." << t << "\", class=\"transition t" << int{row.number}
        << "\", label=\"" << int{row.number} << "\", ltail=cluster_group];\n";
  }
  for (const auto& [from, to, number] : arrows) {
    if (grouped_drawn.count({number, to}) && ((group >> from) & 1u)) continue;
    const char* f = state_name(static_cast<state>(from));
    const char* t = state_name(static_cast<state>(to));
    out << "  \"" << f << "\" -> \"" << t << "\" [id=\"t" << number << "." << f << "." << t
        << "\", class=\"transition t" << number << "\", label=\"" << number << "\"];\n";
  }
  out << "}\n";
  return out.str();
}

std::string diagram_mermaid(const profile& p) {
  const auto arrows = arrows_of(p);
  std::ostringstream out;
  out << "stateDiagram-v2\n";
  for (int s = 1; s < state_count; ++s) {
    if (!state_used(arrows, s)) continue;
    const state st = static_cast<state>(s);
    std::string label = label_of(st);
    for (char& c : label) {
      if (c == '\n') c = ' ';
    }
    out << "  state \"" << label << "\" as " << state_name(st) << "\n";
  }
  for (const auto& [from, to, number] : arrows) {
    const state f = static_cast<state>(from);
    out << "  " << (f == state::start ? "[*]" : state_name(f)) << " --> "
        << state_name(static_cast<state>(to)) << " : " << number << "\n";
  }
  return out.str();
}

}  // namespace cia402
