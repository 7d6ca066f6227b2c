#include "cia402/page/transition_inference.hpp"

namespace cia402::page {
namespace {

// The facts a drive raises from its control word: a row triggered only by these needs a command.
constexpr std::uint32_t command_facts =
    static_cast<std::uint32_t>(fact::disable_voltage) | static_cast<std::uint32_t>(fact::quick_stop) |
    static_cast<std::uint32_t>(fact::shutdown) | static_cast<std::uint32_t>(fact::switch_on) |
    static_cast<std::uint32_t>(fact::enable_operation) |
    static_cast<std::uint32_t>(fact::stop_and_inhibit) | static_cast<std::uint32_t>(fact::fault_reset);

// 2: triggered by what was sent; 1: needs no command; 0: needs a command that was not sent.
int score(const transition_row& row, fact_set sent) {
  if (!(row.any & sent).empty()) return 2;
  if ((row.any.bits() & ~command_facts) != 0) return 1;
  return 0;
}

struct search {
  search(const profile& table, state to, fact_set facts, std::size_t rows)
      : p(table), target(to), sent(facts), depth(rows) {}

  const profile& p;
  state target;
  fact_set sent;
  std::size_t depth;
  std::vector<std::size_t> chain;
  std::vector<std::size_t> best;
  int best_score = -1;

  // Depth-first over chains of exactly `depth` rows; rows are tried in table order and only a
  // strictly better score replaces the best, so ties keep the earlier rows.
  void walk(state at, int total) {
    if (chain.size() == depth) {
      if (at == target && total > best_score) {
        best_score = total;
        best = chain;
      }
      return;
    }
    for (std::size_t r = 0; r < p.row_count; ++r) {
      const transition_row row = p.row(r);
      if (((row.from >> static_cast<unsigned>(at)) & 1u) == 0) continue;
      // A chain through its own end or back through a state it left is no shorter explanation.
      if (row.to == at) continue;
      chain.push_back(r);
      walk(row.to, total + score(row, sent));
      chain.pop_back();
    }
  }
};

}  // namespace

fact_set observer_facts(const profile& p, std::uint16_t control_word, bool reset_edge_sent) noexcept {
  fact_set f = command_fact(p.decode(control_word));
  if (reset_edge_sent) f |= fact::fault_reset;
  return f;
}

std::vector<inferred_transition> infer_transitions(const profile& p, state from, state to,
                                                   fact_set sent) {
  std::vector<inferred_transition> out;
  if (from == to) return out;
  for (std::size_t depth = 1; depth <= max_inferred_chain; ++depth) {
    search s(p, to, sent, depth);
    s.walk(from, 0);
    if (s.best_score < 0) continue;
    state at = from;
    for (std::size_t r : s.best) {
      const transition_row row = p.row(r);
      out.push_back({row.number, at, row.to});
      at = row.to;
    }
    return out;
  }
  return out;
}

}  // namespace cia402::page
