#include "page_names.hpp"

#include <cctype>
#include <string>
#include <string_view>

#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::page {
namespace {

constexpr std::array<const char*, 16> cia402_control = {
    "Switch on",
    "Enable voltage",
    "Quick stop (active low)",
    "Enable operation",
    "Operation mode specific",
    "Operation mode specific",
    "Operation mode specific",
    "Fault reset (0->1 edge)",
    "Halt",
    "Operation mode specific",
    "Reserved",
    "Manufacturer specific",
    "Manufacturer specific",
    "Manufacturer specific",
    "Manufacturer specific",
    "Manufacturer specific",
};

constexpr std::array<const char*, 16> cia402_status = {
    "Ready to switch on",
    "Switched on",
    "Operation enabled",
    "Fault",
    "Voltage enabled",
    "Quick stop (active low)",
    "Switch on disabled",
    "Warning",
    "Manufacturer specific",
    "Remote",
    "Target reached",
    "Internal limit active",
    "Operation mode specific",
    "Operation mode specific",
    "Manufacturer specific",
    "Manufacturer specific",
};

// Kollmorgen S300 / Beckhoff AX2000 PROFIBUS STW and ZSW (cia402-reference.md §6.1).
constexpr std::array<const char*, 16> drivecom_control = {
    "Switch on",
    "Inhibit voltage",
    "Fast stop, switch-on inhibited",
    "Operation enabled",
    "Fast stop / inhibit ramp function generator",
    "Pause",
    "Setpoint enable",
    "Reset fault",
    "Jog",
    "Reserved",
    "PZD enable",
    "Start homing (edge)",
    "Reset position",
    "Acknowledge warnings",
    "Manufacturer specific",
    "Manufacturer specific",
};

// Bit 4: the core sets it when DC-link voltage is present, as in CiA 402; the ZSW text ("voltage
// inhibited") is an open point of docs/profiles/s300-profibus.md, so the page names what it shows.
constexpr std::array<const char*, 16> drivecom_status = {
    "Ready for switch-on",
    "Switched on",
    "Operation enabled",
    "Error",
    "Voltage present (DC link)",
    "Fast stop (active low)",
    "Switch-on inhibit",
    "Warning",
    "Following error",
    "Remote",
    "In position",
    "Limit",
    "Mode specific",
    "Mode specific",
    "Manufacturer specific",
    "Manufacturer specific",
};

bool starts_with(const char* s, std::string_view prefix) {
  return std::string_view(s).substr(0, prefix.size()) == prefix;
}

bool is_drivecom(const profile& p) {
  const std::string_view name = p.name;
  return name == "s300-profibus" || name == "ax2000-profibus" ||
         starts_with(p.seed, "003_83442f2f4b0b2bb9") || starts_with(p.seed, "004_e07fd68605b3a8c6");
}

}  // namespace

bit_names bit_names_for(const profile& p) {
  if (is_drivecom(p)) {
    return {"control word STW (0x6040)", "status word ZSW (0x6041)", drivecom_control,
            drivecom_status};
  }
  return {"controlword 0x6040", "statusword 0x6041", cia402_control, cia402_status};
}

// The objects the page lists for writing: the option codes the profile has and the ramps, named
// from the one object table ("Quick stop option code" -> "quick stop option code (rpm/s)").
std::vector<object_name> object_names(const profile& p) {
  constexpr std::uint16_t listed[] = {0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007,
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
