// Channels by URL, as the `cia402 master --can URL` option takes them:
//   socketcand://HOST:PORT/BUS   a socketcand server's bus (e.g. socketcand://127.0.0.1:29536/can0)
//   socketcan://IFACE            a Linux SocketCAN interface (e.g. socketcan://vcan0)
// ("virtual", an in-process bus, is the CLI's own business: it needs the drives in the process.)
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "cia402/canopen/can/channel.hpp"

namespace cia402::canopen {

struct channel_url {
  enum class kind : std::uint8_t { socketcand, socketcan, virtual_bus } type = kind::virtual_bus;
  std::string host;
  std::uint16_t port = 29536;
  std::string bus = "can0";  ///< socketcand bus, or the SocketCAN interface
};

/// Parses a URL; false with a reason when it is not one of the forms above.
bool parse_channel_url(const std::string& url, channel_url& out, std::string& why);

/// Opens a socketcand or SocketCAN channel; nullptr with a reason on failure.
std::unique_ptr<channel> open_channel(const channel_url& url, std::string& why);

}  // namespace cia402::canopen
