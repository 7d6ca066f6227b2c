// What a master does for a drive when its own client goes silent (an operator's page closed, a
// network lost, a controlling program killed): the drive is stopped as its abort connection option
// code 0x6007 says it stops when its master goes (CiA 402-2, object 0x6007: 0 no action, 1 fault
// signal, 2 Disable voltage, 3 Quick stop), as far as a master can command it. One decision for every master of the project (the
// axis session's lease, the instrument page's sign of life).
#pragma once

#include <cstdint>

namespace cia402 {

/// The stop a master commands for a silent client.
enum class lost_client_stop : std::uint8_t {
  disable_voltage,  ///< 0x6007 = 2: Disable voltage (the motor coasts, no torque)
  /// 0x6007 = 3: Quick stop, ended as 0x605A says; also 1 (a fault, which a master cannot raise)
  /// and a manufacturer-specific (negative) code
  quick_stop,
  /// 0x6007 = 0 (no action on the drive): halt (control bit 8, 0x605D) stops the shaft and keeps
  /// the drive enabled; a quick stop where the profile has no halt
  halt,
};

/// The stop for the drive's 0x6007 value; `profile_has_halt`: the profile supports 0x605D.
constexpr lost_client_stop stop_for_lost_client(int abort_connection, bool profile_has_halt) noexcept {
  if (abort_connection == 2) return lost_client_stop::disable_voltage;
  if (abort_connection == 0 && profile_has_halt) return lost_client_stop::halt;
  return lost_client_stop::quick_stop;
}

}  // namespace cia402
