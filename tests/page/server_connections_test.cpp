// The page's HTTP server against clients that misbehave on the wire: chunked or oversized bodies,
// slow and endless request heads, and too many connections from one address. A raw TCP client
// sends what cpp-httplib's would never send.
#include <gtest/gtest.h>
#include <ifaddrs.h>
#include <unistd.h>
#include <sys/socket.h>
#include <poll.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <atomic>
#include <mutex>
#include <thread>

#include "page_server_fixture.hpp"

using cia402::page::testing::page_server;
using cia402::page::testing::token;
using cia402::page::testing::virtual_axis_page;
using cia402::page::server;
using cia402::page::server_options;
using json = nlohmann::json;

namespace {

// A raw TCP client: what a misbehaving one sends, byte for byte.
class raw_client {
 public:
  explicit raw_client(int port, const std::string& host = "127.0.0.1") {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    inet_pton(AF_INET, host.c_str(), &a.sin_addr);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~raw_client() { ::close(fd_); }
  bool connected() const { return connected_; }
  bool send(const std::string& s) {
    return ::send(fd_, s.data(), s.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(s.size());
  }
  /// What arrives within `ms`, until the server closes or a JSON answer's body ended.
  std::string receive(int ms) {
    std::string out;
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    char buf[4096];
    while (std::chrono::steady_clock::now() < end) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) break;
      out.append(buf, static_cast<std::size_t>(n));
      if (out.find("\r\n\r\n") != std::string::npos && out.back() == '}') break;
    }
    return out;
  }

 private:
  int fd_ = -1;
  bool connected_ = false;
};

// Memory stays bounded whatever a request claims: the head decides, before any body is read.
TEST_F(page_server, a_chunked_or_oversized_body_is_refused_on_its_head_without_reading_it) {
  start(false);
  const json before = observable();
  raw_client chunked(http->bound_port());
  ASSERT_TRUE(chunked.connected());
  ASSERT_TRUE(chunked.send("POST /api/command HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                           "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n"));
  // 4 MiB of chunks: refused before they are read, so sending may fail once the server closed.
  const std::string chunk = "100000\r\n" + std::string(0x100000, 'x') + "\r\n";
  for (int i = 0; i < 4 && chunked.send(chunk); ++i) {}
  const std::string answer = chunked.receive(2000);
  EXPECT_EQ(answer.rfind("HTTP/1.1 411", 0), 0u) << answer.substr(0, 200);

  raw_client big(http->bound_port());
  ASSERT_TRUE(big.send("POST /api/command HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                       "Content-Type: application/json\r\nContent-Length: 200000000\r\n\r\n"));
  const std::string answer2 = big.receive(2000);  // at once: the 200 MB never come
  EXPECT_EQ(answer2.rfind("HTTP/1.1 413", 0), 0u) << answer2.substr(0, 200);

  std::string many = "GET /api/state HTTP/1.1\r\nHost: 127.0.0.1\r\n";
  for (int i = 0; i < 100; ++i) many += "X-Filler-" + std::to_string(i) + ": 1\r\n";
  raw_client headers(http->bound_port());
  ASSERT_TRUE(headers.send(many + "\r\n"));
  const std::string answer3 = headers.receive(2000);
  EXPECT_EQ(answer3.rfind("HTTP/1.1 431", 0), 0u) << answer3.substr(0, 200);
  step(5);
  EXPECT_EQ(observable(), before);
}

// Forty clients that send a request line and then nothing hold a worker each for at most the
// read timeout; the page stays reachable meanwhile.
TEST_F(page_server, slow_clients_do_not_make_the_page_unreachable) {
  start(false);
  std::vector<std::unique_ptr<raw_client>> slow;
  for (int i = 0; i < 40; ++i) {
    slow.push_back(std::make_unique<raw_client>(http->bound_port()));
    ASSERT_TRUE(slow.back()->send("GET /api/state HTTP/1.1\r\nHost: 127.0.0.1\r\n"));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = client->Get("/api/state");
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_LT(ms, 1500) << "the page took " << ms << " ms behind 40 slow clients";
  // And the slow ones are let go after the read timeout (2 s), not kept for ever.
  EXPECT_EQ(slow[0]->receive(4000).find("200 OK"), std::string::npos);
}

}  // namespace

namespace {

// The guard reads nothing: a head that never ends, or ends too late, is answered before cpp-httplib
// would have read it (one GET with 40 MB of header lines used to be read whole and answered 200).
TEST_F(page_server, an_endless_or_slow_request_head_is_refused_before_it_is_read) {
  start(false);
  raw_client endless(http->bound_port());
  std::string lines = "GET /api/state HTTP/1.1\r\nHost: 127.0.0.1\r\n";
  while (lines.size() < 40000) lines += "X-A: 1\r\n";  // 5,000 short lines, no end of head
  ASSERT_TRUE(endless.send(lines));
  const std::string a = endless.receive(3000);
  EXPECT_EQ(a.rfind("HTTP/1.1 431", 0), 0u) << a.substr(0, 200);

  raw_client wide(http->bound_port());
  ASSERT_TRUE(wide.send("GET /api/state HTTP/1.1\r\nX-Big: " + std::string(20000, 'b')));
  const std::string b = wide.receive(3000);
  EXPECT_EQ(b.rfind("HTTP/1.1 431", 0), 0u) << b.substr(0, 200);

  // A header line every 300 ms: the head is not complete within the read timeout (2 s).
  raw_client slow(http->bound_port());
  ASSERT_TRUE(slow.send("GET /api/state HTTP/1.1\r\n"));
  const auto t0 = std::chrono::steady_clock::now();
  std::string c;
  for (int i = 0; i < 20 && c.empty(); ++i) {
    slow.send("X-Slow: 1\r\n");
    c = slow.receive(300);
  }
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(c.rfind("HTTP/1.1 408", 0), 0u) << c.substr(0, 200);
  EXPECT_LT(ms, 4000) << "the slow head was kept " << ms << " ms";
}

// Beyond loopback one client address may hold a bounded number of connections; on loopback all
// clients share one address (the page's own too), so none is counted there.
TEST(page_server_guard, connections_per_client_address_are_bounded_beyond_loopback) {
  std::string address;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) == 0) {
    for (ifaddrs* i = list; i != nullptr && address.empty(); i = i->ifa_next) {
      if (i->ifa_addr == nullptr || i->ifa_addr->sa_family != AF_INET) continue;
      char text[INET_ADDRSTRLEN] = {};
      inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(i->ifa_addr)->sin_addr, text, sizeof text);
      if (!cia402::page::is_loopback_address(text)) address = text;
    }
    ::freeifaddrs(list);
  }
  if (address.empty()) GTEST_SKIP() << "no IPv4 address beyond loopback on this machine";
  virtual_axis_page inst{cia402::standard_profile()};
  server_options o;
  o.bind = address;
  o.port = 0;
  o.token_required = true;
  o.token = token;
  o.max_connections_per_client = 3;
  server http(inst, o);
  ASSERT_TRUE(http.bind()) << http.error();
  http.start();
  const auto connect = [&] {
    auto c = std::make_unique<raw_client>(http.bound_port(), address);
    EXPECT_TRUE(c->connected());
    return c;
  };
  std::vector<std::unique_ptr<raw_client>> held;
  for (int i = 0; i < 3; ++i) {
    held.push_back(connect());
    ASSERT_TRUE(held.back()->send("GET /api/state HTTP/1.1\r\n"));  // and nothing more yet
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  auto fourth = connect();
  const std::string refused = fourth->receive(2000);
  EXPECT_EQ(refused.rfind("HTTP/1.1 503", 0), 0u) << refused.substr(0, 200);
  EXPECT_NE(refused.find("too many connections from " + address), std::string::npos);
  held.clear();  // their slots come back
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto fifth = connect();
  ASSERT_TRUE(fifth->send("GET /api/state HTTP/1.1\r\nHost: x\r\n\r\n"));
  const std::string ok = fifth->receive(2000);
  EXPECT_EQ(ok.rfind("HTTP/1.1 200", 0), 0u) << ok.substr(0, 200);
  http.stop();
}

}  // namespace
