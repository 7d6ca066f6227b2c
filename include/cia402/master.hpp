// The master side: what a PLC, motion controller or test bench runs to bring a drive where it wants
// it. Status-word decoding, command encoding, the shortest command path to a target state computed
// by running the drive-side machine itself (same table, same option codes), and a non-blocking
// master step. No heap, no exceptions, bounded work.
#pragma once

#include <array>
#include <cstdint>

#include "cia402/drive.hpp"
#include "cia402/profile.hpp"
#include "cia402/state.hpp"
#include "cia402/words.hpp"

namespace cia402 {

/// The state a status word shows under the profile's patterns. Bit 5 is don't care where the
/// pattern does not need it (NOT READY TO SWITCH ON, SWITCH ON DISABLED, FAULT REACTION ACTIVE,
/// FAULT in the standard; cia402-reference.md §1.1). False if the word shows no state.
bool decode_status(const profile& p, std::uint16_t status_word, state& out) noexcept;

/// The mask a state's pattern is compared under: 0x4F or 0x6F.
std::uint16_t status_mask(const profile& p, state s) noexcept;

/// The control-word bits the profile's state machine owns: every decoder mask bit and bit 7.
std::uint16_t owned_control_bits(const profile& p) noexcept;

/// The control word that commands `c`, keeping every bit of `keep` the state machine does not own
/// (halt, operation-mode bits 4..6 and 9, manufacturer bits). Of the words that decode to `c`, the
/// one with the fewest bits set (0x06 Shutdown, 0x07 Switch on, 0x0F Enable operation, 0x00
/// Disable voltage, 0x02 Quick stop in the standard). Bit 7 is cleared. False if no word decodes
/// to `c` in this profile.
bool encode_command(const profile& p, command c, std::uint16_t keep, std::uint16_t& out) noexcept;

/// One cycle of a command path.
struct path_step {
  std::uint16_t control_word = 0;          ///< owned bits only
  std::uint8_t transition = no_transition;  ///< the transition the drive takes in this cycle
  state after = state::start;               ///< the drive's state after this cycle
};

inline constexpr std::size_t max_path_length = 24;

/// The fewest-cycles command sequence from an axis (its state, option codes and the fault-reset bit
/// it last saw) to a target state, found by breadth-first search over the drive-side machine itself
/// on an ideal plant with no fault cause present. Every cycle's control word is one of the profile's
/// commands, with bit 7 set or clear, so a fault reset is an edge: bit 7 is cleared for a cycle
/// first if the drive last saw it set.
struct command_path {
  bool reachable = false;
  std::uint8_t length = 0;                 ///< cycles; 0 when the axis is already there
  std::array<path_step, max_path_length> steps{};
};

///
/// S17: a path to any target but OPERATION ENABLED never enters OPERATION ENABLED on the way (motion
/// is never enabled as a side effect), even where that costs a cycle.
command_path plan_path(const profile& p, const axis& from, state target) noexcept;

/// The fewest-cycles path that brings every one of `count` axes (at most 2) to the target with the
/// same words: what a master plans when it cannot tell them apart.
command_path plan_path(const profile& p, const axis* from, std::size_t count, state target) noexcept;

/// The path a master plans from what a status word shows: the drive in state s, at rest, with the
/// given option codes and fault-reset bit, and where the profile remembers how a state was entered
/// (seed 001: a class-1 quick stop needs Fault Reset to leave) every way it may have been entered.
command_path plan_path_from_status(const profile& p, const axis& options_from, state s,
                                   bool fault_reset_bit, state target) noexcept;

/// An axis at rest in state s, as a master may assume it: the profile's option codes as given by
/// `options_from`, torque on where the state runs it, no stop pending.
axis axis_at_rest(const profile& p, const axis& options_from, state s, bool fault_reset_bit) noexcept;

/// What a master step reports.
enum class master_outcome : std::uint8_t {
  idle = 0,            ///< no target set
  in_progress = 1,
  reached = 2,
  timed_out = 3,       ///< `transition` names the one that did not happen in time
  fault = 4,           ///< the drive went to FAULT REACTION ACTIVE or FAULT; `error_code` says why
  not_remote = 5,      ///< status bit 9 is 0: the drive does not process the control word
  unreachable = 6,     ///< no command sequence leads from the observed state to the target
  bad_status_word = 7, ///< the status word shows no state
};

/// "in_progress", ...; never null.
const char* master_outcome_name(master_outcome o) noexcept;

/// For one target: the first command of the shortest path from every state (and from both values
/// of the fault-reset bit the drive last saw). Computed once by set_target; a master step is then
/// a table lookup, so it costs the same whatever the path, and a late status word simply gets the
/// command for the state it shows (commands are levels, so repeating one is harmless).
struct master_policy {
  struct entry {
    std::uint16_t control_word = 0;  ///< owned bits only
    std::uint8_t transition = no_transition;
    std::uint8_t cycles = 0xFF;      ///< cycles to the target; `unreachable` if none
  };
  static constexpr std::uint8_t unreachable = 0xFF;
  static constexpr std::uint8_t no_state = 0xFF;

  state target = state::switch_on_disabled;
  std::uint16_t owned = 0;      ///< owned_control_bits of the profile
  std::uint16_t safe_word = 0;  ///< Disable voltage: what a master sends after a fault
  std::array<std::array<entry, 2>, state_count> first{};  ///< [state][fault-reset bit]
  /// decode_status over status bits 0..6, precomputed: a state, or no_state.
  std::array<std::uint8_t, 128> state_of_bits{};

  static master_policy make(const profile& p, const axis& options_from, state target) noexcept;
};

/// A non-blocking master for one axis: `step(status word, now) -> control word`, one call a cycle.
/// Time is passed in, in any unit, and never read from a clock.
class master {
 public:
  /// The bits the master does not own (halt, mode bits, ...) come from here; change them any time.
  std::uint16_t application_bits = 0;

  /// Start driving towards a target. `timeout` is per transition, in the unit of `now`.
  void set_target(const master_policy& policy, std::uint64_t now, std::uint64_t timeout) noexcept;
  void clear_target() noexcept;

  /// The status-word bits a master's decision reads: the state (bits 0..6) and remote (bit 9).
  static constexpr std::uint16_t decisive_bits = 0x007F | status_bit::remote;

  /// One cycle: the status word the drive last reported (and 0x603F when known) in, the control
  /// word to send out. Never blocks, never allocates. A status word that shows the same state as the
  /// last one (other bits, such as warning or target reached, may differ), with nothing latched and
  /// no deadline passed, gets the same command at once.
  std::uint16_t step(std::uint16_t status_word, std::uint64_t now,
                     std::uint16_t error_code = 0) noexcept {
    if (((status_word ^ last_status_word_) & decisive_bits) == 0 && repeatable_ &&
        (timeout_ == 0 || outcome_ == master_outcome::reached || now - since_ < timeout_)) {
      control_word_ = static_cast<std::uint16_t>(command_bits_ | (application_bits & ~owned_));
      return control_word_;
    }
    return decide(status_word, now, error_code);
  }

  master_outcome outcome() const noexcept { return outcome_; }
  state observed() const noexcept { return observed_; }
  /// For timed_out: the transition that did not happen. Else the next one expected.
  std::uint8_t transition() const noexcept { return transition_; }
  std::uint16_t error_code() const noexcept { return error_code_; }
  /// Cycles the policy expects from the observed state to the target.
  std::uint8_t cycles_left() const noexcept { return cycles_left_; }
  std::uint16_t last_control_word() const noexcept { return control_word_; }

 private:
  std::uint16_t decide(std::uint16_t status_word, std::uint64_t now, std::uint16_t error_code) noexcept;

  const master_policy* policy_ = nullptr;
  std::uint64_t since_ = 0;    // when the observed state last changed
  std::uint64_t timeout_ = 0;
  std::uint16_t control_word_ = 0;
  std::uint16_t error_code_ = 0;
  master_outcome outcome_ = master_outcome::idle;
  state observed_ = state::start;
  std::uint8_t transition_ = no_transition;
  std::uint8_t cycles_left_ = 0;
  bool started_in_fault_ = false;
  // The quiet cycle: the same status word again gets the same owned bits, unless the decision
  // depended on something that changes by itself (bit 7 just sent, a latched outcome).
  bool repeatable_ = false;
  std::uint16_t last_status_word_ = 0;
  std::uint16_t command_bits_ = 0;  // owned bits of the last word
  std::uint16_t owned_ = 0;
};

}  // namespace cia402
