#include "cia402/canopen/transport/socketcan.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace cia402::canopen {

std::unique_ptr<socketcan_channel> socketcan_channel::open(const std::string& interface,
                                                           std::error_code& ec) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    ec = std::make_error_code(std::errc::invalid_argument);
    return nullptr;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    ec = {errno, std::generic_category()};
    return nullptr;
  }
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, interface.c_str(), interface.size() + 1);
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
    ec = {errno, std::generic_category()};
    ::close(fd);
    return nullptr;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
    ec = {errno, std::generic_category()};
    ::close(fd);
    return nullptr;
  }
  ec.clear();
  return std::unique_ptr<socketcan_channel>(new socketcan_channel(fd));
}

socketcan_channel::~socketcan_channel() { ::close(fd_); }

std::error_code socketcan_channel::send(const frame& f) noexcept {
  if (f.len > 8) return std::make_error_code(std::errc::invalid_argument);
  can_frame cf{};
  cf.can_id = f.extended ? (f.id & CAN_EFF_MASK) | CAN_EFF_FLAG : (f.id & CAN_SFF_MASK);
  if (f.rtr) cf.can_id |= CAN_RTR_FLAG;
  cf.can_dlc = f.len;
  std::memcpy(cf.data, f.data.data(), 8);
  if (::write(fd_, &cf, sizeof cf) != static_cast<ssize_t>(sizeof cf)) {
    std::error_code ec{errno, std::generic_category()};
    if (errno != EAGAIN && errno != ENOBUFS) failure_ = ec;
    return ec;
  }
  return {};
}

bool socketcan_channel::receive(frame& f) noexcept {
  for (;;) {
    can_frame cf{};
    const ssize_t n = ::read(fd_, &cf, sizeof cf);
    if (n != static_cast<ssize_t>(sizeof cf)) {
      if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        failure_ = {errno, std::generic_category()};
      }
      return false;
    }
    if (cf.can_id & CAN_ERR_FLAG) continue;  // error frames are not CANopen traffic
    f = frame{};
    f.extended = (cf.can_id & CAN_EFF_FLAG) != 0;
    f.rtr = (cf.can_id & CAN_RTR_FLAG) != 0;
    f.id = cf.can_id & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    f.len = cf.can_dlc > 8 ? 8 : cf.can_dlc;
    std::memcpy(f.data.data(), cf.data, 8);
    return true;
  }
}

}  // namespace cia402::canopen
