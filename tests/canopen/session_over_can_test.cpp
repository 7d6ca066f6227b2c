// Steering a drive over CAN: the axis session (the one master) over a can_link to virtual drives
// (the simulator behind CiA 301 slaves), on the in-process bus and over socketcand on loopback, in
// virtual time. Enable, disable, two drives on one bus each following their own session, quick stop
// with each 0x605A code and T16 back, a fault with its EMCY and the reset. These are the steering
// checks drive_master made with its own retired master step; drive_master now carries the words
// the link gives it, and its bus checks stay in drive_master_test.cpp.
#include <gtest/gtest.h>

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "cia402/apps/bus_host.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/axis/session.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/canopen/transport/socketcand.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/words.hpp"

namespace cia402::canopen {
namespace {

// A session over a can_link on `ch`, for node `id`, with the EMCYs it reports kept.
struct axis_on_can {
  axis_on_can(std::unique_ptr<channel> channel_in, std::uint8_t id, const std::string& bus) : ch(std::move(channel_in)) {
    can_link_config c;
    c.node_id = id;
    c.bus_name = bus;
    c.drive_profile = &standard_profile();
    link = std::make_unique<can_link>(*ch, c);
    axes::session_config sc;
    sc.drive_profile = &standard_profile();
    s.emplace(*link, sc);
    s->on_emergency = [this](std::uint16_t code, std::uint8_t, std::span<const std::uint8_t>) { emcy.push_back(code); };
  }
  std::unique_ptr<channel> ch;
  std::unique_ptr<can_link> link;
  std::optional<axes::session> s;
  std::vector<std::uint16_t> emcy;
};

axes::result no_end() {
  axes::result r;
  r.end = axes::outcome::failed;
  r.error = "no end within the test's time";
  return r;
}

// Drives on the in-process bus, each with a session over its own can_link, in steps of 1 ms.
class bench {
 public:
  explicit bench(std::vector<std::uint8_t> ids = {1}) {
    for (std::uint8_t id : ids) {
      drives_.push_back(
          std::make_unique<apps::virtual_drive_node>(standard_profile(), bus_.attach(), apps::drive_node_config(id)));
    }
    for (int i = 0; i < 10; ++i) {  // past power-up (T0, T1) and the boot-up message
      for (auto& d : drives_) d->poll(1000);
    }
    for (std::uint8_t id : ids) axes_.push_back(std::make_unique<axis_on_can>(bus_.attach(), id, "virtual (test)"));
  }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      for (auto& a : axes_) (void)a->s->poll(1000);
      for (auto& d : drives_) d->poll(1000);
    }
  }
  /// Issues a request on axis `i` and runs until it has ended, at most `ms`.
  axes::result finish(const std::function<std::uint64_t(axes::completion)>& request, int ms = 5000) {
    std::optional<axes::result> got;
    request([&got](const axes::result& r) { got = r; });
    for (int i = 0; i < ms && !got; ++i) run_ms(1);
    return got ? *got : no_end();
  }
  axes::result go_to(state target, std::size_t i = 0) {
    return finish([this, target, i](axes::completion d) { return session(i).go_to(target, std::move(d)); });
  }
  axes::session& session(std::size_t i = 0) { return *axes_[i]->s; }
  const std::vector<std::uint16_t>& emcy(std::size_t i = 0) const { return axes_[i]->emcy; }
  slave& node(std::size_t i = 0) { return drives_[i]->node(); }
  sim::virtual_drive& drive(std::size_t i = 0) { return drives_[i]->drive(); }

 private:
  virtual_bus bus_;
  std::vector<std::unique_ptr<apps::virtual_drive_node>> drives_;
  std::vector<std::unique_ptr<axis_on_can>> axes_;
};

TEST(session_over_can, enable_reaches_operation_enabled) {
  bench b;
  const axes::result on = b.go_to(state::operation_enabled);
  ASSERT_TRUE(on.ok()) << on.error;
  EXPECT_EQ(b.node().state(), nmt_state::operational);
  EXPECT_EQ(b.drive().view().current(), state::operation_enabled);
  EXPECT_EQ(b.session().observed(), state::operation_enabled);
  EXPECT_EQ(b.session().status_word() & 0x6F, 0x27);
  ASSERT_TRUE(on.shown.has_value());
  EXPECT_EQ(*on.shown, state::operation_enabled);
}

TEST(session_over_can, disable_from_operation_enabled_reaches_switch_on_disabled) {
  bench b;
  ASSERT_TRUE(b.go_to(state::operation_enabled).ok());
  const axes::result off = b.go_to(state::switch_on_disabled);
  ASSERT_TRUE(off.ok()) << off.error;
  EXPECT_EQ(b.drive().view().current(), state::switch_on_disabled);
  EXPECT_EQ(b.session().observed(), state::switch_on_disabled);
}

TEST(session_over_can, two_drives_on_one_bus_each_follow_their_own_session) {
  bench b({1, 2});
  std::optional<axes::result> first, second;
  (void)b.session(0).go_to(state::operation_enabled, [&](const axes::result& r) { first = r; });
  (void)b.session(1).go_to(state::ready_to_switch_on, [&](const axes::result& r) { second = r; });
  for (int i = 0; i < 3000 && !(first && second); ++i) b.run_ms(1);
  ASSERT_TRUE(first && second);
  EXPECT_TRUE(first->ok()) << first->error;
  EXPECT_TRUE(second->ok()) << second->error;
  EXPECT_EQ(b.drive(0).view().current(), state::operation_enabled);
  EXPECT_EQ(b.drive(1).view().current(), state::ready_to_switch_on);
}

class quick_stop_code : public ::testing::TestWithParam<int> {};

TEST_P(quick_stop_code, quick_stop_from_operation_enabled_follows_0x605A) {
  const int code = GetParam();
  bench b;
  ASSERT_EQ(b.node().write(0x605A, 0, code), sdo_abort::none);
  const axes::result on = b.go_to(state::operation_enabled);
  ASSERT_TRUE(on.ok()) << on.error;
  EXPECT_EQ(b.session().option_code(option::quick_stop), code) << "the session read the drive's own code";
  const axes::result stop = b.finish([&](axes::completion d) { return b.session().quick_stop(std::move(d)); });
  EXPECT_TRUE(stop.ok()) << stop.error;
  b.run_ms(100);
  // S5: 1..4 ramp then T12 to SWITCH ON DISABLED; 5..8 stay in QUICK STOP ACTIVE with bit 10 at
  // standstill; 0 coasts and stays in QUICK STOP ACTIVE.
  const bool ends = code >= 1 && code <= 4;
  EXPECT_EQ(b.drive().view().current(), ends ? state::switch_on_disabled : state::quick_stop_active);
  EXPECT_EQ(b.session().observed(), ends ? state::switch_on_disabled : state::quick_stop_active);
  if (code >= 5) EXPECT_TRUE(b.session().status_word() & status_bit::target_reached);
  if (code >= 5) {
    // T16 on Enable operation: the planner's way to OPERATION ENABLED from there is one step.
    const axes::result back = b.go_to(state::operation_enabled);
    ASSERT_TRUE(back.ok()) << back.error;
    EXPECT_EQ(b.drive().view().state_of_axis().core.last_transition, 16);
  }
}

INSTANTIATE_TEST_SUITE_P(codes_0_to_8, quick_stop_code, ::testing::Range(0, 9));

TEST(session_over_can, a_fault_is_reported_with_its_emcy_and_a_reset_then_an_enable_brings_the_drive_back) {
  bench b;
  ASSERT_TRUE(b.go_to(state::operation_enabled).ok());
  b.drive().view().inject_fault(0x2310);
  b.run_ms(300);
  EXPECT_EQ(b.session().observed(), state::fault);
  EXPECT_EQ(b.session().error_code(), 0x2310);
  ASSERT_FALSE(b.emcy().empty());
  EXPECT_EQ(b.emcy().front(), 0x2310);
  b.drive().view().clear_faults();
  // The session does not reset on a new target (drive_master's retired step did): it says so.
  const axes::result refused = b.go_to(state::operation_enabled);
  EXPECT_FALSE(refused.ok());
  EXPECT_NE(refused.error.find("reset it first"), std::string::npos) << refused.error;
  const axes::result reset = b.finish([&](axes::completion d) { return b.session().reset(std::move(d)); });
  ASSERT_TRUE(reset.ok()) << reset.error;
  EXPECT_EQ(b.drive().view().current(), state::switch_on_disabled) << "T15";
  EXPECT_EQ(b.emcy().back(), 0x0000) << "EMCY error reset after T15";
  const axes::result on = b.go_to(state::operation_enabled);  // T2, T3, T4
  ASSERT_TRUE(on.ok()) << on.error;
  EXPECT_EQ(b.drive().view().current(), state::operation_enabled);
}

// The same session over socketcand on loopback TCP: `cia402 bus`'s server (apps::bus_host) with
// the virtual drives, the link on our own socketcand client.
class session_over_socketcand : public ::testing::Test {
 protected:
  void SetUp() override {
    socketcand::server_config cfg;
    cfg.port = 0;
    cfg.join_grace_us = 0;
    host.restart_server(cfg);
    ASSERT_FALSE(host.open());
    ASSERT_NE(host.server().port(), 0);
  }
  void spin(std::uint32_t us) { (void)host.cycle(us, 0); }
  void connect() {
    std::error_code ec;
    std::string why;
    std::atomic<bool> connected{false};
    // connect() blocks for the handshake: the server loop runs beside it until it is done.
    std::thread server_loop([&] {
      while (!connected) (void)host.cycle(1000, 5);
    });
    std::unique_ptr<socketcand::client_channel> ch =
        socketcand::client_channel::connect("127.0.0.1", host.server().port(), "can0", ec, why, 3000);
    connected = true;
    server_loop.join();
    ASSERT_TRUE(ch) << why;
    axis = std::make_unique<axis_on_can>(std::move(ch), 1, "socketcand (test)");
  }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      (void)axis->s->poll(1000);
      spin(1000);
      (void)axis->s->poll(0);
      spin(0);
    }
  }
  axes::result finish(const std::function<std::uint64_t(axes::completion)>& request, int ms = 5000) {
    std::optional<axes::result> got;
    request([&got](const axes::result& r) { got = r; });
    for (int i = 0; i < ms && !got; ++i) run_ms(1);
    return got ? *got : no_end();
  }
  axes::result enable() {
    return finish([this](axes::completion d) { return axis->s->go_to(state::operation_enabled, std::move(d)); });
  }
  sim::virtual_drive& drive() { return host.drives()[0]->drive(); }

  apps::bus_host host{socketcand::server_config{}};
  std::unique_ptr<axis_on_can> axis;
};

TEST_F(session_over_socketcand, enable_then_fault_and_reset) {
  host.add_drive(standard_profile(), apps::drive_node_config(1));
  ASSERT_NO_FATAL_FAILURE(connect());
  const axes::result on = enable();
  ASSERT_TRUE(on.ok()) << on.error;
  EXPECT_EQ(drive().view().current(), state::operation_enabled);
  drive().view().inject_fault(0x3210);
  run_ms(300);
  EXPECT_EQ(axis->s->observed(), state::fault);
  EXPECT_EQ(axis->s->error_code(), 0x3210);
  ASSERT_FALSE(axis->emcy.empty());
  EXPECT_EQ(axis->emcy[0], 0x3210);
  drive().view().clear_faults();
  const axes::result reset = finish([this](axes::completion d) { return axis->s->reset(std::move(d)); });
  ASSERT_TRUE(reset.ok()) << reset.error;
  const axes::result again = enable();
  ASSERT_TRUE(again.ok()) << again.error;
  EXPECT_EQ(drive().view().current(), state::operation_enabled);
  EXPECT_EQ(axis->emcy.back(), 0x0000) << "EMCY error reset after T15";
}

class quick_stop_over_socketcand : public session_over_socketcand, public ::testing::WithParamInterface<int> {};

TEST_P(quick_stop_over_socketcand, quick_stop_follows_0x605A) {
  const int code = GetParam();
  host.add_drive(standard_profile(), apps::drive_node_config(1));
  ASSERT_EQ(host.drives()[0]->node().write(0x605A, 0, code), sdo_abort::none);
  ASSERT_NO_FATAL_FAILURE(connect());
  const axes::result on = enable();
  ASSERT_TRUE(on.ok()) << on.error;
  const axes::result stop = finish([this](axes::completion d) { return axis->s->quick_stop(std::move(d)); });
  EXPECT_TRUE(stop.ok()) << stop.error;
  run_ms(100);
  const bool ends = code >= 1 && code <= 4;
  EXPECT_EQ(drive().view().current(), ends ? state::switch_on_disabled : state::quick_stop_active);
  EXPECT_EQ(axis->s->observed(), drive().view().current());
}

INSTANTIATE_TEST_SUITE_P(codes_0_to_8, quick_stop_over_socketcand, ::testing::Range(0, 9));

}  // namespace
}  // namespace cia402::canopen
