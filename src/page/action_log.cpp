#include "action_log.hpp"

#include <utility>

namespace cia402::page::detail {
namespace {

// "done: T2, T3 -> SWITCHED_ON" for the transitions an action led to.
std::string transitions_text(const std::vector<int>& transitions, state now) {
  std::string text = "done: ";
  for (std::size_t i = 0; i < transitions.size(); ++i) {
    text += (i ? ", T" : "T") + std::to_string(transitions[i]);
  }
  return text + " -> " + state_name(now);
}

}  // namespace

action_log::action_log(rules r, std::function<standing()> how_it_stands)
    : rules_(std::move(r)), how_it_stands_(std::move(how_it_stands)) {}

std::uint64_t action_log::track(std::string action, bool refuse_without_transition,
                                std::optional<state> before, std::uint64_t now,
                                expectation expect) {
  finish_pending("superseded before it settled");
  tracked a;
  a.id = next_id_++;
  a.action = std::move(action);
  a.before = before;
  a.started = now;
  a.busy_until = now;
  a.refused_without_transition = refuse_without_transition;
  a.expect = expect;
  result_entry r;
  r.id = a.id;
  r.action = a.action;
  r.outcome = "pending";
  r.text = "pending";
  push(std::move(r));
  pending_ = std::move(a);
  return pending_->id;
}

std::uint64_t action_log::report_now(std::string action, std::string outcome, std::string text) {
  finish_pending("superseded before it settled");
  result_entry r;
  r.id = next_id_++;
  r.action = std::move(action);
  r.outcome = std::move(outcome);
  r.text = std::move(text);
  const std::uint64_t id = r.id;
  push(std::move(r));
  return id;
}

void action_log::refuse_pending(std::string text) {
  if (!pending_) return;
  result_entry r{pending_->id, pending_->action, "refused", std::move(text), pending_->transitions};
  pending_.reset();
  push(std::move(r));
}

void action_log::finish_pending(const char* why_unsettled) {
  if (!pending_) return;
  const tracked a = std::move(*pending_);
  pending_.reset();
  const standing s = how_it_stands_();
  result_entry r;
  r.id = a.id;
  r.action = a.action;
  r.transitions = a.transitions;
  if (!a.transitions.empty()) {
    r.outcome = "done";
    r.text = transitions_text(a.transitions, s.now) + rules_.transitions_note;
  } else if (a.refused_without_transition && a.expect == expectation::already_there) {
    r.outcome = "nothing to do";
    r.text = "nothing to do: already " + s.now_name;
  } else if (a.refused_without_transition && a.expect == expectation::act &&
             !s.waiting_for.empty()) {
    // A level command stays in the control word: it acts once what holds it back is gone.
    r.outcome = "waiting";
    r.text = "waiting: " + s.waiting_for + "; " + a.action + " acts once it is gone";
  } else if (a.refused_without_transition) {
    r.outcome = "refused";
    r.text = std::string("refused: no transition from ") +
             (a.before ? state_name(*a.before) : "UNKNOWN") + " for " + a.action + s.conditions;
  } else {
    r.outcome = "done";
    r.text = "done: no transition, still " + s.now_name;
  }
  if (why_unsettled != nullptr) r.text += std::string(" (") + why_unsettled + ")";
  push(std::move(r));
}

void action_log::settle(std::uint64_t now, bool busy) {
  if (!pending_) return;
  if (busy) pending_->busy_until = now;
  if (now - pending_->busy_until >= rules_.settle_quiet) {
    finish_pending(nullptr);
  } else if (now - pending_->started >= rules_.settle_limit) {
    finish_pending(rules_.gave_up_note.c_str());
  }
}

action_log::json action_log::results_json() const {
  json rs = json::array();
  for (const result_entry& r : results_) {
    rs.push_back({{"id", r.id},
                  {"action", r.action},
                  {"outcome", r.outcome},
                  {"text", r.text},
                  {"transitions", r.transitions}});
  }
  return rs;
}

// A report replaces the entry with its id (pending -> done); the oldest entries fall off.
void action_log::push(result_entry r) {
  for (result_entry& e : results_) {
    if (e.id == r.id) {
      e = std::move(r);
      return;
    }
  }
  results_.push_front(std::move(r));
  while (results_.size() > rules_.kept) results_.pop_back();
}

}  // namespace cia402::page::detail
