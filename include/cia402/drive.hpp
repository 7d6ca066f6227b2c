// The drive-side state machine: control word and plant feedback in, state, status word and power
// stage / brake / ramp commands out. One call per cycle; no heap, no exceptions, no locks, no I/O,
// bounded work (at most max_rows row checks).
#pragma once

#include <cstdint>

#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"
#include "cia402/state.hpp"

namespace cia402 {

/// Everything the drive reads in one cycle. The defaults are an ideal plant: DC link on, no STO, at
/// standstill with no holding brake to wait for, remote control.
struct drive_inputs {
  // A quiet cycle (detail/quiet_step.hpp) finds these first seven as they are by default.
  std::uint16_t fault_code = 0;     ///< error code of the present fault cause (0x603F); 0 = none
  bool dc_link = true;              ///< DC-link (main) voltage present (S13)
  bool sto = false;                 ///< safe torque off active (S14)
  bool remote = true;               ///< the control word is to be processed (status bit 9)
  bool connection_lost = false;     ///< fieldbus connection lost: 0x6007 decides (S10)
  bool local_enable = false;        ///< local request to enable the power stage (seed 001)
  bool local_disable = false;       ///< local request to disable the power stage (seed 001)
  std::uint16_t control_word = 0;   ///< 0x6040
  /// Status-word bits the motion side reports, each in its own place (status_bit::reported): 7
  /// warning, 10 target reached (shown in a running state), 11 internal limit active, 8 and 12..15
  /// mode specific. The bits the drive owns (state, voltage, remote) are ignored here.
  std::uint16_t status_bits = 0;
  std::uint8_t fault_class = 2;     ///< error class 0..4, read by profiles with error classes
  bool standstill = true;           ///< the motion side is at standstill / its ramp has finished
  bool brake_engaged = true;        ///< the holding brake has engaged (true if none is fitted)
  std::int32_t actual_speed_rpm = 0;    ///< read by profiles with a speed limit (seed 001 T2/T7)
};

/// Which stop the motion side must run this cycle.
enum class stop_ramp : std::uint8_t {
  none = 0,           ///< no stop: follow the set-points (or hold, when torque is on but idle)
  slow_down = 1,      ///< the mode's deceleration (0x6084)
  quick_stop = 2,     ///< the quick-stop deceleration (0x6085)
  current_limit = 3,  ///< stop at the current limit
  voltage_limit = 4,  ///< stop at the voltage limit
  coast = 5,          ///< torque off at once; the motor turns freely
};

/// "none", "slow_down", ...; never null.
const char* stop_ramp_name(stop_ramp r) noexcept;

/// Everything the drive decides in one cycle. Two whole 8-byte words (aligned, 16 bytes): the
/// compiled step builds the first, all a transition decides, from one table load, and the second,
/// the error, from the axis's error code; a caller's copy moves two words, not nine fields.
struct alignas(8) drive_outputs {
  state current = state::start;
  bool clear_setpoints = false;             ///< the motion side must drop its set-points now
  std::uint16_t status_word = 0;            ///< 0x6041
  std::uint8_t transition = no_transition;  ///< the transition taken this cycle (0..17)
  stop_ramp ramp = stop_ramp::none;
  bool torque = false;                      ///< power stage on, drive function enabled
  bool brake_released = false;              ///< holding brake released
  std::uint16_t error_code = 0;             ///< 0x603F
  std::uint8_t error_register = 0;          ///< 0x1001
};

// The bits of axis::flags (axis_flag) are in profile.hpp: the profile's ordinary cycles rewrite them.

/// One axis's state between cycles: 16 bytes. The profile is passed to each call, so many axes
/// share one profile. Aligned to 4: the compiled step (compiled.hpp) reads and writes the first
/// four bytes as one word, and a word at an address 2 mod 4 cost it about 0.25 ns a cycle
/// (docs/compiled-step.md); in an array, no axis's word then straddles a cache line.
struct alignas(4) axis {
  std::uint8_t flags = 0;               ///< axis_flag bits (before `current`: compiled.hpp reads both)
  state current = state::start;
  std::uint8_t pending_row = 0xFF;      ///< row whose stop is running (S7), 0xFF = none
  std::uint8_t last_transition = no_transition;  ///< the last transition taken, ever
  std::uint16_t error_code = 0;         ///< 0x603F
  std::int8_t options[option_count] = {};  ///< option-code values, index by `option`
  /// The option code governing the stop or reaction that runs now, as it was when that stop started
  /// (S16): 0x605A in QUICK STOP ACTIVE, 0x605E in FAULT REACTION ACTIVE, 0x605B or 0x605C for a
  /// pending row's stop. A write while the stop runs changes `options`, not this.
  std::int8_t stop_code = 0;
};

/// The pending-row value that means "no row's stop is running".
inline constexpr std::uint8_t no_pending_row = 0xFF;

/// True while a row's stop runs before its state change (S7: T5/T8 ramping, T17's fast stop): the
/// status word still shows the source state. Layers above ask this, never `pending_row` itself.
constexpr bool stop_running(const axis& a) noexcept { return a.pending_row != no_pending_row; }

/// The error register 0x1001 that goes with an error code (CiA 301): bit 0 for any error, bit 1
/// current (0x2xxx), 2 voltage (0x3xxx), 3 temperature (0x4xxx), 4 communication (0x81xx, 0x82xx),
/// 5 device profile (0x83xx..0x8Fxx, e.g. 0x8611 following error), 7 manufacturer (0xFFxx).
/// Inline, so a step whose caller ignores the register does not compute it.
constexpr std::uint8_t error_register_of(std::uint16_t error_code) noexcept {
  if (error_code == 0) return 0;
  const unsigned group = error_code >> 12;
  const unsigned high = error_code >> 8;
  unsigned r = 0x01u;
  if (group - 2u < 3u) {
    r |= 0x02u << (group - 2u);  // 0x2xxx current, 0x3xxx voltage, 0x4xxx temperature
  } else if (group == 0x8) {
    r |= high >= 0x83 ? 0x20u : high >= 0x81 ? 0x10u : 0u;
  } else if (high == 0xFF) {
    r |= 0x80u;
  }
  return static_cast<std::uint8_t>(r);
}

/// Error codes the drive raises itself.
namespace error_code {
inline constexpr std::uint16_t generic = 0x1000;        ///< replay's `fault` without a code
inline constexpr std::uint16_t dc_link_undervoltage = 0x3220;  ///< S13
inline constexpr std::uint16_t safe_torque_off = 0xFF01;  ///< S14: STO while torque was on (no
                                                          ///< standard code: manufacturer range)
inline constexpr std::uint16_t heartbeat = 0x8130;             ///< S10: 0x6007 = 1
}  // namespace error_code

/// An axis at power-on with the profile's default option codes. Its first steps take T0 and T1.
axis make_axis(const profile& p) noexcept;

namespace detail {
inline bool ordinary_inputs(const drive_inputs& in) noexcept;
inline bool quiet_cycle(const profile& p, axis& a, const drive_inputs& in, std::uint64_t& head) noexcept;
inline drive_outputs outputs_of(std::uint64_t head, std::uint16_t code) noexcept;
inline bool quiet_step(const profile& p, axis& a, const drive_inputs& in, drive_outputs& out) noexcept;
drive_outputs full_step(const profile& p, axis& a, const drive_inputs& in) noexcept;
/// full_step for inputs an ordinary cycle has (ordinary_inputs): the same outputs, fewer instructions.
drive_outputs ordinary_full_step(const profile& p, axis& a, const drive_inputs& in) noexcept;
}  // namespace detail

/// Runs one cycle: the profile's compiled ordinary cycle where it answers, else the full step. A
/// build optimised for size (-Os, a firmware) takes the full step every cycle, and its built-in
/// profiles carry no compiled cycles: the inline path and its tables cost flash a firmware lacks
/// (bench/cortex_m4/size.sh).
inline drive_outputs step(const profile& p, axis& a, const drive_inputs& in) noexcept {
#if !defined(__OPTIMIZE_SIZE__)
  std::uint64_t head;
  if (detail::quiet_cycle(p, a, in, head)) return detail::outputs_of(head, a.error_code);
  // The full step on a copy: the only place the inputs' address is taken, so a caller's inputs
  // built in locals stay in registers on the ordinary path instead of being stored every cycle
  // for a call that seldom comes (97 instructions a quiet step where the copy makes it fewer,
  // bench/instructions).
  const drive_inputs copy = in;
  if (detail::ordinary_inputs(copy)) return detail::ordinary_full_step(p, a, copy);
  return detail::full_step(p, a, copy);
#else
  return detail::full_step(p, a, in);
#endif
}

/// The same cycle, its outputs written into `out` where the caller keeps them (a simulator's axis):
/// a returned drive_outputs that the caller copies field by field is spilled in pieces and read
/// back wider, which stalls store forwarding.
inline void step(const profile& p, axis& a, const drive_inputs& in, drive_outputs& out) noexcept {
#if !defined(__OPTIMIZE_SIZE__)
  std::uint64_t head;
  if (detail::quiet_cycle(p, a, in, head)) {
    out = detail::outputs_of(head, a.error_code);
    return;
  }
  const drive_inputs copy = in;  // as above
  out = detail::ordinary_inputs(copy) ? detail::ordinary_full_step(p, a, copy) : detail::full_step(p, a, copy);
#else
  out = detail::full_step(p, a, in);
#endif
}

/// Writes an option code (0x605A..0x605E, 0x6007). A value the profile does not support is refused
/// with its SDO abort code (0x06090030) and changes nothing; an object the profile lacks gives
/// 0x06020000.
sdo_abort write_option(const profile& p, axis& a, std::uint16_t index, std::int32_t value) noexcept;
/// Reads an option code; the abort code tells if the object does not exist.
sdo_abort read_option(const profile& p, const axis& a, std::uint16_t index, std::int32_t& value) noexcept;

/// A drive: an axis bound to its profile, for code that runs one axis.
class drive {
 public:
  explicit drive(const profile& p) noexcept : profile_(&p), axis_(make_axis(p)) {}
  drive_outputs step(const drive_inputs& in) noexcept { return cia402::step(*profile_, axis_, in); }
  sdo_abort write(std::uint16_t index, std::int32_t value) noexcept {
    return write_option(*profile_, axis_, index, value);
  }
  sdo_abort read(std::uint16_t index, std::int32_t& value) const noexcept {
    return read_option(*profile_, axis_, index, value);
  }
  state current() const noexcept { return axis_.current; }
  const axis& state_of_axis() const noexcept { return axis_; }
  const profile& table() const noexcept { return *profile_; }

 private:
  const profile* profile_;
  axis axis_;
};

}  // namespace cia402

#include "cia402/detail/quiet_step.hpp"
