#include "cia402/master.hpp"

#include "bits.hpp"

namespace cia402 {
namespace {

int popcount(unsigned v) noexcept { return detail::set_bits(v); }

bool same_axis(const axis& a, const axis& b) noexcept {
  if (a.current != b.current || a.pending_row != b.pending_row || a.flags != b.flags ||
      a.stop_code != b.stop_code) {
    return false;
  }
  for (int i = 0; i < option_count; ++i) {
    if (a.options[i] != b.options[i]) return false;
  }
  return true;
}

// Breadth-first search needs room for every distinct axis the commands can reach: states times
// pending rows times flag combinations met in practice stay far below this.
constexpr std::size_t max_nodes = 512;

// What the master believes the drive may be: every axis consistent with what it has seen. The
// status word does not show everything the drive remembers (seed 001's "entered by a fault"), so a
// plan must work from each of them at once.
constexpr std::size_t max_beliefs = 2;

struct belief {
  std::array<axis, max_beliefs> at{};
  std::uint8_t count = 1;
  state current() const noexcept { return at[0].current; }
};

bool same_belief(const belief& a, const belief& b) noexcept {
  if (a.count != b.count) return false;
  for (std::size_t i = 0; i < a.count; ++i) {
    if (!same_axis(a.at[i], b.at[i])) return false;
  }
  return true;
}

struct node {
  belief at;
  std::uint16_t parent;
  std::uint16_t control_word;
  std::uint8_t transition;
};

}  // namespace

std::uint16_t status_mask(const profile& p, state s) noexcept {
  // Bit 5 counts where the pattern sets it, or where another state differs from it only there.
  const std::uint16_t pattern = p.status_pattern(s);
  if (pattern & status_bit::quick_stop) return 0x6F;
  for (int o = 1; o < state_count; ++o) {
    const state other = static_cast<state>(o);
    if (other != s && (p.status_pattern(other) & 0x4F) == (pattern & 0x4F)) return 0x6F;
  }
  return 0x4F;
}

bool decode_status(const profile& p, std::uint16_t status_word, state& out) noexcept {
  // START shows like NOT READY TO SWITCH ON and is never reported: begin at state 1.
  for (int i = 1; i < state_count; ++i) {
    const state s = static_cast<state>(i);
    if ((status_word & status_mask(p, s)) == p.status_pattern(s)) {
      out = s;
      return true;
    }
  }
  return false;
}

std::uint16_t owned_control_bits(const profile& p) noexcept {
  std::uint16_t owned = control_bit::fault_reset;
  for (std::size_t i = 0; i < p.decoder_size; ++i) owned |= p.decoder[i].mask;
  return owned;
}

bool encode_command(const profile& p, command c, std::uint16_t keep, std::uint16_t& out) noexcept {
  const std::uint16_t owned = owned_control_bits(p);
  int best = -1;
  for (unsigned bits = 0; bits < 32; ++bits) {
    if ((bits & ~owned) != 0 || p.decode(static_cast<std::uint16_t>(bits)) != c) continue;
    if (best < 0 || popcount(bits) < popcount(static_cast<unsigned>(best))) best = static_cast<int>(bits);
  }
  if (best < 0) return false;
  out = static_cast<std::uint16_t>((keep & ~owned) | static_cast<unsigned>(best));
  return true;
}

axis axis_at_rest(const profile& p, const axis& options_from, state s, bool fault_reset_bit) noexcept {
  axis a = make_axis(p);
  for (int i = 0; i < option_count; ++i) a.options[i] = options_from.options[i];
  a.current = s;
  a.flags = fault_reset_bit ? axis_flag::fault_reset_bit : std::uint8_t{0};
  const state_activity act = p.info(s).activity;
  const int qs = a.options[static_cast<int>(option::quick_stop)];
  const bool torque = act == state_activity::run || act == state_activity::hold ||
                      (act == state_activity::quick_stop && qs != 0);
  if (torque) a.flags |= axis_flag::torque_on;
  if (act == state_activity::fault_reaction) a.flags |= axis_flag::coast_reaction;
  // The code the running stop started with (S16): the present one is the best guess.
  if (act == state_activity::quick_stop) a.stop_code = a.options[static_cast<int>(option::quick_stop)];
  if (act == state_activity::fault_reaction) {
    a.stop_code = a.options[static_cast<int>(option::fault_reaction)];
  }
  return a;
}

namespace {

// True if the drive, once at `at`, stays there while the word that brought it is held: a master
// keeps sending its last word, so a path must not end on a word that moves on (Enable operation
// brings READY TO SWITCH ON to SWITCHED ON, but then on to OPERATION ENABLED).
bool word_holds(const profile& p, axis at, std::uint16_t word) noexcept {
  drive_inputs in;
  in.control_word = word;
  const state target = at.current;
  for (int i = 0; i < 2; ++i) {
    step(p, at, in);
    if (at.current != target) return false;
  }
  return true;
}

bool at_goal(const profile& p, const belief& b, state target, std::uint16_t word,
             bool must_hold) noexcept {
  for (std::size_t i = 0; i < b.count; ++i) {
    if (b.at[i].current != target) return false;
    if (must_hold && !word_holds(p, b.at[i], word)) return false;
  }
  return true;
}

command_path search(const profile& p, const belief& from, state target,
                    const std::uint16_t* words, std::size_t word_count, bool must_hold) noexcept {
  command_path path;
  std::array<node, max_nodes> nodes{};
  std::array<std::uint8_t, max_nodes> depth{};
  std::size_t count = 1;
  nodes[0] = {from, 0, 0, no_transition};
  for (std::size_t head = 0; head < count; ++head) {
    if (depth[head] >= max_path_length) break;
    for (std::size_t w = 0; w < word_count; ++w) {
      drive_inputs in;
      in.control_word = words[w];
      belief next = nodes[head].at;
      drive_outputs out;
      bool enters_operation = false;
      for (std::size_t i = 0; i < next.count; ++i) {
        const state before = next.at[i].current;
        const drive_outputs o = step(p, next.at[i], in);
        if (i == 0) out = o;
        enters_operation |= before != state::operation_enabled &&
                            next.at[i].current == state::operation_enabled;
      }
      // S17: motion is never enabled on the way to another target.
      if (enters_operation && target != state::operation_enabled) continue;
      // The goal test comes before the seen test: whether the target holds depends on the word,
      // and an axis first reached by a word that moves on may be reached again by one that holds.
      const bool goal = at_goal(p, next, target, words[w], must_hold);
      bool seen = false;
      for (std::size_t k = 0; k < count && !seen && !goal; ++k) seen = same_belief(nodes[k].at, next);
      if (seen || count == max_nodes) continue;
      nodes[count] = {next, static_cast<std::uint16_t>(head), words[w], out.transition};
      depth[count] = static_cast<std::uint8_t>(depth[head] + 1);
      if (goal) {
        // Walk back to the start, then write the steps in order.
        path.reachable = true;
        path.length = depth[count];
        for (std::size_t k = count, d = path.length; k != 0; k = nodes[k].parent) {
          --d;
          path.steps[d] = {nodes[k].control_word, nodes[k].transition, nodes[k].at.current()};
        }
        return path;
      }
      ++count;
    }
  }
  return path;
}

}  // namespace

command_path plan_path(const profile& p, const axis& from, state target) noexcept {
  return plan_path(p, &from, 1, target);
}

command_path plan_path(const profile& p, const axis* from, std::size_t count, state target) noexcept {
  belief start;
  start.count = static_cast<std::uint8_t>(count < max_beliefs ? count : max_beliefs);
  bool there = true;
  for (std::size_t i = 0; i < start.count; ++i) {
    start.at[i] = from[i];
    there &= from[i].current == target;
  }
  if (there || start.count == 0) {
    command_path here;
    here.reachable = there;
    return here;
  }
  // The distinct control words a master may send: each command, with bit 7 clear or set. Of equally
  // short paths the first found wins, so the order says what we prefer: Enable operation first, so
  // one command is held through T3 and T4 (S3); and a fault reset carries Disable voltage, so the
  // reset itself never asks for more than SWITCH ON DISABLED.
  constexpr command order[command_count] = {command::enable_operation, command::switch_on,
                                            command::shutdown,         command::quick_stop,
                                            command::disable_voltage,  command::stop_and_inhibit};
  constexpr command reset_order[command_count] = {command::disable_voltage,  command::shutdown,
                                                  command::switch_on,        command::enable_operation,
                                                  command::quick_stop,       command::stop_and_inhibit};
  // A master asked for any other state never sends Enable operation, not even where the drive moves
  // on by itself whatever it gets (NOT READY TO SWITCH ON, a fault reaction): a drive in QUICK STOP
  // ACTIVE would take it as T16. Only a profile that cannot do without it (none built in) gets it.
  for (const bool with_enable : {target == state::operation_enabled, true}) {
    std::array<std::uint16_t, 2 * command_count> words{};
    std::size_t word_count = 0;
    for (const command c : order) {
      std::uint16_t w = 0;
      if ((with_enable || c != command::enable_operation) && encode_command(p, c, 0, w)) words[word_count++] = w;
    }
    for (const command c : reset_order) {
      std::uint16_t w = 0;
      if ((with_enable || c != command::enable_operation) && encode_command(p, c, 0, w)) {
        words[word_count++] = static_cast<std::uint16_t>(w | control_bit::fault_reset);
      }
    }
    // A target the drive leaves by itself (QUICK STOP ACTIVE with 0x605A = 1..4) has no word that
    // holds it: then arriving is enough.
    const command_path held = search(p, start, target, words.data(), word_count, true);
    if (held.reachable) return held;
    const command_path arrived = search(p, start, target, words.data(), word_count, false);
    if (arrived.reachable || with_enable) return arrived;
  }
  return {};
}

namespace {

bool reads_entered_by_fault(const profile& p) noexcept {
  for (std::size_t i = 0; i < p.row_count; ++i) {
    const transition_row r = p.row(i);
    if ((r.any | r.all | r.none).has(fact::entered_by_fault)) return true;
  }
  return false;
}

}  // namespace

command_path plan_path_from_status(const profile& p, const axis& options_from, state s,
                                   bool fault_reset_bit, state target) noexcept {
  std::array<axis, max_beliefs> beliefs{};
  beliefs[0] = axis_at_rest(p, options_from, s, fault_reset_bit);
  std::size_t count = 1;
  // Seed 001: a quick stop a class-1 error caused needs Fault Reset to leave, one the fieldbus
  // asked for needs Enable operation, and the status word shows the same state for both.
  if (reads_entered_by_fault(p)) {
    beliefs[1] = beliefs[0];
    beliefs[1].flags |= axis_flag::entered_by_fault;
    count = 2;
  }
  return plan_path(p, beliefs.data(), count, target);
}

master_policy master_policy::make(const profile& p, const axis& options_from, state target) noexcept {
  master_policy policy;
  policy.target = target;
  policy.owned = owned_control_bits(p);
  encode_command(p, command::disable_voltage, 0, policy.safe_word);
  for (unsigned bits = 0; bits < 128; ++bits) {
    state s;
    policy.state_of_bits[bits] =
        decode_status(p, static_cast<std::uint16_t>(bits), s) ? static_cast<std::uint8_t>(s) : no_state;
  }
  for (int s = 0; s < state_count; ++s) {
    for (int bit = 0; bit < 2; ++bit) {
      const command_path path =
          plan_path_from_status(p, options_from, static_cast<state>(s), bit != 0, target);
      entry& e = policy.first[s][bit];
      if (!path.reachable) continue;
      e.cycles = path.length;  // at most max_path_length, below `unreachable`
      if (path.length > 0) {
        e.control_word = path.steps[0].control_word;
        e.transition = path.steps[0].transition;
      } else {
        // At the target: hold it with the command that keeps it (the one that got there).
        e.control_word = 0xFFFF;
      }
    }
  }
  // The holding word at the target keeps the drive there and asks nothing more of it: of the
  // commands that hold every way the drive may stand there, the one that asks least. The last word
  // of a path into the target is no such word: from START every word leads to SWITCH ON DISABLED,
  // and Enable operation, first in the search order, would then be held there, and would bring a
  // drive in QUICK STOP ACTIVE with 0x605A = 5..8 back to OPERATION ENABLED (T16).
  constexpr command least_first[command_count] = {command::disable_voltage, command::quick_stop,
                                                  command::stop_and_inhibit, command::shutdown,
                                                  command::switch_on,        command::enable_operation};
  for (int bit = 0; bit < 2; ++bit) {
    entry& hold = policy.first[static_cast<int>(target)][bit];
    if (hold.control_word != 0xFFFF) continue;
    std::array<axis, max_beliefs> at{};
    at[0] = axis_at_rest(p, options_from, target, bit != 0);
    std::size_t count = 1;
    if (reads_entered_by_fault(p)) {
      at[1] = at[0];
      at[1].flags |= axis_flag::entered_by_fault;
      count = 2;
    }
    for (const command c : least_first) {
      std::uint16_t w = 0;
      if (!encode_command(p, c, 0, w)) continue;
      bool holds = true;
      for (std::size_t i = 0; i < count && holds; ++i) holds = word_holds(p, at[i], w);
      if (holds) {
        hold.control_word = w;
        break;
      }
    }
  }
  // A target the drive leaves by itself (QUICK STOP ACTIVE with 0x605A = 1..4) has no holding word:
  // keep the last word of a path into it, so arriving is enough, but never Enable operation on the
  // way to another target (S17).
  std::uint16_t enable = 0xFFFF;
  (void)encode_command(p, command::enable_operation, 0, enable);
  for (int s = 0; s < state_count; ++s) {
    for (int bit = 0; bit < 2; ++bit) {
      entry& hold = policy.first[static_cast<int>(target)][bit];
      if (hold.control_word != 0xFFFF) continue;
      const command_path path =
          plan_path_from_status(p, options_from, static_cast<state>(s), bit != 0, target);
      if (!path.reachable || path.length == 0) continue;
      const auto last = static_cast<std::uint16_t>(path.steps[path.length - 1].control_word &
                                                   ~control_bit::fault_reset);
      if (last != enable || target == state::operation_enabled) hold.control_word = last;
    }
  }
  for (int bit = 0; bit < 2; ++bit) {
    entry& hold = policy.first[static_cast<int>(target)][bit];
    if (hold.control_word == 0xFFFF) {
      // Nothing leads in (FAULT, say): keep the drive as it is by asking for nothing.
      hold.control_word = policy.safe_word;
    }
  }
  return policy;
}

const char* master_outcome_name(master_outcome o) noexcept {
  switch (o) {
    case master_outcome::idle: return "idle";
    case master_outcome::in_progress: return "in_progress";
    case master_outcome::reached: return "reached";
    case master_outcome::timed_out: return "timed_out";
    case master_outcome::fault: return "fault";
    case master_outcome::not_remote: return "not_remote";
    case master_outcome::unreachable: return "unreachable";
    case master_outcome::bad_status_word: return "bad_status_word";
  }
  return "unknown";
}

void master::set_target(const master_policy& policy, std::uint64_t now,
                        std::uint64_t timeout) noexcept {
  policy_ = &policy;
  owned_ = policy.owned;
  repeatable_ = false;
  since_ = now;
  timeout_ = timeout;
  outcome_ = master_outcome::in_progress;
  error_code_ = 0;
  started_in_fault_ = true;  // until a state outside FAULT / FAULT REACTION ACTIVE is seen
}

void master::clear_target() noexcept {
  policy_ = nullptr;
  repeatable_ = false;
  outcome_ = master_outcome::idle;
}

std::uint16_t master::decide(std::uint16_t status_word, std::uint64_t now,
                             std::uint16_t error_code) noexcept {
  repeatable_ = false;
  last_status_word_ = status_word;
  if (policy_ == nullptr) {
    control_word_ = static_cast<std::uint16_t>(control_word_ & ~control_bit::fault_reset);
    return control_word_;
  }
  const master_policy& policy = *policy_;
  const std::uint16_t keep = static_cast<std::uint16_t>(application_bits & ~policy.owned);
  if (outcome_ == master_outcome::fault) {
    // Latched until the next set_target: a master never resets a fault on its own.
    control_word_ = static_cast<std::uint16_t>(policy.safe_word | keep);
    return control_word_;
  }
  if (outcome_ == master_outcome::timed_out) return control_word_;

  const std::uint8_t code = policy.state_of_bits[status_word & 0x7F];
  if (code == master_policy::no_state) {
    outcome_ = master_outcome::bad_status_word;  // not latched: the next good word resumes
    return control_word_;
  }
  const state seen = static_cast<state>(code);
  if (seen != observed_) {
    observed_ = seen;
    since_ = now;
  }
  if ((status_word & status_bit::remote) == 0) {
    outcome_ = master_outcome::not_remote;
    return control_word_;
  }
  const bool in_fault = seen == state::fault || seen == state::fault_reaction_active;
  const bool fault_is_target =
      policy.target == state::fault || policy.target == state::fault_reaction_active;
  if (!in_fault) started_in_fault_ = false;
  if (in_fault && !started_in_fault_ && !fault_is_target) {
    outcome_ = master_outcome::fault;
    error_code_ = error_code;
    control_word_ = static_cast<std::uint16_t>(policy.safe_word | keep);
    return control_word_;
  }
  // The drive compares bit 7 with the word we sent last (S2), so that picks the entry.
  const int reset_bit = (control_word_ & control_bit::fault_reset) ? 1 : 0;
  const master_policy::entry& e = policy.first[static_cast<int>(seen)][reset_bit];
  cycles_left_ = e.cycles;
  transition_ = e.transition;
  if (e.cycles == master_policy::unreachable) {
    outcome_ = master_outcome::unreachable;
    return control_word_;
  }
  if (e.cycles == 0) {
    outcome_ = master_outcome::reached;
  } else if (timeout_ != 0 && now - since_ >= timeout_) {
    outcome_ = master_outcome::timed_out;
    return control_word_;
  } else {
    outcome_ = master_outcome::in_progress;
  }
  control_word_ = static_cast<std::uint16_t>(e.control_word | keep);
  command_bits_ = e.control_word;
  // Repeating is right when the next cycle would pick this same entry: bit 7 unchanged.
  const int next_bit = (e.control_word & control_bit::fault_reset) ? 1 : 0;
  repeatable_ = next_bit == reset_bit;
  return control_word_;
}

}  // namespace cia402
