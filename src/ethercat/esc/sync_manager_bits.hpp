// A sync manager's register bits (0x0805..0x0807 + 8 n, ET1100 datasheet section II) and the AL event
// bit they raise, which the controller's sources share.
#pragma once

#include <cstdint>

namespace cia402::ethercat::detail {

/// Mailbox mode: the mailbox is full (written by one side, not yet read by the other).
inline constexpr std::uint8_t sm_status_mailbox_full = 1u << 3;
/// Activate register: the master's repeat request; PDI control: the application's repeat acknowledge.
inline constexpr std::uint8_t sm_repeat = 1u << 1;
/// AL event request (0x0220) bit 4: the master wrote a sync manager's activate register.
inline constexpr std::uint8_t al_event_sm_activation = 1u << 4;

}  // namespace cia402::ethercat::detail
