// Names the page shows: the 16 bits of each word as the profile's documents name them, and the
// objects the page can write.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cia402/profile.hpp"

namespace cia402::page {

struct bit_names {
  const char* control_word = "";  ///< "controlword 0x6040" or "STW"
  const char* status_word = "";
  std::array<const char*, 16> control{};
  std::array<const char*, 16> status{};
};

/// The profile's names of the bits (cia402::bit_names_of: CiA 402's, or DRIVECOM's STW / ZSW on the
/// PROFIBUS profiles).
bit_names bit_names_for(const profile& p);

struct object_name {
  std::uint16_t index = 0;
  std::string name;
};

/// The objects the page offers to write: the mode and its set-points, the profile's option codes,
/// then the ramps.
std::vector<object_name> object_names(const profile& p);

/// The values a write of `index` may take where they are a choice, not a range: an option code's
/// values the profile allows, the modes 0x6502 announces (0x6060), the homing methods the drive
/// runs (0x6098); empty for any other object.
std::vector<std::int64_t> accepted_values(const profile& p, std::uint16_t index);

/// The name CiA 402-2 gives an operation mode ("Profile position", ...), "" for any other value.
const char* mode_title(std::int64_t m) noexcept;

/// A bit's name in operation mode `m` where the profile leaves the bit to the mode (CiA 402's
/// "Operation mode specific", DRIVECOM's "Mode specific"): control bits 4, 5, 6, 9 and status bits
/// 12, 13 as CiA 402-2 names them in that mode ("New set-point", "Homing attained", "Reserved in
/// csv", ...). nullptr where the profile's own name stands: a bit the profile names itself
/// (DRIVECOM's STW bit 4 "Fast stop / inhibit ramp function generator"), or a value that is no mode.
const char* mode_bit_name(const profile& p, bool control_word, int bit, std::int64_t m) noexcept;

/// Whether the profile leaves this bit of the word to the operation mode.
bool left_to_mode(const profile& p, bool control_word, int bit) noexcept;

}  // namespace cia402::page
