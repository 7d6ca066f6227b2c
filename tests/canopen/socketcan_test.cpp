// SocketCAN needs a kernel with CAN and a vcan interface; where there is none the tests say why
// and skip. Set CIA402_VCAN (default vcan0) to the interface to use.
#include <gtest/gtest.h>

#include <cstdlib>

#include "cia402/canopen/transport/channel_url.hpp"
#include "cia402/canopen/transport/socketcan.hpp"

namespace cia402::canopen {
namespace {

std::string vcan_name() {
  const char* n = std::getenv("CIA402_VCAN");
  return n != nullptr ? n : "vcan0";
}

TEST(socketcan, two_sockets_on_one_vcan_see_each_others_frames) {
  std::error_code ec;
  auto a = socketcan_channel::open(vcan_name(), ec);
  if (!a) GTEST_SKIP() << "no SocketCAN interface " << vcan_name() << ": " << ec.message();
  auto b = socketcan_channel::open(vcan_name(), ec);
  ASSERT_TRUE(b) << ec.message();
  frame f = make_frame(0x123, {1, 2, 3});
  ASSERT_FALSE(a->send(f));
  frame got;
  bool received = false;
  for (int i = 0; i < 1000 && !received; ++i) received = b->receive(got);
  ASSERT_TRUE(received);
  EXPECT_EQ(got, f);
}

TEST(socketcan, missing_interface_fails_with_the_os_reason) {
  std::error_code ec;
  auto c = socketcan_channel::open("nosuchcan9", ec);
  EXPECT_FALSE(c);
  EXPECT_TRUE(ec);
  std::string why;
  channel_url u;
  ASSERT_TRUE(parse_channel_url("socketcan://nosuchcan9", u, why));
  EXPECT_FALSE(open_channel(u, why));
  EXPECT_NE(why.find("cannot open SocketCAN interface 'nosuchcan9'"), std::string::npos) << why;
}

TEST(channel_url, urls_parse_and_bad_ones_say_why) {
  channel_url u;
  std::string why;
  ASSERT_TRUE(parse_channel_url("socketcand://127.0.0.1:29536/can0", u, why));
  EXPECT_EQ(u.type, channel_url::kind::socketcand);
  EXPECT_EQ(u.host, "127.0.0.1");
  EXPECT_EQ(u.port, 29536);
  EXPECT_EQ(u.bus, "can0");
  ASSERT_TRUE(parse_channel_url("socketcan://vcan0", u, why));
  EXPECT_EQ(u.bus, "vcan0");
  ASSERT_TRUE(parse_channel_url("virtual", u, why));
  EXPECT_EQ(u.type, channel_url::kind::virtual_bus);
  EXPECT_FALSE(parse_channel_url("socketcand://host:99999/can0", u, why));
  EXPECT_NE(why.find("99999"), std::string::npos);
  EXPECT_FALSE(parse_channel_url("tcp://x", u, why));
  EXPECT_FALSE(parse_channel_url("socketcan://", u, why));
}

}  // namespace
}  // namespace cia402::canopen
