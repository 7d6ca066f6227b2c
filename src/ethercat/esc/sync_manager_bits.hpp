// A sync manager's status register bits (0x0805 + 8 n, ET1100 datasheet section II) the controller's
// sources share.
#pragma once

#include <cstdint>

namespace cia402::ethercat::detail {

/// Mailbox mode: the mailbox is full (written by one side, not yet read by the other).
inline constexpr std::uint8_t sm_status_mailbox_full = 1u << 3;

}  // namespace cia402::ethercat::detail
