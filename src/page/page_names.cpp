#include "page_names.hpp"

#include <cctype>
#include <string>
#include <string_view>

#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::page {

bit_names bit_names_for(const profile& p) {
  const word_bit_names& n = bit_names_of(p);  // the profile's own names (core)
  bit_names out;
  out.control_word = n.control_word;
  out.status_word = n.status_word;
  for (int b = 0; b < 16; ++b) {
    out.control[b] = n.control[b];
    out.status[b] = n.status[b];
  }
  return out;
}

// The objects the page lists for writing: the mode and its set-points first, then the option codes
// the profile has and the ramps, named from the one object table ("Quick stop option code" ->
// "quick stop option code (rpm/s)").
std::vector<object_name> object_names(const profile& p) {
  constexpr std::uint16_t listed[] = {object_index::modes_of_operation, object_index::target_position,
                                      object_index::profile_velocity, object_index::target_torque,
                                      object_index::homing_method, object_index::home_offset,
                                      0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007,
                                      object_index::profile_acceleration, object_index::profile_deceleration,
                                      object_index::quick_stop_deceleration};
  std::vector<object_name> out;
  for (const std::uint16_t index : listed) {
    option opt{};
    if (option_of_index(index, opt) && !p.spec(opt).exists()) continue;
    const object_description* o = find_drive_object(index);
    if (o == nullptr) continue;
    std::string name = o->name;
    if (!name.empty()) name[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(name[0])));
    if (o->unit[0] != '\0') name += std::string(" (") + o->unit + ")";
    out.push_back({index, std::move(name)});
  }
  return out;
}

}  // namespace cia402::page
