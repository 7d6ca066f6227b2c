// The ordinary cycle of the drive-side machine, inline so a controller's loop over its axes compiles
// it in place. Most cycles of a running drive are ordinary: no fault, voltage on, no STO, remote
// control, no stop running, and the control word either asks for the state the drive is in or for
// a transition that takes effect at once (T2, T3, T4, T6, T7, T9, T10, ...) or whose stop starts
// under torque (T5, T8: S7). This path handles exactly those, by one entry of the profile's compiled ordinary cycles (profile::ordinary, which
// finalize() compiles from the rows: at compile time for the built-in profiles, at load for a
// profile file), and returns false, touching nothing, whenever anything else might happen;
// detail::full_step (src/core/drive.cpp) then does the whole work. The model check
// (tests/core/model_check.hpp) holds the two equal on every reachable pair of every built-in profile.
#pragma once

#include <cstddef>
#include <cstring>

namespace cia402::detail {

/// A condition the ordinary cycle does not meet: its code is laid out away from the table's path.
inline constexpr bool seldom(bool condition) noexcept {
#if defined(__GNUC__)
  return __builtin_expect(condition, false);
#else
  return condition;
#endif
}

/// The outputs from their first 8 bytes (`head`: all an entry decides) and what fills the second:
/// 0x603F (bytes 8, 9) and its 0x1001 (byte 10). Two whole words, no field stores.
inline drive_outputs outputs_of(std::uint64_t head, std::uint16_t code) noexcept {
  static_assert(sizeof(drive_outputs) == 16 && offsetof(drive_outputs, clear_setpoints) == 1 &&
                    offsetof(drive_outputs, status_word) == 2 && offsetof(drive_outputs, ramp) == 5 &&
                    offsetof(drive_outputs, error_code) == 8 && offsetof(drive_outputs, error_register) == 10,
                "the outputs are two 8-byte words");
  std::uint64_t tail = std::uint64_t{code} << (little_endian ? 0u : 48u);
  // No error is the rule: its register (0) costs no branch the ordinary cycle takes.
  if (seldom(code != 0)) tail |= std::uint64_t{error_register_of(code)} << byte_shift<8>(2);
#if defined(__GNUC__)
  // One register for both ways: GCC would otherwise build the no-error tail (0) in memory and
  // load it back into the vector register that carries the outputs.
  __asm__("" : "+r"(tail));
#endif
  drive_outputs out;
  std::memcpy(static_cast<void*>(&out), &head, 8);
  std::memcpy(reinterpret_cast<unsigned char*>(&out) + 8, &tail, 8);
  return out;
}

/// The motion side's reported status bits an entry with these actions shows: target reached only
/// where the state runs (ordinary_action::runs).
inline unsigned reported_bits(unsigned status_bits, unsigned actions) noexcept {
  static_assert(ordinary_action::runs << 8 == status_bit::target_reached, "runs passes bit 10");
  return status_bits & ((status_bit::reported & ~unsigned{status_bit::target_reached}) |
                        ((actions & ordinary_action::runs) << 8));
}

/// The inputs of an ordinary cycle: no fault code, DC link, no STO, remote, link up, no local
/// request. Field by field rather than one 8-byte load: callers fill inputs field by field, and a
/// wide load over narrow stores stalls store forwarding. Bitwise ORs keep it to one branch.
inline bool ordinary_inputs(const drive_inputs& in) noexcept {
  return !((in.fault_code != 0) | !in.dc_link | in.sto | !in.remote | in.connection_lost |
           in.local_enable | in.local_disable);
}

/// The stop word of a cycle's key (ordinary_tables::stop_words).
inline std::uint32_t stop_word_of(const ordinary_tables& t, unsigned cw, std::size_t axis_offset) noexcept {
  return t.stop_words[(t.row_offset[cw & 0xFFu] + axis_offset) / 8u];
}

/// Row r's state change as this cycle's outcome (a pending stop that completes, or the row QUICK
/// STOP ACTIVE takes once its stop is complete); false, touching nothing, where its entry does not hold.
inline bool commit_entry(const ordinary_tables& t, unsigned r, axis& a, const drive_inputs& in,
                         std::uint32_t word, std::uint64_t& head) noexcept {
  static_assert(row_action::runs == ordinary_action::runs, "reported_bits reads a row's runs bit");
  const ordinary_tables::row_entry& e = t.row_entries[r];
  if (!(e.actions & row_action::commits)) return false;
  const std::uint32_t after = (word & e.keep) | e.set |
                              ((((in.control_word >> 7) & 1u) << 3) << byte_shift<4>(0));  // fault_reset_bit
  std::memcpy(static_cast<void*>(&a), &after, 4);
  a.stop_code = 0;  // S16: outside a stop the code is 0
  head = e.image | (std::uint64_t{reported_bits(in.status_bits, e.actions)} << status_shift);
  return true;
}

/// A cycle whose row enters QUICK STOP ACTIVE (T11) or that runs in it, by the stop word `sw` of its
/// key, for the profile's default 0x605A: `head` holds the entry's image, the entry's axis words
/// are keep and set. False, touching nothing, where the full step must decide.
inline bool quick_stop_cycle(const profile& p, const ordinary_tables& t, axis& a, const drive_inputs& in,
                             std::uint32_t word, std::uint32_t keep, std::uint32_t set, std::uint32_t sw,
                             std::uint64_t& head) noexcept {
  const unsigned kind = sw & 0xFFu, flags = (sw >> 8) & 0xFFu;
  if (kind < stop_kind::enters_quick_stop ||
      ((in.control_word & control_bit::halt) && (flags & stop_flag::has_halt))) {
    return false;
  }
  // S16: the quick stop runs by the code it read as it started; the entry holds for the default.
  const std::int8_t code = p.options[static_cast<int>(option::quick_stop)].default_value;
  const std::int8_t running = kind == stop_kind::enters_quick_stop
                                  ? a.options[static_cast<int>(option::quick_stop)]
                                  : a.stop_code;
  if ((running != code) | ((a.flags & (axis_flag::entered_by_fault | axis_flag::fault_latched)) != 0)) {
    return false;
  }
  const unsigned completes = sw >> 24;
  if (completes != 0 && ((flags & stop_flag::quick_stop_coasts) ||
                         (in.standstill && (in.brake_engaged || !(flags & stop_flag::quick_stop_ends_torque))))) {
    return commit_entry(t, completes - 1u, a, in, word, head);
  }
  const std::uint32_t after = (word & keep) | set;
  std::memcpy(static_cast<void*>(&a), &after, 4);
  const bool lands = (flags & stop_flag::lands_in_quick_stop) != 0;
  a.stop_code = lands ? code : std::int8_t{0};
  if (lands && in.standstill) {
    // At standstill a quick stop that ends with torque off closes the brake (S12); one that holds
    // the state shows bit 10 (target reached).
    if (flags & stop_flag::quick_stop_ends_torque) head &= ~(std::uint64_t{0xFF} << byte_shift<8>(7));
    if (flags & stop_flag::quick_stop_stays) head |= std::uint64_t{status_bit::target_reached} << status_shift;
  }
  return true;
}

/// A cycle with a pending row (its stop runs, S7): the key's row takes over where it interrupts
/// stops, else the stop goes on, or completes at standstill (with the brake engaged where it ends
/// torque). `head` holds the key's entry's image. False, touching nothing, where the full step must decide.
inline bool pending_cycle(const profile& p, const ordinary_tables& t, axis& a, const drive_inputs& in,
                          std::uint32_t word, std::uint32_t keep, std::uint32_t set, std::size_t axis_offset,
                          std::uint64_t& head) noexcept {
  const std::uint32_t sw = stop_word_of(t, in.control_word, axis_offset);
  const unsigned kind = sw & 0xFFu, flags = (sw >> 8) & 0xFFu;
  if (kind == stop_kind::none || kind == stop_kind::in_quick_stop ||
      ((in.control_word & control_bit::halt) && (flags & stop_flag::has_halt))) {
    return false;
  }
  const unsigned pending = (word >> byte_shift<4>(2)) & 0xFFu;
  const unsigned fired = (sw >> 16) & 0xFFu;
  if (fired != 0 && fired - 1u != pending && (flags & stop_flag::interrupts)) {
    if (kind == stop_kind::enters_quick_stop) return quick_stop_cycle(p, t, a, in, word, keep, set, sw, head);
    if (kind != stop_kind::ordinary) return false;  // another row's stop takes over
    const std::uint32_t after = (word & keep) | set;
    std::memcpy(static_cast<void*>(&a), &after, 4);
    a.stop_code = 0;
    return true;
  }
  if (pending >= ordinary_tables::row_capacity) return false;
  const ordinary_tables::row_entry& e = t.row_entries[pending];
  if (!(e.actions & row_action::stop_runs) || ((word >> byte_shift<4>(1)) & 0xFFu) != e.stop_state ||
      ((e.actions & row_action::stop_reads_code) && a.stop_code != 1)) {
    return false;
  }
  std::uint64_t image = e.stop_image;
  if (e.actions & row_action::halt_ramp) {  // 0x605D, read live (S16): 1..4, else the full step's
    const auto ramp = static_cast<std::uint8_t>(a.options[static_cast<int>(option::halt)]);
    if (static_cast<std::uint8_t>(ramp - 1u) >= 4u) return false;
    image |= std::uint64_t{ramp} << byte_shift<8>(5);
  }
  const bool ends = (e.actions & row_action::stop_ends_torque) != 0;
  if (in.standstill && (in.brake_engaged || !ends)) return commit_entry(t, pending, a, in, word, head);
  if (ends && in.standstill) image &= ~(std::uint64_t{0xFF} << byte_shift<8>(7));  // S12
  const unsigned flags_after = axis_flag::torque_on | (((in.control_word >> 7) & 1u) << 3);
  const std::uint32_t after = (word & ~(std::uint32_t{axis_flag::fault_reset_bit} << byte_shift<4>(0))) |
                              (flags_after << byte_shift<4>(0));
  std::memcpy(static_cast<void*>(&a), &after, 4);
  head = image | (std::uint64_t{reported_bits(in.status_bits, 0)} << status_shift);
  return true;
}

/// The ordinary cycle: false, touching nothing, where anything else might happen; else the axis
/// stepped and `head` the outputs' first 8 bytes (outputs_of adds the error code). The same path
/// as the compiled step's (compiled.hpp), on the profile's own tables.
inline bool quiet_cycle(const profile& p, axis& a, const drive_inputs& in, std::uint64_t& head) noexcept {
  static_assert(offsetof(axis, flags) == 0 && offsetof(axis, current) == 1 &&
                    offsetof(axis, pending_row) == 2 && offsetof(axis, last_transition) == 3 &&
                    alignof(axis) >= 4,
                "an ordinary cycle rewrites the axis's first four bytes as one aligned word");
  static_assert(offsetof(drive_outputs, current) == 0 && offsetof(drive_outputs, transition) == 4 &&
                    offsetof(drive_outputs, torque) == 6 && offsetof(drive_outputs, brake_released) == 7,
                "an image is the outputs' first 8 bytes");
  static_assert(axis_flag::fault_reset_bit == 1u << 3 && axis_flag::torque_on == 1u << 4,
                "the key's flags lie where offset_of puts them: the word & 0xF18");
  const ordinary_tables* const tables = p.ordinary;
  if (seldom(!ordinary_inputs(in) | (tables == nullptr))) return false;  // no tables: finalize()
  const unsigned cw = in.control_word;
  // The axis's first four bytes as one word, read and written back whole: a row that fires costs
  // no branch and no field stores.
  std::uint32_t word;
  std::memcpy(&word, &a, 4);
  const std::size_t axis_offset =
      (little_endian ? word : (((word >> 24) & 0xFFu) | ((word >> 8) & 0xFF00u))) & 0xF18u;
  const unsigned char* row = reinterpret_cast<const unsigned char*>(tables) + tables->row_offset[cw & 0xFFu];
  std::uint32_t keep;
  std::memcpy(&keep, row + axis_offset, sizeof keep);
  std::uint32_t set;
  std::memcpy(&set, row + axis_offset + 4, sizeof set);
  std::uint64_t image;
  std::memcpy(&image, row + sizeof(ordinary_tables::axis_words) + axis_offset, sizeof image);
  constexpr unsigned actions_shift = byte_shift<4>(2);
  const unsigned actions = (keep >> actions_shift) & 0xFFu;
  head = image | (std::uint64_t{reported_bits(in.status_bits, actions)} << status_shift);
  // A profile that watches |speed| (seed 001's T2/T7): speed + limit - 1 in [0, 2 limit - 2] is
  // |speed| < limit, one unsigned compare that no speed or limit can overflow (mod 2^32 it is a
  // shift of the interval). Its own test: in the one below, lexium32's every cycle took the rare path.
  if (seldom(keep & (std::uint32_t{ordinary_action::speed_limit} << actions_shift))) {
    const std::uint32_t span = static_cast<std::uint32_t>(p.speed_limit_rpm) - 1u;
    if (static_cast<std::uint32_t>(in.actual_speed_rpm) + span > 2u * span) return false;
  }
  // A stop runs (the pending row is not 0xFF: adding one to its byte leaves it nonzero).
  if (seldom(((word + (1u << actions_shift)) & (0xFFu << actions_shift)) != 0)) {
    return pending_cycle(p, *tables, a, in, word, keep, set, axis_offset, head);
  }
  // One test of the keep word for the rare entries: the full step decides or a stop starts, or the
  // control word halts (bit 8) where the profile has 0x605D.
  if (seldom(keep & ((((cw >> 8) & 1u) | ordinary_action::full) << actions_shift))) {
    if (actions & ordinary_action::full) {
      if (!(actions & ordinary_action::stop_starts)) {
        return quick_stop_cycle(p, *tables, a, in, word, keep, set, stop_word_of(*tables, cw, axis_offset), head);
      }
      // S7: the row's stop starts, by the option code it reads as it starts (S16), if any: a code
      // other than 1 makes the change immediate, which the full step commits.
      std::int8_t code = 0;
      if (actions & ordinary_action::stop_reads_code) {
        code = a.options[static_cast<int>((actions & ordinary_action::stop_code_605c) ? option::disable_operation
                                                                                      : option::shutdown)];
        if (code != 1) return false;
      }
      // The ramp 0x605D picks, read live (S8, S16): 1..4; any other value is the full step's.
      if (((head >> byte_shift<8>(5)) & 0xFFu) == 0) {
        const auto ramp = static_cast<std::uint8_t>(a.options[static_cast<int>(option::halt)]);
        if (static_cast<std::uint8_t>(ramp - 1u) >= 4u) return false;
        head |= std::uint64_t{ramp} << byte_shift<8>(5);
      }
      // A stop that ends with torque off closes the brake at standstill (S12).
      if ((actions & ordinary_action::stop_ends_torque) && in.standstill) {
        head &= ~(std::uint64_t{0xFF} << byte_shift<8>(7));
      }
      const std::uint32_t pending = (word & keep & ~(0xFFu << actions_shift)) | set;
      std::memcpy(static_cast<void*>(&a), &pending, 4);
      a.stop_code = code;
      return true;
    }
    if ((actions & ordinary_action::has_halt) && (cw & control_bit::halt)) {
      // Halt (S8) ramps by 0x605D: 1 slow-down, 2 quick-stop, 3 current limit, 4 voltage limit
      // (stop_ramp's values); bit 10 then says standstill. A value outside 1..4 is the full step's.
      const auto ramp = static_cast<std::uint8_t>(a.options[static_cast<int>(option::halt)]);
      if (static_cast<std::uint8_t>(ramp - 1u) >= 4u) return false;
      if (actions & ordinary_action::runs) {
        const unsigned standstill = static_cast<unsigned>(in.standstill) << 10;
        head = (head & ~(std::uint64_t{status_bit::target_reached} << status_shift)) |
               (std::uint64_t{standstill} << status_shift) | (std::uint64_t{ramp} << byte_shift<8>(5));
      }
    }
  }
  // A committed row's stop code needs no clearing: outside a stop it is 0 (S16; the model check
  // holds every reachable axis to it).
  const std::uint32_t after = (word & keep) | set;
  std::memcpy(static_cast<void*>(&a), &after, 4);
  return true;
}

/// The ordinary cycle with its outputs: false, touching nothing, where the full step must decide.
inline bool quiet_step(const profile& p, axis& a, const drive_inputs& in, drive_outputs& out) noexcept {
  std::uint64_t head = 0;
  if (!quiet_cycle(p, a, in, head)) return false;
  out = outputs_of(head, a.error_code);
  return true;
}

}  // namespace cia402::detail
