#include "raw_ethercat_socket.hpp"

#include <arpa/inet.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "cia402/ethercat/esc/frame.hpp"

namespace cia402::apps::detail {

std::error_code open_raw_ethercat_socket(const std::string& interface, raw_socket& held) {
  const unsigned index = ::if_nametoindex(interface.c_str());
  if (index == 0) return {errno != 0 ? errno : ENODEV, std::generic_category()};
  const int fd = ::socket(AF_PACKET, SOCK_RAW | SOCK_CLOEXEC, htons(ethercat::ethertype));
  if (fd < 0) return {errno, std::generic_category()};
  sockaddr_ll address{};
  address.sll_family = AF_PACKET;
  address.sll_protocol = htons(ethercat::ethertype);
  address.sll_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const int e = errno;
    ::close(fd);
    return {e, std::generic_category()};
  }
  if (held.fd >= 0) ::close(held.fd);
  held.fd = fd;
  held.ifindex = static_cast<int>(index);
  return {};
}

bool send_raw_frame(const raw_socket& s, const std::vector<std::uint8_t>& frame) {
  if (s.fd < 0 || frame.size() < 6) return false;
  sockaddr_ll to{};
  to.sll_family = AF_PACKET;
  to.sll_protocol = htons(ethercat::ethertype);
  to.sll_ifindex = s.ifindex;
  to.sll_halen = 6;
  std::memcpy(to.sll_addr, frame.data(), 6);
  return ::sendto(s.fd, frame.data(), frame.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) >= 0;
}

}  // namespace cia402::apps::detail
