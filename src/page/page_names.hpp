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

/// The objects the page offers to write: the profile's option codes, then the ramps.
std::vector<object_name> object_names(const profile& p);

}  // namespace cia402::page
