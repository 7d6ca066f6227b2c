#include "cli/replay.hpp"

#include <istream>
#include <ostream>

#include "cli/common.hpp"

namespace cia402::cli {

bool parse_option_write(std::string_view text, option_write& out, std::string& error) {
  const std::size_t eq = text.find('=');
  if (eq == std::string_view::npos) {
    error = "expected INDEX=VALUE, e.g. 0x605A=6";
    return false;
  }
  const auto index = parse_number(text.substr(0, eq));
  if (!index || *index < 0 || *index > 0xFFFF) {
    error = "index '" + std::string(text.substr(0, eq)) + "' is not a 16-bit object index";
    return false;
  }
  const auto value = parse_number(text.substr(eq + 1));
  if (!value || *value < INT32_MIN || *value > INT32_MAX) {
    error = "value '" + std::string(text.substr(eq + 1)) + "' is not a number";
    return false;
  }
  out.index = static_cast<std::uint16_t>(*index);
  out.value = static_cast<std::int32_t>(*value);
  return true;
}

int run_replay(const profile& p, const std::vector<option_write>& writes, std::istream& in,
               std::ostream& out, std::ostream& err) {
  replay_session session(p);
  for (const option_write& w : writes) {
    const sdo_abort result = session.write(w.index, w.value);
    if (result != sdo_abort::none) {
      err << "cia402 replay: --set " << hex(w.index, 4) << "=" << w.value << " refused by profile '"
          << p.name << "': SDO abort " << hex(static_cast<std::uint32_t>(result), 8) << " ("
          << sdo_abort_text(result) << ")\n";
      return 2;
    }
  }
  out << session.power_up() << "\n" << std::flush;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string result = session.feed(line, line_number);
    if (!result.empty()) out << result << "\n" << std::flush;
  }
  return 0;
}

}  // namespace cia402::cli
