// The instrument page's actions in any order: a refused action changes nothing the page shows (while
// nothing the page started earlier is still under way), and no sequence crashes. Each input byte pair is one action; cycles pass between them.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "cia402/apps/local_link.hpp"
#include "cia402/page/axis_page.hpp"
#include "cia402/profile.hpp"

using namespace cia402::page;

namespace {

// The page's drive as `cia402 serve` builds it without a bus: an axis session over a local link.
drive_connection virtual_connection(const cia402::profile& p) {
  auto link = std::make_unique<cia402::apps::local_link>(p);
  cia402::sim::virtual_drive* plant = &link->drive();
  return {std::move(link), plant};
}

// What an action could change (time and results aside).
nlohmann::json observable(const axis_page& inst) {
  nlohmann::json s = nlohmann::json::parse(inst.snapshot_json());
  return {s["state"], s["control_word"], s["dc_link"], s["sto"], s["fault_cause"],
          s["target_velocity"], s["objects"], s["profile"]};
}

// Something the page started goes on by itself: a pending result, a homing run. A request the page
// answers only once the drive did (an SDO write the drive refuses) lets the drive's cycles pass
// meanwhile, and what runs moves on in them (homing raises bit 4 when its turn comes): that is the
// earlier request's doing, not the refused one's.
bool under_way(const axis_page& inst) {
  const nlohmann::json s = nlohmann::json::parse(inst.snapshot_json());
  for (const auto& r : s["results"]) {
    if (r["outcome"] == "pending") return true;
  }
  return s["homing"].is_object() && s["homing"].value("running", false);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  axis_page inst(cia402::builtin_profile(data[0] % cia402::builtin_profile_count()), virtual_connection);
  for (int k = 0; k < 5; ++k) inst.step();
  for (std::size_t i = 1; i + 1 < size && i < 80; i += 2) {
    const std::uint8_t what = data[i];
    const std::uint8_t arg = data[i + 1];
    const nlohmann::json before = observable(inst);
    const bool busy = under_way(inst);
    reply r = accepted{};
    switch (what % 7) {
      case 0: r = inst.command(static_cast<page_command>(arg % 8)); break;
      case 1: r = inst.toggle_control_bit(static_cast<int>(arg) - 8); break;
      case 2: {
        constexpr std::uint16_t indices[] = {0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007,
                                             0x6083, 0x6040, 0x60FF, 0x1234};
        if (arg & 0x80) {  // by index and sub-index, from text (the parameter list's writes)
          const std::uint8_t sub = static_cast<std::uint8_t>(arg % 4);
          r = inst.write_entry(arg & 0x40 ? 0x6099 : 0x607D, sub, std::to_string((arg % 7) * 9999 - 20000));
          break;
        }
        r = inst.write_object(indices[arg % 10], static_cast<std::int8_t>(arg) * 37);
        break;
      }
      case 3: {
        plant_change c;
        if (arg & 1) c.target_velocity = static_cast<std::int64_t>(static_cast<std::int8_t>(arg)) << (arg % 40);
        if (arg & 2) c.fault = (arg & 4) != 0;
        c.fault_code = static_cast<std::uint16_t>(arg * 31);
        c.fault_class = static_cast<std::uint8_t>(arg % 6);
        if (arg & 8) c.dc_link = (arg & 16) != 0;
        if (arg & 32) c.sto = (arg & 64) != 0;
        r = inst.change_plant(c);
        break;
      }
      case 4: {
        const char* names[] = {"cia402", "s300-profibus", "nonesuch", ""};
        r = inst.select_profile(names[arg % 4]);
        break;
      }
      case 5: {
        // POST /api/homing (parameters, start, stop) and the drive's 0x1003 read and cleared.
        homing_request h;
        if (arg & 1) h.method = static_cast<std::int8_t>(arg) % 40;
        if (arg & 2) h.switch_speed = static_cast<std::int8_t>(arg) * 97;
        if (arg & 4) h.acceleration = arg % 3;
        if (arg & 8) h.start = (arg & 16) != 0;
        r = (arg & 96) == 32 ? inst.read_error_field() : (arg & 96) == 64 ? inst.clear_error_field() : inst.home(h);
        break;
      }
      default:
        for (int k = 0; k < arg % 64; ++k) inst.step();
        continue;
    }
    if (std::holds_alternative<refused>(r) && !busy && observable(inst) != before) std::abort();
    inst.step();
  }
  return 0;
}
