// Uses cia402::profile_file, when the package has it: its link to toml++ must come along through
// find_package(cia402). Writes the standard profile as TOML and loads it back.
#include <cstdio>
#include <variant>

#include "cia402/profile_file.hpp"

int main() {
  const auto text = cia402::dump_profile_toml(cia402::standard_profile());
  const auto loaded = cia402::load_profile_toml(text, "standard.toml");
  if (const auto* error = std::get_if<cia402::profile_file_error>(&loaded)) {
    std::printf("%s\n", error->message().c_str());
    return 1;
  }
  const cia402::profile& p = std::get<cia402::custom_profile>(loaded);
  std::printf("loaded %s: %d rows\n", p.name, p.row_count);
  return p.row_count == cia402::standard_profile().row_count ? 0 : 1;
}
