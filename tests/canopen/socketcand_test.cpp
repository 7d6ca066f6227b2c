// socketcand over loopback TCP (free port): the protocol as python-can and socketcand speak it, bad
// input, limits, and the drive master (carrying the test's words) joining the virtual bus through
// our own socketcand client. The axis session over socketcand: session_over_can_test.cpp.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>
#include <atomic>
#include <thread>
#include <string>
#include <vector>

#include "cia402/apps/bus_host.hpp"
#include "cia402/canopen/master/drive_master.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/transport/socketcand.hpp"
#include "carried_words.hpp"

namespace cia402::canopen {
namespace {

using socketcand::element_reader;

TEST(socketcand_protocol, frames_format_as_socketcand_prints_them) {
  EXPECT_EQ(socketcand::format_frame(make_frame(0x181, {0x37, 0x02}), 12000345),
            "< frame 181 12.000345 3702 >");
  EXPECT_EQ(socketcand::format_frame(make_frame(0x080, {}), 1000000), "< frame 080 1.000000  >");
  frame ext = make_frame(0x1AAAAAAA, {1});
  ext.extended = true;
  EXPECT_EQ(socketcand::format_frame(ext, 0), "< frame 1AAAAAAA 0.000000 01 >");
  EXPECT_EQ(socketcand::format_send(make_frame(0x601, {0x40, 0x00, 0x10})), "< send 601 3 40 00 10 >");
}

TEST(socketcand_protocol, send_parses_python_can_style_lower_case_unpadded_bytes) {
  frame f;
  std::string why;
  ASSERT_TRUE(socketcand::parse_send("< send 605 8 40 0 10 0 0 0 0 0 >", f, why)) << why;
  EXPECT_EQ(f.id, 0x605u);
  EXPECT_EQ(f.len, 8);
  EXPECT_EQ(f.data[2], 0x10);
  ASSERT_TRUE(socketcand::parse_send("< send 0 2 1 a >", f, why)) << why;
  EXPECT_EQ(f.data[1], 0x0A);
  ASSERT_TRUE(socketcand::parse_send("< send 1AAAAAAA 2 1 F1 >", f, why)) << why;
  EXPECT_TRUE(f.extended);
  ASSERT_TRUE(socketcand::parse_send("< send 123 0  >", f, why)) << why;
  EXPECT_EQ(f.len, 0);
}

TEST(socketcand_protocol, malformed_send_is_refused_with_a_reason) {
  frame f;
  std::string why;
  EXPECT_FALSE(socketcand::parse_send("< send 12G 1 00 >", f, why));
  EXPECT_FALSE(socketcand::parse_send("< send 123 9 0 0 0 0 0 0 0 0 0 >", f, why));
  EXPECT_FALSE(socketcand::parse_send("< send 123 2 01 >", f, why));
  EXPECT_NE(why.find("length 2 but 1"), std::string::npos);
  EXPECT_FALSE(socketcand::parse_send("< send 123 1 100 >", f, why));
  EXPECT_FALSE(socketcand::parse_send("< send 123456789 0 >", f, why));
  EXPECT_FALSE(socketcand::parse_send("< send >", f, why));
}

TEST(socketcand_protocol, reader_splits_elements_skips_noise_and_flags_overlong_ones) {
  element_reader r(16);
  r.feed("junk< hi >\n< o");
  std::string e;
  ASSERT_EQ(r.next(e), element_reader::result::element);
  EXPECT_EQ(e, "< hi >");
  EXPECT_EQ(r.next(e), element_reader::result::none);
  r.feed("k >< 0123456789abcdefghij >< echo >");
  ASSERT_EQ(r.next(e), element_reader::result::element);
  EXPECT_EQ(e, "< ok >");
  EXPECT_EQ(r.next(e), element_reader::result::too_long);
  ASSERT_EQ(r.next(e), element_reader::result::element);
  EXPECT_EQ(e, "< echo >");
}

// A raw TCP peer: what a socketcand client sends and receives, byte for byte.
class tcp_peer {
 public:
  explicit tcp_peer(std::uint16_t port, int receive_buffer = 0) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    if (receive_buffer != 0) {
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    }
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~tcp_peer() { close(); }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  bool connected() const { return connected_; }
  void send(const std::string& s) { ASSERT_EQ(::send(fd_, s.data(), s.size(), MSG_NOSIGNAL), static_cast<ssize_t>(s.size())); }
  /// Everything readable now; sets `closed` on EOF.
  std::string take() {
    std::string out;
    char buf[4096];
    for (;;) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 0) <= 0) break;
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) {
        closed = true;
        break;
      }
      out.append(buf, static_cast<std::size_t>(n));
    }
    return out;
  }
  bool closed = false;

 private:
  int fd_ = -1;
  bool connected_ = false;
};

class socketcand_server_test : public ::testing::Test {
 protected:
  void SetUp() override { start({}); }
  void start(socketcand::server_config cfg) {
    cfg.port = 0;
    if (cfg.join_grace_us == socketcand::server_config{}.join_grace_us) cfg.join_grace_us = 0;
    host.restart_server(cfg);
    srv = &host.server();
    ASSERT_FALSE(host.open());
    ASSERT_NE(srv->port(), 0);
  }
  void add_drive(std::uint8_t id) {
    host.add_drive(standard_profile(), apps::drive_node_config(id));
  }
  /// One cycle of the server loop: sockets, time, nodes, output.
  void spin(int cycles = 1, std::uint32_t us = 1000) {
    for (int i = 0; i < cycles; ++i) (void)host.cycle(us, 0);
  }
  /// Runs the server loop (waiting on its sockets) until `done`: for a client whose connect()
  /// blocks in the test's own thread.
  void serve_until(const std::atomic<bool>& done) {
    while (!done) (void)host.cycle(1000, 5);
  }
  /// Our client channel joined to the server on `bus` (null, with `ec` and `why`, when it could
  /// not). Its connect() blocks for the handshake, so the server loop runs on a thread of its own
  /// meanwhile.
  std::unique_ptr<socketcand::client_channel> connect_client(std::string& why, std::error_code& ec,
                                                             const std::string& bus = "can0") {
    std::atomic<bool> connected{false};
    std::thread server_loop([&] { serve_until(connected); });
    auto ch = socketcand::client_channel::connect("127.0.0.1", srv->port(), bus, ec, why, 3000);
    connected = true;
    server_loop.join();
    return ch;
  }
  /// A peer that has joined in raw mode.
  std::unique_ptr<tcp_peer> join(int receive_buffer = 0) {
    auto p = std::make_unique<tcp_peer>(srv->port(), receive_buffer);
    spin();
    EXPECT_EQ(p->take(), "< hi >");
    p->send("< open can0 >");
    spin();
    EXPECT_EQ(p->take(), "< ok >");
    p->send("< rawmode >");
    spin();
    EXPECT_EQ(p->take(), "< ok >");
    return p;
  }

  apps::bus_host host{socketcand::server_config{}};
  std::vector<std::unique_ptr<apps::virtual_drive_node>>& drives = host.drives();
  socketcand::server* srv = nullptr;
};

TEST_F(socketcand_server_test, handshake_answers_exactly_hi_ok_ok) {
  auto p = join();
  EXPECT_EQ(srv->clients(), 1u);
}

TEST_F(socketcand_server_test, unknown_bus_gets_an_error_and_the_connection_closes) {
  tcp_peer p(srv->port());
  spin();
  EXPECT_EQ(p.take(), "< hi >");
  p.send("< open can7 >");
  spin(3);
  EXPECT_EQ(p.take(), "< error could not open bus >");
  EXPECT_TRUE(p.closed || (spin(2), p.take(), p.closed));
  EXPECT_EQ(srv->clients(), 0u);
}

TEST_F(socketcand_server_test, frames_reach_every_other_client_but_not_the_sender) {
  auto a = join();
  auto b = join();
  a->send("< send 123 2 ab 1 >");
  spin();
  const std::string got = b->take();
  EXPECT_EQ(got.substr(0, 13), "\n< frame 123 ");
  EXPECT_EQ(got.substr(got.size() - 7), " AB01 >") << got;
  EXPECT_EQ(a->take(), "");
}

TEST_F(socketcand_server_test, bad_input_gets_errors_and_the_session_goes_on) {
  auto a = join();
  auto b = join();
  a->send("< launch rockets >< send 123 2 01 >< send 1x3 0 >< " + std::string(300, 'x') + " >");
  spin();
  const std::string errors = a->take();
  EXPECT_NE(errors.find("< error unknown command >"), std::string::npos) << errors;
  EXPECT_NE(errors.find("< error syntax error in send command: length 2 but 1 data bytes >"),
            std::string::npos) << errors;
  EXPECT_NE(errors.find("identifier '1x3' is not hexadecimal"), std::string::npos) << errors;
  EXPECT_NE(errors.find("< error element longer than 256 characters >"), std::string::npos) << errors;
  EXPECT_EQ(b->take(), "") << "nothing bad reached the bus";
  a->send("< echo >< send 7E5 1 4 >");
  spin();
  EXPECT_EQ(a->take(), "< echo >");
  EXPECT_EQ(b->take().substr(0, 15), "\n< frame 7E5 0.");
}

TEST_F(socketcand_server_test, commands_before_open_are_refused) {
  tcp_peer p(srv->port());
  spin();
  p.take();
  p.send("< send 123 0 >< rawmode >");
  spin();
  EXPECT_EQ(p.take(), "< error open a bus first >< error open a bus first >");
}

TEST_F(socketcand_server_test, seventeenth_client_is_refused_and_the_others_go_on) {
  std::vector<std::unique_ptr<tcp_peer>> peers;
  for (int i = 0; i < 16; ++i) peers.push_back(join());
  tcp_peer extra(srv->port());
  spin(2);
  EXPECT_EQ(extra.take(), "< error too many clients >");
  EXPECT_EQ(srv->clients(), 16u);
  peers[0]->send("< send 100 0 >");
  spin();
  EXPECT_FALSE(peers[15]->take().empty());
}

// A client that writes and closes at once: every frame it sent reaches the bus, whatever the
// number of bytes (exactly 4,096 and 8,192 were the sizes that lost frames: the read that filled
// the buffer was followed by EOF, and the connection was dropped before its bytes were handled).
TEST_F(socketcand_server_test, frames_sent_together_with_a_close_all_reach_the_bus) {
  for (const std::size_t total : {4095u, 4096u, 4097u, 8192u}) {
    auto listener = join();
    auto sender = join();
    // "< send 123 1 00 >" is 17 bytes; pad the first element with spaces to hit `total` exactly.
    const std::string element = "< send 123 1 00 >";
    const std::size_t count = total / element.size();
    std::string burst(total - count * element.size(), ' ');
    for (std::size_t i = 0; i < count; ++i) burst += element;
    ASSERT_EQ(burst.size(), total);
    sender->send(burst);
    sender->close();
    std::string got;
    for (int i = 0; i < 20; ++i) {
      spin();
      got += listener->take();
    }
    std::size_t frames = 0;
    for (std::size_t at = got.find("< frame 123 "); at != std::string::npos;
         at = got.find("< frame 123 ", at + 1)) {
      ++frames;
    }
    EXPECT_EQ(frames, count) << total << " bytes";
    listener->close();
    spin(2);
  }
}

// Connections that never open the bus are dropped after open_timeout_us, so they cannot hold
// every slot; a client that opened stays however quiet it is.
TEST_F(socketcand_server_test, a_client_that_never_opens_the_bus_is_dropped_after_the_timeout) {
  socketcand::server_config cfg;
  cfg.open_timeout_us = 50000;
  start(cfg);
  auto quiet_but_open = join();
  std::vector<std::unique_ptr<tcp_peer>> idle;
  for (int i = 0; i < 15; ++i) {
    idle.push_back(std::make_unique<tcp_peer>(srv->port()));
    spin();
  }
  EXPECT_EQ(srv->clients(), 16u);
  spin(60);  // 60 ms of bus time
  EXPECT_EQ(srv->clients(), 1u);
  EXPECT_NE(idle[0]->take().find("< error no open within the time allowed >"), std::string::npos);
  auto newcomer = join();  // a slot is free again
  EXPECT_EQ(srv->clients(), 2u);
}

TEST_F(socketcand_server_test, client_that_never_reads_is_dropped_without_stalling_the_others) {
  socketcand::server_config cfg;
  cfg.max_backlog = 8192;
  start(cfg);
  auto lazy = join(4096);
  auto busy = join();
  auto reader = join();
  // Fill the lazy client's socket buffers and backlog; the reader keeps up.
  std::size_t seen = 0;
  for (int i = 0; i < 20000 && srv->clients() == 3; ++i) {
    busy->send("< send 100 8 1 2 3 4 5 6 7 8 >");
    spin();
    seen += reader->take().size();
  }
  EXPECT_EQ(srv->clients(), 2u) << "the lazy client was dropped";
  EXPECT_FALSE(reader->closed);
  busy->take();
  EXPECT_FALSE(busy->closed);
  busy->send("< send 101 0 >");
  std::string last;
  for (int i = 0; i < 200 && last.find("< frame 101 ") == std::string::npos; ++i) {
    spin();
    last += reader->take();
    if (last.find("< frame 101 ") == std::string::npos) ::usleep(1000);  // Nagle on the sender
  }
  EXPECT_NE(last.find("< frame 101 "), std::string::npos);
  EXPECT_GT(seen, 0u);
}

TEST_F(socketcand_server_test, client_leaving_mid_sdo_transfer_leaves_the_node_usable) {
  add_drive(4);
  auto a = join();
  auto b = join();
  a->send("< send 604 8 40 08 10 00 00 00 00 00 >");  // segmented upload of 0x1008
  spin();
  EXPECT_NE(b->take().find("< frame 584 "), std::string::npos);
  a->close();
  spin(1100);  // the server's SDO timeout is 1 s
  const std::string seen = b->take();
  EXPECT_NE(seen.find("8008100000000405"), std::string::npos) << "abort 0x05040000 after 1 s: " << seen;
  EXPECT_EQ(srv->clients(), 1u);
  b->send("< send 604 8 40 00 10 00 00 00 00 00 >");
  spin();
  EXPECT_NE(b->take().find("4300100092010200"), std::string::npos);
}

TEST_F(socketcand_server_test, frames_for_unknown_nodes_pass_by_without_an_answer) {
  add_drive(4);
  auto a = join();
  a->send("< send 67F 8 40 00 10 00 00 00 00 00 >< send 0 2 1 7f >");
  spin(10);
  EXPECT_EQ(a->take(), "");
  EXPECT_EQ(drives[0]->node().state(), nmt_state::pre_operational);
}

/// 0x6064 from the last TPDO3 of node 1 (0x6041 + 0x6064) among the frames a client got.
std::int32_t last_tpdo3_position(const std::string& seen) {
  element_reader reader;
  reader.feed(seen);
  std::string element;
  std::string why;
  std::int32_t position = 0;
  bool found = false;
  while (reader.next(element) == element_reader::result::element) {
    frame f;
    if (!socketcand::parse_frame(element, f, why) || f.id != 0x381 || f.len != 6) continue;
    position = static_cast<std::int32_t>(f.data[2] | f.data[3] << 8 | f.data[4] << 16 |
                                         static_cast<std::uint32_t>(f.data[5]) << 24);
    found = true;
  }
  EXPECT_TRUE(found) << "no TPDO3 in " << seen;
  return position;
}

std::string rpdo3_send(std::int32_t set_point) {
  frame f = make_frame(0x401, {0x0F, 0x00});
  f.len = 6;
  const auto bits = static_cast<std::uint32_t>(set_point);
  for (int i = 0; i < 4; ++i) f.data[2 + i] = static_cast<std::uint8_t>(bits >> (8 * i));
  return socketcand::format_send(f);
}

TEST_F(socketcand_server_test, a_held_up_host_steps_its_drives_before_it_answers_the_sync_that_waited) {
  add_drive(1);
  auto a = join();
  a->send("< send 0 2 1 1 >< send 601 8 2f 60 60 0 8 0 0 0 >");  // NMT start; SDO 0x6060 = 8 (csp)
  spin(5);
  a->send("< send 201 2 6 0 >");
  spin(5);
  a->send("< send 201 2 f 0 >");
  spin(100);  // enabled, the holding brake open
  a->take();
  a->send("< send 80 0 >");
  spin(1, 0);
  const std::int32_t start = last_tpdo3_position(a->take());
  a->send(rpdo3_send(start + 100) + "< send 80 0 >");
  spin(1, 0);  // the SYNC takes the set-point; no time has passed
  EXPECT_EQ(last_tpdo3_position(a->take()), start);
  // The host is held up for 5 ms while the next set-point and SYNC wait for it: it steps the drive
  // through those 5 ms first, so TPDO3 shows the set-point before reached, not a position 5 ms old.
  a->send(rpdo3_send(start + 200) + "< send 80 0 >");
  spin(1, 5000);
  EXPECT_EQ(last_tpdo3_position(a->take()), start + 100);
}

TEST_F(socketcand_server_test, our_client_channel_joins_and_exchanges_frames) {
  auto peer = join();
  std::string why;
  std::error_code ec;
  const std::unique_ptr<socketcand::client_channel> ch = connect_client(why, ec);
  ASSERT_TRUE(ch) << why;
  ASSERT_FALSE(ch->send(make_frame(0x222, {9})));
  spin(2);
  EXPECT_EQ(peer->take().substr(0, 15), "\n< frame 222 0.");
  peer->send("< send 333 1 7 >");
  spin(2);
  frame f;
  ASSERT_TRUE(ch->receive(f));
  EXPECT_EQ(f.id, 0x333u);
  EXPECT_EQ(f.data[0], 7);
}

// The drive master over socketcand on loopback: the bus checks of the in-process bus
// (drive_master_test.cpp) with the test's own words carried.
class master_over_socketcand : public socketcand_server_test {
 protected:
  void connect() {
    std::string why;
    std::error_code ec;
    channel_ = connect_client(why, ec);
    ASSERT_TRUE(channel_) << why;
  }
  std::unique_ptr<drive_master> connect_master(drive_master_config mc = {}) {
    connect();
    if (!channel_) return nullptr;
    return std::make_unique<drive_master>(*channel_, mc);
  }
  void run(drive_master& m, int ms, bool alive = true) {
    for (int i = 0; i < ms; ++i) {
      if (alive) m.poll(*channel_, 1000);
      spin(1);
      if (alive) m.poll(*channel_, 0);
      spin(1, 0);
    }
  }
  /// Carries `word` and runs until the status word shows `s` (or the master failed), at most `ms`.
  bool carry_until(drive_master& m, std::uint16_t word, state s, int ms = 3000) {
    m.send_control_word(word);
    for (int i = 0; i < ms; ++i) {
      run(m, 1);
      if (m.observed() == s) return true;
      if (m.phase() == master_phase::failed) return false;
    }
    return false;
  }
  sim::virtual_drive& drive() { return drives[0]->drive(); }
  std::unique_ptr<socketcand::client_channel> channel_;
};

TEST_F(master_over_socketcand, the_words_it_carries_enable_the_drive_and_a_fault_comes_with_its_emcy) {
  add_drive(1);
  auto m = connect_master();
  ASSERT_TRUE(m);
  std::vector<std::uint16_t> emcy;
  m->on_emcy = [&](std::uint16_t code, std::uint8_t, const std::uint8_t*) { emcy.push_back(code); };
  ASSERT_TRUE(carry_until(*m, test::shutdown_word, state::ready_to_switch_on)) << m->failure_text();
  ASSERT_TRUE(carry_until(*m, test::switch_on_word, state::switched_on));
  ASSERT_TRUE(carry_until(*m, test::enable_operation_word, state::operation_enabled));
  EXPECT_EQ(drive().view().current(), state::operation_enabled);
  drive().view().inject_fault(0x3210);
  run(*m, 300);
  EXPECT_EQ(m->observed(), state::fault);
  EXPECT_EQ(m->error_code(), 0x3210);
  ASSERT_FALSE(emcy.empty());
  EXPECT_EQ(emcy[0], 0x3210);
}

class heartbeat_over_socketcand : public master_over_socketcand,
                                  public ::testing::WithParamInterface<int> {};

TEST_P(heartbeat_over_socketcand, silent_master_makes_the_drive_apply_0x6007) {
  const int code = GetParam();
  add_drive(1);
  ASSERT_EQ(drives[0]->node().write(0x6007, 0, code), sdo_abort::none);
  drive_master_config mc;
  mc.master_heartbeat_ms = 20;
  auto m = connect_master(mc);
  ASSERT_TRUE(m);
  ASSERT_TRUE(carry_until(*m, test::shutdown_word, state::ready_to_switch_on)) << m->failure_text();
  ASSERT_TRUE(carry_until(*m, test::switch_on_word, state::switched_on));
  ASSERT_TRUE(carry_until(*m, test::enable_operation_word, state::operation_enabled));
  run(*m, 100);
  ASSERT_FALSE(drives[0]->node().connection_lost());
  run(*m, 500, /*alive=*/false);
  EXPECT_TRUE(drives[0]->node().connection_lost());
  const state expected[4] = {state::operation_enabled, state::fault, state::switch_on_disabled,
                             state::switch_on_disabled};
  EXPECT_EQ(drive().view().current(), expected[code]);
}

INSTANTIATE_TEST_SUITE_P(codes_0_to_3, heartbeat_over_socketcand, ::testing::Range(0, 4));


}  // namespace
}  // namespace cia402::canopen

namespace cia402::canopen {
namespace {

TEST_F(socketcand_server_test, a_client_asking_for_a_bus_the_server_lacks_is_told_so_in_words) {
  std::error_code ec;
  std::string why;
  const auto ch = connect_client(why, ec, "can9");
  EXPECT_EQ(ch, nullptr);
  EXPECT_TRUE(ec);
  EXPECT_EQ(why, "the socketcand server at 127.0.0.1:" + std::to_string(srv->port()) +
                     " has no bus 'can9'");
}

}  // namespace
}  // namespace cia402::canopen
