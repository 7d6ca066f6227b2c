#include "cli/path.hpp"

#include <iomanip>
#include <ostream>

#include "cia402/master.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

std::string describe_word(const profile& p, std::uint16_t word) {
  std::string text = command_name(p.decode(word));
  if (word & control_bit::fault_reset) text = "FAULT_RESET + " + text;
  return text;
}

}  // namespace

int run_path(const profile& p, const std::vector<option_write>& writes, const std::string& from,
             const std::string& to, std::ostream& out, std::ostream& err) {
  state start;
  state target;
  const auto unknown = [&](const std::string& name) {
    err << "cia402 path: unknown state '" << name << "'; the states are";
    for (int i = 1; i < state_count; ++i) {
      const auto s = static_cast<state>(i);
      err << (i == 1 ? " " : ", ") << state_name(s) << " (" << state_abbreviation(s) << ")";
    }
    err << "\n";
    return 2;
  };
  if (!parse_state(from, start) || start == state::start) return unknown(std::string(from));
  if (!parse_state(to, target) || target == state::start) return unknown(std::string(to));
  axis options = make_axis(p);
  for (const option_write& w : writes) {
    const sdo_abort abort = write_option(p, options, w.index, w.value);
    if (abort != sdo_abort::none) {
      err << "cia402 path: --set " << hex(w.index, 4) << "=" << w.value << " refused: SDO abort "
          << hex(static_cast<std::uint32_t>(abort), 8) << " (" << sdo_abort_text(abort) << ")\n";
      return 2;
    }
  }
  const command_path path = plan_path_from_status(p, options, start, false, target);
  out << p.name << ": " << state_name(start) << " -> " << state_name(target);
  if (!path.reachable) {
    out << ": unreachable by any sequence of commands\n";
    return 1;
  }
  out << " in " << int{path.length} << (path.length == 1 ? " cycle\n" : " cycles\n");
  for (int k = 0; k < path.length; ++k) {
    const path_step& s = path.steps[static_cast<std::size_t>(k)];
    const std::string cmd = describe_word(p, s.control_word);
    out << "  cycle " << std::setw(2) << k + 1 << "  cw " << hex(s.control_word, 4) << "  "
        << std::left << std::setw(32) << cmd << "  " << std::setw(4)
        << (s.transition == no_transition ? std::string("-")
                                          : "T" + std::to_string(s.transition))
        << std::right << "  -> " << state_name(s.after) << "\n";
  }
  return 0;
}

}  // namespace cia402::cli
