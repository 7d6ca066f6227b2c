#include "page_names.hpp"

#include <cctype>
#include <string>
#include <string_view>

#include "cia402/motion/homing.hpp"
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
  std::vector<std::uint16_t> listed = {object_index::modes_of_operation, object_index::target_position,
                                       object_index::profile_velocity, object_index::target_torque,
                                       object_index::homing_method, object_index::home_offset};
  for (int i = 0; i < option_count; ++i) listed.push_back(option_index(static_cast<option>(i)));
  listed.insert(listed.end(), {object_index::profile_acceleration, object_index::profile_deceleration,
                               object_index::quick_stop_deceleration});
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

std::vector<std::int64_t> accepted_values(const profile& p, std::uint16_t index) {
  std::vector<std::int64_t> values;
  option opt{};
  if (option_of_index(index, opt)) {
    for (int v = 0; v < 16; ++v) {
      if (p.spec(opt).allows(v)) values.push_back(v);
    }
  }
  // The modes 0x6502 announces, the homing methods the drive runs: a choice, not a number.
  if (index == object_index::modes_of_operation) {
    const object_description* supported = find_drive_object(object_index::supported_drive_modes);
    for (int m = 1; m <= 10 && supported != nullptr; ++m) {
      if (mode::supported_bit(m) & static_cast<std::uint32_t>(supported->default_value)) values.push_back(m);
    }
  }
  if (index == object_index::homing_method) {
    for (int m = 0; m <= 37; ++m) {
      if (motion::homing::supports(m)) values.push_back(m);
    }
  }
  return values;
}

namespace {

struct mode_words {
  std::int64_t mode;
  const char* title;
  const char* control[4];  // bits 4, 5, 6, 9
  const char* status[2];   // bits 12, 13
};

// CiA 402-2 (IEC 61800-7-201), the mode-specific bits of 0x6040 and 0x6041 per mode (docs/modes.md).
// A bit a mode does not use is "Reserved in <mode>".
constexpr mode_words mode_table[] = {
    {mode::profile_position, "Profile position",
     {"New set-point", "Change set immediately", "Relative (0 absolute)", "Change on set-point"},
     {"Set-point acknowledge", "Following error"}},
    {mode::profile_velocity, "Profile velocity", {nullptr, nullptr, nullptr, nullptr},
     {"Speed = 0", "Max slippage error"}},
    {mode::profile_torque, "Profile torque", {nullptr, nullptr, nullptr, nullptr}, {nullptr, nullptr}},
    {mode::homing, "Homing", {"Homing operation start", nullptr, nullptr, nullptr},
     {"Homing attained", "Homing error"}},
    {mode::cyclic_synchronous_position, "Cyclic synchronous position",
     {nullptr, nullptr, nullptr, nullptr}, {"Drive follows the command value", "Following error"}},
    {mode::cyclic_synchronous_velocity, "Cyclic synchronous velocity",
     {nullptr, nullptr, nullptr, nullptr}, {"Drive follows the command value", nullptr}},
    {mode::cyclic_synchronous_torque, "Cyclic synchronous torque",
     {nullptr, nullptr, nullptr, nullptr}, {"Drive follows the command value", nullptr}},
};

const mode_words* words_of(std::int64_t m) noexcept {
  for (const mode_words& w : mode_table) {
    if (w.mode == m) return &w;
  }
  return nullptr;
}

// "Reserved in pv": a bit the mode does not use (the short names of cia402::mode::short_name).
const char* reserved_in(std::int64_t m) noexcept {
  constexpr const char* names[] = {nullptr,          "Reserved in pp",  nullptr,
                                   "Reserved in pv", "Reserved in tq",  nullptr,
                                   "Reserved in hm", nullptr,           "Reserved in csp",
                                   "Reserved in csv", "Reserved in cst"};
  return m >= 0 && m <= 10 ? names[m] : nullptr;
}

}  // namespace

const char* mode_title(std::int64_t m) noexcept {
  const mode_words* w = words_of(m);
  return w != nullptr ? w->title : "";
}

bool left_to_mode(const profile& p, bool control_word, int bit) noexcept {
  if (bit < 0 || bit > 15) return false;
  const word_bit_names& n = bit_names_of(p);
  const std::string_view name = control_word ? n.control[bit] : n.status[bit];
  return name == "Operation mode specific" || name == "Mode specific";
}

const char* mode_bit_name(const profile& p, bool control_word, int bit, std::int64_t m) noexcept {
  const mode_words* w = words_of(m);
  if (w == nullptr || !left_to_mode(p, control_word, bit)) return nullptr;
  const char* name = nullptr;
  if (control_word) {
    switch (bit) {
      case 4: name = w->control[0]; break;
      case 5: name = w->control[1]; break;
      case 6: name = w->control[2]; break;
      case 9: name = w->control[3]; break;
      default: return nullptr;
    }
  } else {
    switch (bit) {
      case 12: name = w->status[0]; break;
      case 13: name = w->status[1]; break;
      default: return nullptr;
    }
  }
  return name != nullptr ? name : reserved_in(m);
}

}  // namespace cia402::page
