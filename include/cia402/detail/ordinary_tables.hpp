// The ordinary cycles a profile compiles from its rows (profile::finalize, profile::ordinary), in the
// layout the inline step reads (detail/quiet_step.hpp). Data only: profile.hpp compiles them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace cia402 {

/// What an ordinary cycle (detail/quiet_step.hpp: default inputs, no stop running, |speed| below the
/// limit) does, compiled from the rows for every key: the state, the decoded command, control-word
/// bit 7 and the axis's flags fault_reset_bit and torque_on. Each key has an 8-byte axis entry (the
/// axis's first four bytes, flags, state, pending row, last transition, after the cycle are
/// (before & keep) | set) and an 8-byte image of the outputs' first 8 bytes (state, clear
/// set-points, status pattern | 0x0210 for voltage enabled and remote, transition, no ramp, torque,
/// brake released). The pending row is none before (tested) and after, so set's third byte is 0xFF
/// and keep's is free: it holds the entry's ordinary_action bits.
///
/// Laid out by offset_of, as compiled_profile's tables: the axis's part of a key's byte offset is
/// its first word under one mask (the state times 256, the two flags times 8), the control word's
/// part is row_offset[bits 0..7]; one base serves both tables. 21.5 KiB a profile with the stop words
/// and row entries; a firmware built for size has none (profile::ordinary).
struct ordinary_tables {
  static constexpr std::size_t entry_count = 1024;
  /// Byte offset of a key: bits 0..3 the state, 4..6 the decoded command, 7 control-word bit 7, 8
  /// and 9 the axis flags fault_reset_bit and torque_on.
  static constexpr std::size_t offset_of(unsigned key) noexcept {
    return ((key & 0xFu) << 8) | (((key >> 4) & 7u) << 5) | (((key >> 8) & 3u) << 3) |
           (((key >> 7) & 1u) << 12);
  }
  /// keep, set of each key, at offset_of(key) in bytes.
  std::array<std::uint32_t, 2 * entry_count> axis_words{};
  /// The outputs' image of each key, at sizeof(axis_words) + offset_of(key) in bytes.
  std::array<std::uint64_t, entry_count> images{};
  /// Control-word bits 0..7 to offset_of of key bits 4..7 (the decoded command and bit 7).
  std::array<std::uint16_t, 256> row_offset{};

  /// What each key's cycle is where a stop runs or starts (stop_word), at offset_of(key) / 8: the
  /// cycles the entries above leave to the rare path (detail/quiet_step.hpp).
  std::array<std::uint32_t, entry_count> stop_words{};
  /// A row's state change, and its stop while that runs, as a cycle with a pending row needs them.
  struct row_entry {
    std::uint32_t keep = 0;          ///< the commit, as an entry's axis words (set: bit 7's flag clear)
    std::uint32_t set = 0;
    std::uint64_t image = 0;         ///< the outputs' first 8 bytes after the commit
    std::uint64_t stop_image = 0;    ///< the outputs' first 8 bytes while the stop runs (ramp 0: 0x605D's)
    std::uint8_t actions = 0;        ///< row_action bits
    std::uint8_t stop_state = 0xFF;  ///< the one state the row leaves, where its stop runs
  };
  static constexpr std::size_t row_capacity = 32;  ///< max_rows (profile.hpp checks)
  std::array<row_entry, row_capacity> row_entries{};
};

/// A stop word: byte 0 its kind, byte 1 stop_flag bits, byte 2 the row that fires on the key plus
/// one (0: none), byte 3 (in QUICK STOP ACTIVE) the row that fires instead once the stop is
/// complete, plus one (0: the same). Every entry but the `none` kind holds only for an axis whose
/// 0x605A is the profile's default, with entered_by_fault and fault_latched clear, and no halt.
namespace stop_kind {
inline constexpr std::uint8_t none = 0;            ///< detail::full_step decides
inline constexpr std::uint8_t ordinary = 1;        ///< the entry is an ordinary one: a pending stop reads its row
inline constexpr std::uint8_t stop_start = 2;      ///< the entry starts its row's stop (S7)
inline constexpr std::uint8_t enters_quick_stop = 3;  ///< its row enters QUICK STOP ACTIVE (T11)
inline constexpr std::uint8_t in_quick_stop = 4;   ///< the axis is in QUICK STOP ACTIVE
}  // namespace stop_kind

namespace stop_flag {
inline constexpr std::uint8_t interrupts = 1u << 0;  ///< the key's row takes over a running stop (S7)
inline constexpr std::uint8_t lands_in_quick_stop = 1u << 1;  ///< the axis is in QUICK STOP ACTIVE after
inline constexpr std::uint8_t quick_stop_ends_torque = 1u << 2;  ///< 0x605A 1..4: the brake closes at standstill
inline constexpr std::uint8_t quick_stop_stays = 1u << 3;  ///< 0x605A 5..8: bit 10 at standstill
inline constexpr std::uint8_t quick_stop_coasts = 1u << 4; ///< the stop is complete at once
inline constexpr std::uint8_t has_halt = 1u << 5;    ///< the profile has 0x605D: bit 8 halts (S8)
}  // namespace stop_flag

/// row_entry::actions.
namespace row_action {
inline constexpr std::uint8_t commits = 1u << 0;     ///< `keep`, `set` and `image` hold
inline constexpr std::uint8_t stop_runs = 1u << 1;   ///< `stop_image` and `stop_state` hold
inline constexpr std::uint8_t runs = 1u << 2;        ///< the state after runs (ordinary_action::runs)
inline constexpr std::uint8_t stop_ends_torque = 1u << 3;  ///< the brake closes at standstill (S12)
inline constexpr std::uint8_t stop_reads_code = 1u << 4;   ///< its stop ran only because the code was 1
inline constexpr std::uint8_t halt_ramp = 1u << 5;         ///< its ramp is 0x605D's, read live (S16)
}  // namespace row_action

struct profile;
namespace detail {
/// Fills t's stop words and row entries, and the entries of the keys that enter or stay in QUICK
/// STOP ACTIVE (detail/stop_entries.hpp), after profile::compile_ordinary has filled the rest.
constexpr void compile_stop_entries(const profile& p, ordinary_tables& t) noexcept;
}  // namespace detail

/// Byte 2 of an entry's keep word.
namespace ordinary_action {
inline constexpr std::uint8_t has_halt = 1u << 0;     ///< the profile has 0x605D (S8)
inline constexpr std::uint8_t full = 1u << 1;         ///< detail::full_step decides every such cycle
inline constexpr std::uint8_t runs = 1u << 2;         ///< the state after runs: bit 10 shows, halt acts
/// With `full`: torque is on and the row that fires stops first (S7); set's byte 2 is its index.
inline constexpr std::uint8_t stop_starts = 1u << 3;
inline constexpr std::uint8_t stop_reads_code = 1u << 4;   ///< it ramps only if 0x605B (0x605C) is 1
inline constexpr std::uint8_t stop_code_605c = 1u << 6;    ///< that code is 0x605C
inline constexpr std::uint8_t stop_ends_torque = 1u << 7;  ///< the brake closes at standstill (S12)
inline constexpr std::uint8_t speed_limit = 1u << 5;  ///< the profile watches |speed| (seed 001)
}  // namespace ordinary_action

}  // namespace cia402
