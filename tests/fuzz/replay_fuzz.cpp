// `cia402 replay` lines: every output line is one valid JSON object, whatever the input bytes
// (non-UTF-8 included), and the drive's safety rules hold after every line.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "cia402/profile.hpp"
#include "cli/replay.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // The first byte picks the profile, the rest are lines.
  const cia402::profile& p = cia402::builtin_profile(data[0] % cia402::builtin_profile_count());
  cia402::cli::replay_session session(p);
  const auto valid = [](const std::string& line) {
    const auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object()) std::abort();
  };
  valid(session.power_up());
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  int number = 0;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string out = session.feed(text.substr(start, end - start), ++number);
    if (!out.empty()) valid(out);
    start = end + 1;
    if (number > 200) break;  // enough steps for one input
  }
  return 0;
}
