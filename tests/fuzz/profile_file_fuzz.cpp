// Profile files: any bytes are refused with a reason or give a profile that passes check_profile and
// writes back to a file that loads to the same text (the round trip a user relies on).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <variant>

#include "cia402/profile.hpp"
#include "cia402/profile_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const cia402::profile_load_result r = cia402::load_profile_toml(text, "fuzz.toml");
  if (const auto* e = std::get_if<cia402::profile_file_error>(&r)) {
    if (e->reason.empty()) std::abort();  // a refusal always says why
    return 0;
  }
  const cia402::profile& p = std::get<cia402::custom_profile>(r).get();
  int row = -1;
  if (cia402::check_profile(p, row) != nullptr) std::abort();
  const std::string written = cia402::dump_profile_toml(p);
  const cia402::profile_load_result again = cia402::load_profile_toml(written, "again.toml");
  if (!std::holds_alternative<cia402::custom_profile>(again)) std::abort();
  if (cia402::dump_profile_toml(std::get<cia402::custom_profile>(again).get()) != written) std::abort();
  return 0;
}
