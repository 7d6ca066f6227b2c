// The socketcand protocol (linux-can/socketcand, doc/protocol.md): CAN over TCP as ASCII elements
// "< ... >". A server that is a virtual CAN bus any socketcand client joins (python-can's
// `socketcand` interface, a real socketcand client, our own), and a client channel that joins a
// socketcand daemon. POSIX sockets and poll(), one thread; nothing blocks once connected.
//
// Session: the server greets "< hi >"; the client sends "< open BUS >" (answer "< ok >", or
// "< error ... >" and the connection closes); then "< rawmode >" ("< ok >"), after which every frame
// on the bus but the client's own arrives as "< frame ID SECS.USECS DATA >", DATA as contiguous hex
// ("< frame 123 1.000000  >" with no data, two spaces, as socketcand prints it). "< send ID LEN B0 B1 ...
// >" puts a frame on the bus (after open, in BCM or raw mode). "< echo >" is echoed.
//
// Bad input gets "< error REASON >" and changes nothing: an unknown command, a malformed send, an
// element longer than the line limit (the rest up to its '>' is skipped), a 17th client (closed at
// once). A client that stops reading is dropped when its unsent output passes the backlog limit, so
// it cannot hold up the bus for the others.
//
// Two details for python-can 4.1's client, which compares whole recv() results with "< hi >" and
// "< ok >", and drops the character after the last element of each recv() it parses (so without a
// separator it would cut the '<' off a frame split between two reads): each frame element is
// preceded by one newline, and the frames that arrive in the first `join_grace_us` after a client's
// rawmode "< ok >" are held on its channel (up to the channel's capacity) and sent after it, so that
// "< ok >" reaches the client alone. And since that client does not set TCP_NODELAY, its second small
// write (a SYNC after an RPDO) waits until the first is ACKed: the server ACKs at once
// (TCP_QUICKACK, armed again after every read) instead of delaying its ACK by up to 40 ms.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "cia402/canopen/can/channel.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"

namespace cia402::canopen::socketcand {

/// Splits a byte stream into "< ... >" elements. Bytes outside elements are skipped.
class element_reader {
 public:
  explicit element_reader(std::size_t max_length = 256) : max_(max_length) {}
  void feed(std::string_view bytes) { pending_.append(bytes); }
  enum class result : std::uint8_t { none, element, too_long };
  /// The next complete element (with its brackets), or too_long once per oversized element.
  result next(std::string& element);

 private:
  std::size_t max_;
  std::string pending_;
  std::string current_;
  bool inside_ = false;
  bool skipping_ = false;
};

/// The words of an element without its brackets: "< send 123 1 AB >" -> {"send","123","1","AB"}.
std::vector<std::string_view> words(std::string_view element);

/// "< frame 123 12.000345 0102 >" (no trailing newline).
std::string format_frame(const frame& f, std::uint64_t time_us);
/// "< send 123 2 01 02 >".
std::string format_send(const frame& f);
/// Parses "< send ID LEN DATA... >": ID hex (8 digits = 29-bit), LEN 0..8, LEN data bytes in hex.
bool parse_send(std::string_view element, frame& out, std::string& why);
/// Parses "< frame ID SECS.USECS DATA >" with DATA contiguous hex (or bytes separated by spaces).
bool parse_frame(std::string_view element, frame& out, std::string& why);

struct server_config {
  std::string host = "127.0.0.1";
  std::uint16_t port = 29536;      ///< 0 = any free port (see server::port())
  std::string bus_name = "can0";
  std::size_t max_clients = 16;
  std::size_t max_line = 256;
  std::size_t max_backlog = 1u << 20;  ///< bytes of unsent output before a client is dropped
  std::uint32_t join_grace_us = 100000;
  /// A client must `open` the bus within this time (bus time, advance()) or it is dropped, so
  /// idle connections cannot hold every slot.
  std::uint64_t open_timeout_us = 10000000;
};

/// A virtual CAN bus served over TCP. Every client is a channel on `bus`, so it sees every other
/// client's frames and those of the nodes on the bus.
class server {
 public:
  server(virtual_bus& bus, server_config config);
  ~server();
  server(const server&) = delete;
  server& operator=(const server&) = delete;

  /// Binds and listens. Fails with the socket error (e.g. address in use).
  std::error_code open();
  std::uint16_t port() const noexcept { return port_; }

  /// Waits up to `timeout_ms` for sockets, then accepts and reads whatever is ready; frames the
  /// clients send go onto the bus at once.
  void poll_sockets(int timeout_ms);
  /// Advances the time stamped on frames, the join grace and the open timeout.
  void advance(std::uint32_t elapsed_us) noexcept;
  /// Writes the bus's frames to the clients in raw mode (call after the nodes ran).
  void flush();

  std::size_t clients() const noexcept { return clients_.size(); }
  /// Errors sent to clients so far, for tests and logs.
  std::uint64_t errors_sent() const noexcept { return errors_sent_; }

 private:
  struct client;
  void accept_clients();
  void read_client(client& c);
  void handle(client& c, std::string_view element);
  void queue(client& c, std::string_view text);
  void write_out(client& c);
  void drop(client& c);

  virtual_bus* bus_;
  server_config config_;
  int listen_fd_ = -1;
  std::uint16_t port_ = 0;
  std::uint64_t now_us_ = 0;
  std::uint64_t errors_sent_ = 0;
  std::vector<std::unique_ptr<client>> clients_;
};

/// A channel that joins a socketcand server's bus in raw mode.
class client_channel final : public channel {
 public:
  /// Connects, greets, opens `bus` and enters raw mode, waiting at most `timeout_ms` in all.
  static std::unique_ptr<client_channel> connect(const std::string& host, std::uint16_t port,
                                                 const std::string& bus, std::error_code& ec,
                                                 std::string& why, int timeout_ms = 3000);
  ~client_channel() override;

  std::error_code send(const frame& f) noexcept override;
  bool receive(frame& f) noexcept override;
  int native_handle() const noexcept override { return fd_; }
  std::error_code failure() const noexcept override { return failure_; }
  /// Elements from the server that were neither frames nor expected (e.g. "< error ... >").
  const std::vector<std::string>& notices() const noexcept { return notices_; }

 private:
  explicit client_channel(int fd) : fd_(fd) {}
  void pump() noexcept;

  int fd_;
  element_reader reader_{4096};
  std::deque<frame> frames_;
  std::string out_;
  std::error_code failure_;
  std::vector<std::string> notices_;
};

}  // namespace cia402::canopen::socketcand
