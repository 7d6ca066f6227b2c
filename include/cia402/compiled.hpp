// A profile compiled to a lookup table: the drive-side step at the speed of a table, with every
// feature of the full step kept. The table is derived once, by running detail::full_step on every
// (state, decoded command, control-word bit 7, the axis's two remembered bits) an ordinary cycle can
// meet; the rows stay the one source of truth. A stop that runs or starts goes to a second table,
// built the same way for an axis with the profile's default option codes. What neither holds (a
// fault, STO, no DC link, no remote control, a lost link, a local request, overspeed, other option
// codes) goes to detail::full_step, so the compiled step is exactly the full step: the model check
// (tests/core/model_check.hpp) proves it on every reachable pair of every built-in profile.
//
// Where the table lives: in RAM, built by the constructor: 1,024 keys of 16 bytes (an 8-byte axis
// word entry and an 8-byte image of the outputs), 16 KiB a profile, of which the 576 keys of the
// nine states are used (the gaps buy a key of one mask), and 148 KiB for the stop table.
// Built at run time because a profile loaded from a file can only be compiled then, and because
// on a Cortex-M4 16 KiB of flash for each profile would cost more than the whole interpreter: a
// firmware there runs cia402::step(profile, ...) and keeps its flash. Build it once at start-up,
// outside the control loop: the constructor runs the full step a few hundred thousand times.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "cia402/drive.hpp"

namespace cia402 {

class compiled_profile;

/// What an ordinary cycle with a key does to the axis: its first four bytes (flags, state, pending
/// row, last transition) after the cycle are (before & keep) | set, in the axis's own byte order.
/// The pending row is none before (tested) and after, so set's third byte is 0xFF and keep's is
/// free: it carries the actions (compiled_profile::fallback, ...), which one test reads in the word
/// that is loaded anyway, and which an OR with 0xFF leaves no trace of.
struct compiled_entry {
  std::uint32_t keep = 0;
  std::uint32_t set = 0;
};

class compiled_profile {
 public:
  /// The key of an entry: bits 0..3 the state, 4..6 the decoded command, 7 control-word bit 7, 8
  /// and 9 the axis flags fault_reset_bit (bit 7 before) and torque_on. So the state and the flags,
  /// adjacent in `axis`, come with the one load of the axis's first word and one mask, and bits
  /// 0..7 of the control word with one byte load and one lookup. 9 of 16 state slots are used.
  /// An entry's place in the tables is not the key itself but offset_of(key).
  static constexpr std::size_t entry_count = 1024;

  /// The byte offset of a key's entry in each of the two tables: the state times 256, the
  /// command's three bits times 32, the two flags times 8, control-word bit 7 times 4,096. The
  /// axis keeps the flags in bits 3 and 4 of the byte before the state, so the axis's part of the
  /// offset is its word under one mask, already a multiple of the entry's 8 bytes: the load of the
  /// entry takes a base and an index, with no scale, which is a cycle shorter on the path from one
  /// cycle's axis word to the next (docs/compiled-step.md).
  static constexpr std::size_t offset_of(unsigned key) noexcept {
    return ((key & 0xFu) << 8) | (((key >> 4) & 7u) << 5) | (((key >> 8) & 3u) << 3) |
           (((key >> 7) & 1u) << 12);
  }

  explicit compiled_profile(const profile& p) noexcept;

  const profile& source() const noexcept { return *profile_; }
  /// Entries the table answers itself (the rest fall back to the full step), of the 576 keys the
  /// nine states can have.
  std::size_t covered() const noexcept;
  /// Entries the stop table answers (cycles with a stop running or starting, on an axis whose
  /// option codes are the profile's defaults).
  std::size_t stops_covered() const noexcept;
  /// Whether the stop table had room for every key it tried (true for the built-in profiles). Where
  /// it had not, the full step answers the keys left over; a key whose entries would all have
  /// fallen back counts as left over too, so false is the cautious answer.
  bool stops_complete() const noexcept { return stops_complete_; }

  static constexpr std::uint8_t halt_possible = 1u << 0;  ///< running, and the profile has 0x605D
  static constexpr std::uint8_t fallback = 1u << 1;       ///< detail::full_step decides
  static constexpr std::uint8_t runs = 1u << 2;           ///< the status word shows target reached
  static constexpr std::uint8_t resets_error = 1u << 3;   ///< a fault reset (T15, seed 001 T16)

 private:
  friend drive_outputs step(const compiled_profile& c, axis& a, const drive_inputs& in) noexcept;

  // The two 8-byte tables of a key, one after the other, each laid out by offset_of: a command's
  // row is one offset from their start, and the axis word under a mask indexes both, so no shift,
  // add or scale lies on the path from one cycle's axis word to the next.
  struct tables {
    std::array<compiled_entry, entry_count> entries{};
    /// Bytes 0..7 of the drive_outputs of each key (state, status word without the reported bits,
    /// transition, no ramp, torque, brake; padding zero): the outputs are one load and one OR.
    std::array<std::uint64_t, entry_count> images{};
  };
  tables tables_;
  /// Control-word bits 0..7 to the byte offset of the command's row in `tables_`: offset_of key
  /// bits 4..7 (the decoded command and bit 7).
  std::array<std::uint16_t, 256> row_offset_{};
  /// The same as key bits 4..7, for the rare paths: their own bytes, so the ordinary cycle does
  /// not keep the row offset in a register for them.
  std::array<std::uint8_t, 256> command_key_{};
  const profile* profile_;
  std::int64_t speed_offset_ = 0;          ///< limit - 1 (0 without a limit)
  std::uint64_t speed_span_ = ~0ull;       ///< 2 * limit - 2 (every value without a limit)
  bool has_speed_limit_ = false;

  // Whether the speed leaves the range every entry was built for (|speed| < limit, or any speed
  // without a limit). One unsigned compare, in 64 bits so no limit or speed can overflow it.
  bool beyond_speed_limit(const drive_inputs& in) const noexcept {
    return static_cast<std::uint64_t>(std::int64_t{in.actual_speed_rpm} + speed_offset_) > speed_span_;
  }

  // The stop table: what the ordinary table leaves to the full step because a stop runs (a pending
  // row's ramp, QUICK STOP ACTIVE) or starts (T5, T8 or a quick stop whose outcome the option codes
  // decide). Its entries hold for an axis with the profile's default option codes, so the option
  // codes need not be in the key; standstill, the brake and the pending row are. Its key is the
  // ordinary key and whether a fault brought the axis to its state (axis_key): seed 001's T16
  // leaves QUICK STOP ACTIVE on Enable Operation only after a quick stop the fieldbus asked for.
  // Reached on the branch the ordinary cycle does not take, so the larger key costs that cycle
  // nothing.
  struct stop_entry {
    std::uint32_t keep = 0;  ///< the axis's first four bytes: (before & keep) | set
    std::uint32_t set = 0;
    std::uint64_t image = 0;  ///< the outputs' first 8 bytes, as tables::images
    std::int8_t code_before = 0;  ///< the stop code the axis must have (S16)
    std::int8_t code_after = 0;   ///< its stop code after the cycle
    std::uint8_t actions = fallback;
  };
  static constexpr std::size_t stop_block = 16;  ///< per key: standstill, brake, 4 pending slots
  /// 384 blocks of 16: ax2000-profibus fills them all (stops_complete()).
  static constexpr std::size_t stop_capacity = 6144;
  static constexpr std::uint16_t no_block = 0xFFFF;
  static constexpr std::uint8_t no_slot = 0xFF;

  // The full step on a copy of the inputs. It is the only place the inputs' address is taken; on a
  // copy made there, a caller's inputs built in locals stay in registers on the table's path
  // instead of being stored to memory every cycle for a call that seldom comes (10,000 axes: 2.45x
  // the bare table's time where passing them on was 3.01x, docs/compiled-step.md).
  drive_outputs full_on_copy(axis& a, const drive_inputs& in) const noexcept {
    const drive_inputs copy = in;
    return detail::full_step(*profile_, a, copy);
  }
  // A cycle with ordinary inputs that the ordinary table leaves out: the stop table, else the full
  // step. `word` is the axis's first four bytes; the key is found here, off the step's own code,
  // which g++ -O2 inlines only below a size it is at (step()). Inline: a call here cost
  // the transition sequence 0.5 ns a step (docs/compiled-step.md). The inputs come by value for
  // the same reason as full_on_copy's copy: where the compiler calls it rather than inlining it
  // (g++ -O2), a reference would put the caller's inputs in memory on every cycle.
  inline drive_outputs stop_step(axis& a, drive_inputs in, std::uint32_t word) const noexcept;
  void compile_stops() noexcept;

  std::array<stop_entry, stop_capacity> stops_{};
  /// The stop table's keys: the ordinary key's ten bits, and bit 10 axis_flag::entered_by_fault.
  static constexpr std::size_t stop_key_count = 2048;
  std::array<std::uint16_t, stop_key_count> stop_block_{};  ///< key -> first of its 16, or no_block
  std::array<std::uint8_t, 256> slot_of_row_{};  ///< pending row -> 1..3 (none: 0), or no_slot
  std::int8_t default_options_[option_count] = {};
  bool stops_complete_ = true;

  // The axis's part of the stop table's key (the state, the flags fault_reset_bit and torque_on as
  // bits 8 and 9, entered_by_fault as bit 10), for the rare paths.
  static unsigned axis_key(std::uint32_t word) noexcept;
};

namespace detail {

/// The first 8 bytes of drive_inputs as an ordinary cycle has them: no fault code, DC link, no STO,
/// remote, link up, no local request. One compare tells an ordinary cycle from one the table does
/// not hold.
inline std::uint64_t ordinary_head() noexcept {
  static_assert(offsetof(drive_inputs, local_disable) + sizeof(bool) <= 8,
                "the unusual inputs must fill the first 8 bytes of drive_inputs");
  constexpr drive_inputs defaults{};
  std::uint64_t head = 0;
  std::memcpy(&head, &defaults, 8);
  return head;
}

}  // namespace detail

static_assert(compiled_profile::runs == ordinary_action::runs,
              "detail::reported_bits reads both tables' runs bit");

inline unsigned compiled_profile::axis_key(std::uint32_t word) noexcept {
  const unsigned flags = (word >> detail::byte_shift<4>(0)) & 0xFFu;
  const unsigned current = (word >> detail::byte_shift<4>(1)) & 0xFu;
  static_assert(axis_flag::fault_reset_bit == 1u << 3 && axis_flag::torque_on == 1u << 4 &&
                    axis_flag::entered_by_fault == 1u << 0,
                "the key's flags are bits 3, 4 and 0 of axis::flags");
  return current | (((flags >> 3) & 3u) << 8) | ((flags & 1u) << 10);
}

inline drive_outputs compiled_profile::stop_step(axis& a, drive_inputs in,
                                                std::uint32_t word) const noexcept {
  const std::uint16_t block = stop_block_[axis_key(word) | command_key_[in.control_word & 0xFFu]];
  const std::uint8_t slot = slot_of_row_[(word >> detail::byte_shift<4>(2)) & 0xFFu];
  if ((block != no_block) & (slot != no_slot) & !(in.control_word & control_bit::halt) &&
      std::memcmp(a.options, default_options_, sizeof default_options_) == 0) {
    const stop_entry& e = stops_[block + (static_cast<unsigned>(in.standstill) |
                                          (static_cast<unsigned>(in.brake_engaged) << 1) |
                                          (static_cast<unsigned>(slot) << 2))];
    if (!(e.actions & fallback) && a.stop_code == e.code_before) {
      const std::uint32_t after = (word & e.keep) | e.set;
      std::memcpy(static_cast<void*>(&a), &after, 4);
      a.stop_code = e.code_after;
      if (e.actions & resets_error) a.error_code = 0;
      const unsigned reported = detail::reported_bits(in.status_bits, e.actions);
      return detail::outputs_of(e.image | (std::uint64_t{reported} << detail::status_shift),
                                a.error_code);
    }
  }
  return detail::full_step(*profile_, a, in);  // `in` is a copy already
}

/// Runs one cycle: one table load for an ordinary cycle, the stop table for a stop that runs or
/// starts, detail::full_step for the rest. The same outputs and axis as cia402::step(profile, ...),
/// byte for byte.
///
/// Meant to be inlined into the caller's loop, and g++ 12 does so at -O2 and -O3. At -O2 it is at
/// the size where the inliner stops: one branch more and the bench's loop called it, which doubled
/// the quiet cycle. Forcing it with always_inline was no cure: GCC then built the outputs field by
/// field, about as slow (docs/compiled-step.md). bench/inlining/inlined.sh fails when g++ stops
/// inlining it into the bench's loops at -O2 or -O3.
inline drive_outputs step(const compiled_profile& c, axis& a, const drive_inputs& in) noexcept {
  std::uint64_t head;
  std::memcpy(&head, &in, 8);
  if (head != detail::ordinary_head()) return c.full_on_copy(a, in);
  // A profile with a limit (lexium32) checks the speed off the path. In line, beside the two loads
  // below, the check cost lexium32's quiet cycle about 0.2 ns at -O2: this loop is near what the
  // front end delivers in its 7 cycles (docs/compiled-step.md).
  if (detail::seldom(c.has_speed_limit_) && c.beyond_speed_limit(in)) return c.full_on_copy(a, in);
  static_assert(offsetof(axis, flags) == 0 && offsetof(axis, current) == 1 &&
                    offsetof(axis, pending_row) == 2 && offsetof(axis, last_transition) == 3 &&
                    alignof(axis) >= 4,
                "the table rewrites the axis's first four bytes as one aligned word");
  const unsigned cw = in.control_word;
  // The first four bytes of the axis are read, and written back, as one word: no branch on
  // whether a row fires, and a wide load of what the last cycle stored in narrow stores would
  // wait for all of them (store forwarding).
  std::uint32_t word;
  std::memcpy(&word, &a, 4);
  // The axis's part of the entry's offset (compiled_profile::offset_of): the state's byte times
  // 256 and the two flags times 8, as they lie in the word.
  static_assert(compiled_profile::offset_of(0x30Fu) == 0xF18u, "the axis's part is the word & 0xF18");
  const std::size_t axis_offset =
      (detail::little_endian ? word : (((word >> 24) & 0xFFu) | ((word >> 8) & 0xFF00u))) & 0xF18u;
  // The command's row first: it does not depend on the last cycle, so only a mask lies between the
  // axis word and the load of the entry, and one base serves both tables.
  const unsigned char* row =
      reinterpret_cast<const unsigned char*>(&c.tables_) + c.row_offset_[cw & 0xFFu];
#if defined(__GNUC__)
  // Keeps the compiler from folding the row back into the axis's index (an add more between one
  // cycle's axis word and the next).
  __asm__("" : "+r"(row));
#endif
  // Keep and set as two loads: keep's is a base and an index (4 cycles before the AND), set's has a
  // displacement too (5 cycles, but it is needed a cycle later, for the OR), and no shift splits
  // them: one instruction less in a loop that the front end bounds about as much as the chain.
  static_assert(sizeof(compiled_entry) == 8 && offsetof(compiled_entry, set) == 4, "keep, then set");
  std::uint32_t keep;
  std::memcpy(&keep, row + axis_offset, sizeof keep);
  std::uint32_t set;
  std::memcpy(&set, row + axis_offset + offsetof(compiled_entry, set), sizeof set);
  std::uint64_t image;
  std::memcpy(&image, row + offsetof(compiled_profile::tables, images) + axis_offset, sizeof image);
  // Byte 2: the pending row's in the axis word, the actions' in keep.
  constexpr unsigned actions_shift = detail::byte_shift<4>(2);
  const unsigned actions = (keep >> actions_shift) & 0xFFu;
  const unsigned reported = detail::reported_bits(in.status_bits, actions);
  std::uint64_t head_out = image | (std::uint64_t{reported} << detail::status_shift);
  // A stop runs (the pending row is not 0xFF: adding one to its byte leaves it nonzero).
  if (detail::seldom(((word + (1u << actions_shift)) & (0xFFu << actions_shift)) != 0)) {
    return c.stop_step(a, in, word);
  }
  // One test of the entry's keep word for the rare entries: it falls back (the stop table, else the
  // full step decides), the state runs and the control word halts (bit 8), or a fault reset clears
  // the error code.
  if (detail::seldom(keep & ((((cw >> 8) & 1u) | compiled_profile::fallback |
                              compiled_profile::resets_error)
                             << actions_shift))) {
    if (actions & compiled_profile::fallback) {
      return c.stop_step(a, in, word);
    }
    if (actions & compiled_profile::resets_error) a.error_code = 0;
    if ((actions & compiled_profile::halt_possible) && (cw & control_bit::halt)) {
      // 0x605D: 1 slow-down, 2 quick-stop, 3 current limit, 4 voltage limit (stop_ramp's values,
      // S8); bit 10 then says standstill.
      const auto ramp = static_cast<std::uint8_t>(a.options[static_cast<int>(option::halt)]);
      const unsigned standstill = static_cast<unsigned>(in.standstill) << 10;
      head_out = (head_out & ~(std::uint64_t{status_bit::target_reached} << detail::status_shift)) |
                 (std::uint64_t{standstill} << detail::status_shift) |
                 (std::uint64_t{ramp} << detail::byte_shift<8>(5));
    }
  }
  // A committed row's stop code needs no clearing: outside a stop it is 0 (S16; the model check
  // holds every reachable axis to it).
  const std::uint32_t after = (word & keep) | set;
  // Stored every cycle, whole: a store only on a change would be a branch that a command changing
  // at random mispredicts, and the next cycle's load of the same word is forwarded from this store.
  std::memcpy(static_cast<void*>(&a), &after, 4);
  return detail::outputs_of(head_out, a.error_code);
}

}  // namespace cia402
