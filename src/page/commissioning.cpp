#include "commissioning.hpp"

#include "cia402/error_codes.hpp"
#include "page_json.hpp"

namespace cia402::page::detail {

std::string enable_blocker(state shown, std::uint16_t error_code, bool sto, bool dc_link, bool remote) {
  if (shown == state::fault || shown == state::fault_reaction_active) {
    return std::string(state_name(shown)) + ", error " + hex(error_code, 4) + " (" +
           error_code_text(error_code) +
           "): Enable does not reset a fault; remove its cause and press Fault reset first";
  }
  if (sto) return "STO asserted (safe torque off): release it first";
  if (!dc_link) return "no DC-link voltage: switch the power section on first";
  if (!remote) return "local control (status word bit 9, remote, is off): the drive does not take the control word";
  return "";
}

}  // namespace cia402::page::detail
