#include <charconv>

#include "cia402/canopen/transport/channel_url.hpp"
#include "cia402/canopen/transport/socketcan.hpp"
#include "cia402/canopen/transport/socketcand.hpp"

namespace cia402::canopen {

bool parse_channel_url(const std::string& url, channel_url& out, std::string& why) {
  channel_url u;
  if (url == "virtual") {
    out = u;
    return true;
  }
  constexpr std::string_view tcp = "socketcand://";
  constexpr std::string_view can = "socketcan://";
  if (url.rfind(tcp, 0) == 0) {
    std::string_view rest = std::string_view(url).substr(tcp.size());
    const auto slash = rest.find('/');
    const std::string_view hostport = rest.substr(0, slash);
    if (slash != std::string_view::npos) u.bus = std::string(rest.substr(slash + 1));
    const auto colon = hostport.rfind(':');
    u.host = std::string(hostport.substr(0, colon));
    if (colon != std::string_view::npos) {
      const std::string_view p = hostport.substr(colon + 1);
      unsigned port = 0;
      const auto [end, ec] = std::from_chars(p.data(), p.data() + p.size(), port);
      if (ec != std::errc{} || end != p.data() + p.size() || port == 0 || port > 65535) {
        why = "port '" + std::string(p) + "' is not 1..65535";
        return false;
      }
      u.port = static_cast<std::uint16_t>(port);
    }
    if (u.host.empty() || u.bus.empty()) {
      why = "expected socketcand://HOST:PORT/BUS";
      return false;
    }
    u.type = channel_url::kind::socketcand;
    out = u;
    return true;
  }
  if (url.rfind(can, 0) == 0) {
    u.bus = url.substr(can.size());
    if (u.bus.empty()) {
      why = "expected socketcan://INTERFACE";
      return false;
    }
    u.type = channel_url::kind::socketcan;
    out = u;
    return true;
  }
  why = "'" + url + "' is not socketcand://HOST:PORT/BUS, socketcan://INTERFACE or virtual";
  return false;
}

std::unique_ptr<channel> open_channel(const channel_url& url, std::string& why) {
  std::error_code ec;
  switch (url.type) {
    case channel_url::kind::socketcand: {
      auto c = socketcand::client_channel::connect(url.host, url.port, url.bus, ec, why);
      return c;
    }
    case channel_url::kind::socketcan: {
      auto c = socketcan_channel::open(url.bus, ec);
      if (!c) why = "cannot open SocketCAN interface '" + url.bus + "': " + ec.message();
      return c;
    }
    case channel_url::kind::virtual_bus: break;
  }
  why = "the virtual bus has no channel to open here";
  return nullptr;
}

}  // namespace cia402::canopen
