#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

#include "cia402/canopen/transport/socketcand.hpp"

namespace cia402::canopen::socketcand {

struct server::client {
  int fd = -1;
  enum class mode : std::uint8_t { no_bus, bcm, raw } m = mode::no_bus;
  element_reader reader;
  std::unique_ptr<virtual_channel> ch;  // attached on open
  std::string out;
  std::uint64_t raw_since_us = 0;
  std::uint64_t since_us = 0;  // when it connected
  bool closing = false;  // close once `out` is written
  bool dead = false;
  explicit client(std::size_t max_line) : reader(max_line) {}
};

namespace {

std::error_code last_error() { return {errno, std::generic_category()}; }

void set_nonblocking(int fd) { ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL, 0) | O_NONBLOCK); }

// ACK what a client sent at once instead of delaying the ACK (up to 40 ms on Linux). A client
// without TCP_NODELAY (python-can 4.1's socketcand interface) holds its next small write until its
// last one is ACKed (Nagle), so an RPDO followed by a SYNC made the SYNC wait for the delayed ACK:
// cycles of 2..46 ms instead of a steady period. Linux leaves quick-ACK mode by itself, so it is
// armed again after every read.
void quick_ack(int fd) {
  const int yes = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_QUICKACK, &yes, sizeof yes);
}

}  // namespace

server::server(virtual_bus& bus, server_config config) : bus_(&bus), config_(std::move(config)) {}

server::~server() {
  for (auto& c : clients_) ::close(c->fd);
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

std::error_code server::open() {
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) return last_error();
  const int yes = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(config_.port);
  if (::inet_pton(AF_INET, config_.host.c_str(), &addr.sin_addr) != 1) {
    return std::make_error_code(std::errc::invalid_argument);
  }
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return last_error();
  // Room for a burst of connects: a full queue makes clients wait for SYN retries (1 s each).
  if (::listen(listen_fd_, SOMAXCONN) != 0) return last_error();
  socklen_t len = sizeof addr;
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  set_nonblocking(listen_fd_);
  return {};
}

void server::poll_sockets(int timeout_ms) {
  std::vector<pollfd> fds;
  fds.push_back({listen_fd_, POLLIN, 0});
  for (auto& c : clients_) {
    fds.push_back({c->fd, static_cast<short>(POLLIN | (c->out.empty() ? 0 : POLLOUT)), 0});
  }
  if (::poll(fds.data(), fds.size(), timeout_ms) <= 0) return;
  if (fds[0].revents & POLLIN) accept_clients();
  for (std::size_t i = 1; i < fds.size(); ++i) {
    client& c = *clients_[i - 1];
    if (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) read_client(c);
    if (!c.dead && (fds[i].revents & POLLOUT)) write_out(c);
  }
  clients_.erase(std::remove_if(clients_.begin(), clients_.end(), [](const auto& c) {
                   if (c->dead) ::close(c->fd);
                   return c->dead;
                 }),
                 clients_.end());
}

void server::accept_clients() {
  for (;;) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;
    const int yes = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
    quick_ack(fd);
    // A fixed send buffer (no autotuning) bounds what a client that does not read can hold.
    const int buffer = 65536;
    ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &buffer, sizeof buffer);
    if (clients_.size() >= config_.max_clients) {
      static constexpr char refusal[] = "< error too many clients >";
      (void)!::write(fd, refusal, sizeof refusal - 1);
      ++errors_sent_;
      ::close(fd);
      continue;
    }
    auto c = std::make_unique<client>(config_.max_line);
    c->fd = fd;
    c->since_us = now_us_;
    queue(*c, "< hi >");
    write_out(*c);
    clients_.push_back(std::move(c));
  }
}

void server::read_client(client& c) {
  char buf[4096];
  bool peer_gone = false;
  for (;;) {
    const ssize_t n = ::read(c.fd, buf, sizeof buf);
    if (n > 0) {
      c.reader.feed(std::string_view(buf, static_cast<std::size_t>(n)));
      if (static_cast<std::size_t>(n) < sizeof buf) break;
      continue;
    }
    // The peer closed (perhaps mid-transfer): what it sent before is still handled below, so a
    // client that writes and closes at once loses nothing.
    if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) peer_gone = true;
    break;
  }
  if (!peer_gone) quick_ack(c.fd);
  std::string element;
  for (;;) {
    const auto r = c.reader.next(element);
    if (r == element_reader::result::none || c.dead || c.closing) break;
    if (r == element_reader::result::too_long) {
      queue(c, "< error element longer than " + std::to_string(config_.max_line) + " characters >");
      ++errors_sent_;
      continue;
    }
    handle(c, element);
  }
  if (peer_gone) {
    drop(c);  // its nodes time out by themselves
    return;
  }
  if (!c.dead) write_out(c);
}

void server::advance(std::uint32_t elapsed_us) noexcept {
  now_us_ += elapsed_us;
  // A client that has not opened the bus within open_timeout_us holds a slot for nothing.
  for (auto& c : clients_) {
    if (!c->dead && c->m == client::mode::no_bus && now_us_ - c->since_us >= config_.open_timeout_us) {
      static constexpr char refusal[] = "< error no open within the time allowed >";
      (void)!::send(c->fd, refusal, sizeof refusal - 1, MSG_NOSIGNAL);
      ++errors_sent_;
      drop(*c);
    }
  }
}

void server::handle(client& c, std::string_view element) {
  const auto w = words(element);
  const auto error = [&](const std::string& why) {
    queue(c, "< error " + why + " >");
    ++errors_sent_;
  };
  if (w.empty()) return error("empty command");
  const std::string_view cmd = w[0];
  if (c.m == client::mode::no_bus) {
    if (cmd != "open") return error("open a bus first");
    if (w.size() != 2 || w[1] != config_.bus_name) {
      // socketcand answers an unknown bus with an error and closes the connection.
      error("could not open bus");
      c.closing = true;
      return;
    }
    c.ch = bus_->attach();
    c.m = client::mode::bcm;
    return queue(c, "< ok >");
  }
  if (cmd == "send") {
    frame f;
    std::string why;
    if (!parse_send(element, f, why)) return error("syntax error in send command: " + why);
    (void)c.ch->send(f);
    return;
  }
  if (cmd == "rawmode") {
    c.m = client::mode::raw;
    c.raw_since_us = now_us_;
    frame ignored;
    while (c.ch->receive(ignored)) {}  // raw mode starts now
    return queue(c, "< ok >");
  }
  if (cmd == "bcmmode") {
    c.m = client::mode::bcm;
    return queue(c, "< ok >");
  }
  if (cmd == "echo") return queue(c, "< echo >");
  if (cmd == "open") return error("bus already open");
  error("unknown command");
}

void server::queue(client& c, std::string_view text) { c.out.append(text); }

void server::write_out(client& c) {
  while (!c.out.empty() && !c.dead) {
    const ssize_t n = ::send(c.fd, c.out.data(), c.out.size(), MSG_NOSIGNAL);
    if (n > 0) {
      c.out.erase(0, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) break;
    drop(c);
    return;
  }
  if (c.out.empty() && c.closing) drop(c);
  // What the socket would not take stays queued; a client that does not read must not make the
  // server hold ever more for it.
  if (c.out.size() > config_.max_backlog) drop(c);
}

void server::drop(client& c) {
  c.dead = true;
  c.ch.reset();
  c.out.clear();
}

void server::flush() {
  frame f;
  for (auto& cp : clients_) {
    client& c = *cp;
    if (c.dead || !c.ch) continue;
    if (c.m != client::mode::raw) {
      while (c.ch->receive(f)) {}  // not in raw mode: frames pass it by
      continue;
    }
    if (now_us_ - c.raw_since_us < config_.join_grace_us) continue;  // held on its channel
    while (c.ch->receive(f)) {
      c.out.push_back('\n');
      queue(c, format_frame(f, now_us_));
    }
    if (!c.out.empty()) write_out(c);
  }
  clients_.erase(std::remove_if(clients_.begin(), clients_.end(), [](const auto& c) {
                   if (c->dead) ::close(c->fd);
                   return c->dead;
                 }),
                 clients_.end());
}

}  // namespace cia402::canopen::socketcand
