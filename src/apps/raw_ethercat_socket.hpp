// The raw socket both ends of an EtherCAT line use here (the slaves' host and our master's link):
// AF_PACKET, EtherType 0x88A4, bound to one interface. Linux; needs CAP_NET_RAW (root).
#pragma once

#include <cstdint>
#include <string>
#include <system_error>
#include <vector>

#include "cia402/apps/raw_socket.hpp"

namespace cia402::apps::detail {

/// Opens and binds the socket on `interface`; on success `held` is closed and then holds the new one
/// (the caller closes it), on failure `held` is as it was.
std::error_code open_raw_ethercat_socket(const std::string& interface, raw_socket& held);
/// Sends a whole frame out of the interface, to the destination its first six bytes name.
bool send_raw_frame(const raw_socket& s, const std::vector<std::uint8_t>& frame);

}  // namespace cia402::apps::detail
