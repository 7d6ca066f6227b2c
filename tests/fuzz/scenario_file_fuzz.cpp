// Scenario files: any bytes are refused with a reason or give a scenario; never a crash, a hang on
// a device or an exception out of the loader.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <variant>

#include "cia402/sim/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto r = cia402::sim::load_scenario_toml(text, "fuzz.toml", CIA402_FUZZ_DATA_DIR);
  if (const auto* e = std::get_if<cia402::sim::scenario_error>(&r)) {
    if (e->reason.empty()) std::abort();
  }
  return 0;
}
