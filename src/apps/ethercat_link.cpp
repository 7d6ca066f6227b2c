#include "cia402/apps/ethercat_link.hpp"

#include <linux/if_packet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <ctime>

#include "raw_ethercat_socket.hpp"

namespace cia402::apps {
namespace {

constexpr std::size_t first_index_at = ethercat::ethernet_header_size + ethercat::ethercat_header_size + 1;

}  // namespace

ethercat_link::ethercat_link(std::uint32_t answer_timeout_us)
    : answer_timeout_us_(answer_timeout_us), buffer_(ethercat::maximum_frame_size + 4) {}

ethercat_link::~ethercat_link() {
  if (socket_.fd >= 0) ::close(socket_.fd);
}

std::error_code ethercat_link::open(const std::string& interface) {
  return detail::open_raw_ethercat_socket(interface, socket_);
}

bool ethercat_link::exchange(std::vector<std::uint8_t>& frame) {
  if (socket_.fd < 0 || frame.size() <= first_index_at) return false;
  if (!detail::send_raw_frame(socket_, frame)) return false;
  const std::uint8_t index = frame[first_index_at];
  const std::uint64_t until = now_us() + answer_timeout_us_;
  for (;;) {
    const std::uint64_t now = now_us();
    if (now >= until) return false;
    pollfd p{socket_.fd, POLLIN, 0};
    const std::uint64_t left = until - now;
    const timespec wait{static_cast<time_t>(left / 1000000), static_cast<long>(left % 1000000) * 1000};
    if (::ppoll(&p, 1, &wait, nullptr) <= 0) continue;
    sockaddr_ll from{};
    socklen_t from_len = sizeof from;
    const ssize_t n = ::recvfrom(socket_.fd, buffer_.data(), buffer_.size(), MSG_DONTWAIT,
                                 reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n <= 0) continue;
    if (from.sll_pkttype == PACKET_OUTGOING) continue;  // our own frame, seen going out
    const auto size = static_cast<std::size_t>(n);
    if (size <= first_index_at || buffer_[first_index_at] != index) continue;  // a late answer
    frame.assign(buffer_.begin(), buffer_.begin() + static_cast<long>(size));
    return true;
  }
}

std::uint64_t ethercat_link::now_us() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(
                                        std::chrono::steady_clock::now().time_since_epoch())
                                        .count());
}

void ethercat_link::wait_us(std::uint32_t us) {
  const timespec t{static_cast<time_t>(us / 1000000), static_cast<long>(us % 1000000) * 1000};
  (void)::nanosleep(&t, nullptr);
}

}  // namespace cia402::apps
