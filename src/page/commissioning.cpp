#include "commissioning.hpp"

#include "cia402/error_codes.hpp"
#include "cia402/master.hpp"
#include "page_json.hpp"

namespace cia402::page::detail {

std::string enable_blocker(state shown, std::uint16_t error_code, bool sto, bool dc_link) {
  if (shown == state::fault || shown == state::fault_reaction_active) {
    return std::string(state_name(shown)) + ", error " + hex(error_code, 4) + " (" +
           error_code_text(error_code) +
           "): Enable does not reset a fault; remove its cause and press Fault reset first";
  }
  if (sto) return "STO asserted (safe torque off): release it first";
  if (!dc_link) return "no DC-link voltage: switch the power section on first";
  return "";
}

walk_step next_enable_step(const profile& p, const axis& options_from, state shown,
                           std::uint16_t control_word) {
  walk_step s;
  if (shown == state::operation_enabled) {
    s.there = true;
    return s;
  }
  const bool reset_bit = (control_word & control_bit::fault_reset) != 0;
  const command_path path =
      plan_path_from_status(p, options_from, shown, reset_bit, state::operation_enabled);
  if (!path.reachable || path.length == 0) {
    s.refusal = std::string("no command path from ") + state_name(shown) + " to OPERATION_ENABLED";
    return s;
  }
  const path_step& first = path.steps[0];
  s.word = static_cast<std::uint16_t>((control_word & ~owned_control_bits(p)) | first.control_word);
  s.after = first.after;
  s.transition = first.transition == no_transition ? -1 : int{first.transition};
  return s;
}

}  // namespace cia402::page::detail
