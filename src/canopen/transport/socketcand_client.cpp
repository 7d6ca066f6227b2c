#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>

#include "cia402/canopen/transport/socketcand.hpp"

namespace cia402::canopen::socketcand {
namespace {

std::error_code last_error() { return {errno, std::generic_category()}; }

// Reads until one complete element arrives or the deadline passes (handshake only).
bool read_element(int fd, element_reader& reader, std::string& element, int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    if (reader.next(element) == element_reader::result::element) return true;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
    char buf[512];
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) return false;
    reader.feed(std::string_view(buf, static_cast<std::size_t>(n)));
  }
}

bool write_all(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::send(fd, text.data() + done, text.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

std::unique_ptr<client_channel> client_channel::connect(const std::string& host, std::uint16_t port,
                                                        const std::string& bus, std::error_code& ec,
                                                        std::string& why, int timeout_ms) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 || !found) {
    ec = std::make_error_code(std::errc::host_unreachable);
    why = "cannot resolve host '" + host + "'";
    return nullptr;
  }
  int fd = -1;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd >= 0 && ::connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
      ec = last_error();
      ::close(fd);
      fd = -1;
    }
  }
  ::freeaddrinfo(found);
  if (fd < 0) {
    why = "cannot connect to " + host + ":" + std::to_string(port) + ": " + ec.message();
    return nullptr;
  }
  const int yes = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
  std::unique_ptr<client_channel> c(new client_channel(fd));
  std::string element;
  const auto expect = [&](const char* what, const char* step) {
    if (!read_element(fd, c->reader_, element, timeout_ms)) {
      ec = std::make_error_code(std::errc::timed_out);
      why = std::string("no answer to ") + step;
      return false;
    }
    if (element != what) {
      ec = std::make_error_code(std::errc::protocol_error);
      why = std::string(step) + " answered '" + element + "'";
      return false;
    }
    return true;
  };
  if (!expect("< hi >", "the greeting")) return nullptr;
  if (!write_all(fd, "< open " + bus + " >") || !expect("< ok >", "< open >")) {
    // A server that refuses the bus says "< error could not open bus >": say it in words.
    if (element.rfind("< error", 0) == 0) {
      why = "the socketcand server at " + host + ":" + std::to_string(port) + " has no bus '" + bus +
            "'";
    }
    return nullptr;
  }
  if (!write_all(fd, "< rawmode >") || !expect("< ok >", "< rawmode >")) return nullptr;
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL, 0) | O_NONBLOCK);
  ec.clear();
  return c;
}

client_channel::~client_channel() {
  if (fd_ >= 0) ::close(fd_);
}

void client_channel::pump() noexcept {
  if (failure_) return;
  if (!out_.empty()) {
    const ssize_t n = ::send(fd_, out_.data(), out_.size(), MSG_NOSIGNAL);
    if (n > 0) {
      out_.erase(0, static_cast<std::size_t>(n));
    } else if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      failure_ = last_error();
      return;
    }
  }
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n > 0) {
      reader_.feed(std::string_view(buf, static_cast<std::size_t>(n)));
      continue;
    }
    if (n == 0) failure_ = std::make_error_code(std::errc::connection_reset);
    else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) failure_ = last_error();
    break;
  }
  std::string element;
  for (;;) {
    const auto r = reader_.next(element);
    if (r == element_reader::result::none) break;
    if (r == element_reader::result::too_long) continue;
    frame f;
    std::string why;
    if (element.rfind("< frame ", 0) == 0 && parse_frame(element, f, why)) {
      frames_.push_back(f);
    } else if (notices_.size() < 100) {
      notices_.push_back(element);
    }
  }
}

std::error_code client_channel::send(const frame& f) noexcept {
  if (failure_) return failure_;
  out_.append(format_send(f));
  pump();
  return failure_;
}

bool client_channel::receive(frame& f) noexcept {
  if (frames_.empty()) pump();
  if (frames_.empty()) return false;
  f = frames_.front();
  frames_.pop_front();
  return true;
}

}  // namespace cia402::canopen::socketcand
