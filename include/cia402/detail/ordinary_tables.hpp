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
/// part is row_offset[bits 0..7]; one base serves both tables. 16.5 KiB a profile; a firmware built
/// for size has none (profile::ordinary).
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
};

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
