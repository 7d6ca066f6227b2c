#include "page_names.hpp"

#include <string_view>

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

std::vector<object_name> object_names(const profile& p) {
  constexpr object_name options[] = {
      {0x605A, "quick stop option code"},   {0x605B, "shutdown option code"},
      {0x605C, "disable operation option code"}, {0x605D, "halt option code"},
      {0x605E, "fault reaction option code"}, {0x6007, "abort connection option code"},
  };
  std::vector<object_name> out;
  for (const object_name& o : options) {
    option opt{};
    if (option_of_index(o.index, opt) && p.spec(opt).exists()) out.push_back(o);
  }
  out.push_back({sim::object::profile_acceleration, "profile acceleration (rpm/s)"});
  out.push_back({sim::object::profile_deceleration, "profile deceleration (rpm/s)"});
  out.push_back({sim::object::quick_stop_deceleration, "quick stop deceleration (rpm/s)"});
  return out;
}

}  // namespace cia402::page
