// The CANopen drive master against virtual drives (the simulator behind CiA 301 slaves) on the
// in-process bus: configuration over SDO, NMT start, the core's master step over PDOs with SYNC;
// enable, quick stop with each 0x605A code, fault and reset, heartbeat loss with each 0x6007 code,
// and the clear failures for a missing node, a refused SDO and a lost drive heartbeat.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "cia402/canopen/drive_objects.hpp"
#include "cia402/canopen/drive_master.hpp"
#include "cia402/canopen/sim_device.hpp"
#include "cia402/canopen/slave.hpp"
#include "cia402/canopen/virtual_bus.hpp"
#include "cia402/words.hpp"

namespace cia402::canopen {
namespace {

struct drive_node {
  std::unique_ptr<sim_device> dev;
  std::unique_ptr<virtual_channel> ch;
  std::unique_ptr<slave> sl;
};

class bench {
 public:
  explicit bench(drive_master_config mc = {}, std::vector<std::uint8_t> ids = {1}) {
    for (std::uint8_t id : ids) add_drive(id);
    master_ch_ = bus_.attach();
    master_ = std::make_unique<drive_master>(*master_ch_, mc);
    master_->on_emcy = [this](std::uint16_t code, std::uint8_t, const std::uint8_t*) {
      emcy.push_back(code);
    };
  }
  void add_drive(std::uint8_t id) {
    drive_node n;
    n.dev = std::make_unique<sim_device>(standard_profile());
    n.ch = bus_.attach();
    slave_config c;
    c.objects = drive_objects();
    c.node_id = id;
    n.sl = std::make_unique<slave>(*n.dev, *n.ch, c);
    drives_.push_back(std::move(n));
  }
  /// `ms` milliseconds in steps of 1 ms; the master stays silent with `master_alive` false.
  void run_ms(int ms, bool master_alive = true) {
    for (int i = 0; i < ms; ++i) {
      if (master_alive) master_->poll(*master_ch_, 1000);
      for (drive_node& n : drives_) n.sl->poll(*n.ch, 1000);
      if (master_alive) master_->poll(*master_ch_, 0);
      for (drive_node& n : drives_) n.sl->poll(*n.ch, 0);
      if (master_alive) {
        master_->poll(*master_ch_, 0);
      } else {
        frame f;
        while (master_ch_->receive(f)) {}
      }
    }
  }
  /// Runs until the master has reached its target (or failed), at most `ms`.
  bool run_until_reached(int ms) {
    for (int i = 0; i < ms; ++i) {
      run_ms(1);
      if (master_->outcome() == master_outcome::reached) return true;
      if (master_->phase() == master_phase::failed) return false;
    }
    return false;
  }
  drive_master& master() { return *master_; }
  slave& node(std::size_t i = 0) { return *drives_[i].sl; }
  sim::virtual_drive& drive(std::size_t i = 0) { return drives_[i].dev->drive(); }
  void remove_drives() { drives_.clear(); }

  std::vector<std::uint16_t> emcy;

 private:
  virtual_bus bus_;
  std::vector<drive_node> drives_;
  std::unique_ptr<virtual_channel> master_ch_;
  std::unique_ptr<drive_master> master_;
};

TEST(drive_master, enable_configures_the_drive_and_reaches_operation_enabled) {
  bench b;
  b.master().set_target(state::operation_enabled);
  ASSERT_TRUE(b.run_until_reached(2000)) << b.master().failure_text();
  EXPECT_EQ(b.master().phase(), master_phase::running);
  EXPECT_EQ(b.node().state(), nmt_state::operational);
  EXPECT_EQ(b.drive().view().current(), state::operation_enabled);
  EXPECT_EQ(b.master().observed(), state::operation_enabled);
  EXPECT_EQ(b.master().status_word() & 0x6F, 0x27);
  // The master set up TPDO1 = 0x6041 + 0x603F on every SYNC and RPDO1 = 0x6040 on receipt.
  EXPECT_EQ(b.node().tpdo(0).count, 2);
  EXPECT_EQ(b.node().tpdo(0).transmission_type, 1);
  EXPECT_EQ(b.node().rpdo(0).count, 1);
  std::int64_t hb = 0;
  b.node().read(0x1017, 0, hb);
  EXPECT_EQ(hb, 100);
}

TEST(drive_master, disable_from_operation_enabled_reaches_switch_on_disabled) {
  bench b;
  b.master().set_target(state::operation_enabled);
  ASSERT_TRUE(b.run_until_reached(2000));
  b.master().set_target(state::switch_on_disabled);
  ASSERT_TRUE(b.run_until_reached(2000));
  EXPECT_EQ(b.drive().view().current(), state::switch_on_disabled);
}

TEST(drive_master, two_drives_on_one_bus_each_follow_their_own_master) {
  virtual_bus bus;
  std::vector<drive_node> nodes;
  std::vector<std::unique_ptr<virtual_channel>> chs;
  std::vector<std::unique_ptr<drive_master>> masters;
  for (std::uint8_t id : {1, 2}) {
    drive_node n;
    n.dev = std::make_unique<sim_device>(standard_profile());
    n.ch = bus.attach();
    n.sl = std::make_unique<slave>(*n.dev, *n.ch, drive_node_config(id));
    nodes.push_back(std::move(n));
    chs.push_back(bus.attach());
    drive_master_config c;
    c.node_id = id;
    masters.push_back(std::make_unique<drive_master>(*chs.back(), c));
  }
  masters[0]->set_target(state::operation_enabled);
  masters[1]->set_target(state::ready_to_switch_on);
  for (int i = 0; i < 1500; ++i) {
    for (std::size_t k = 0; k < 2; ++k) masters[k]->poll(*chs[k], 1000);
    for (drive_node& n : nodes) n.sl->poll(*n.ch, 1000);
  }
  EXPECT_EQ(nodes[0].dev->drive().view().current(), state::operation_enabled);
  EXPECT_EQ(nodes[1].dev->drive().view().current(), state::ready_to_switch_on);
}

class quick_stop_code : public ::testing::TestWithParam<int> {};

TEST_P(quick_stop_code, quick_stop_from_operation_enabled_follows_0x605A) {
  const int code = GetParam();
  bench b;
  ASSERT_EQ(b.node().write(0x605A, 0, code), sdo_abort::none);
  b.master().set_target(state::operation_enabled);
  ASSERT_TRUE(b.run_until_reached(2000)) << b.master().failure_text();
  b.master().set_command(command::quick_stop);
  b.run_ms(500);
  // S5: 1..4 ramp then T12 to SWITCH ON DISABLED; 5..8 stay in QUICK STOP ACTIVE with bit 10 at
  // standstill; 0 coasts and stays in QUICK STOP ACTIVE.
  const bool ends = code >= 1 && code <= 4;
  EXPECT_EQ(b.drive().view().current(), ends ? state::switch_on_disabled : state::quick_stop_active);
  EXPECT_EQ(b.master().observed(), ends ? state::switch_on_disabled : state::quick_stop_active);
  if (code >= 5) EXPECT_TRUE(b.master().status_word() & status_bit::target_reached);
  if (code >= 5) {
    // T16 on Enable operation: the master's plan for OPERATION ENABLED is one step.
    b.master().set_target(state::operation_enabled);
    ASSERT_TRUE(b.run_until_reached(500));
    EXPECT_EQ(b.drive().view().state_of_axis().core.last_transition, 16);
  }
}

INSTANTIATE_TEST_SUITE_P(codes_0_to_8, quick_stop_code, ::testing::Range(0, 9));

TEST(drive_master, fault_is_reported_with_its_emcy_and_a_new_target_resets_it) {
  bench b;
  b.master().set_target(state::operation_enabled);
  ASSERT_TRUE(b.run_until_reached(2000));
  b.drive().view().inject_fault(0x2310);
  b.run_ms(300);
  EXPECT_EQ(b.master().outcome(), master_outcome::fault);
  EXPECT_EQ(b.master().observed(), state::fault);
  EXPECT_EQ(b.master().error_code(), 0x2310);
  ASSERT_FALSE(b.emcy.empty());
  EXPECT_EQ(b.emcy.front(), 0x2310);
  // The cause is gone: a new target is the decision to reset (T15), then T2, T3, T4.
  b.drive().view().clear_faults();
  b.master().set_target(state::operation_enabled);
  ASSERT_TRUE(b.run_until_reached(2000));
  EXPECT_EQ(b.drive().view().current(), state::operation_enabled);
  EXPECT_EQ(b.emcy.back(), 0x0000) << "EMCY error reset after T15";
}

class master_heartbeat_loss : public ::testing::TestWithParam<int> {};

TEST_P(master_heartbeat_loss, silent_master_makes_the_drive_apply_0x6007) {
  const int code = GetParam();
  drive_master_config mc;
  mc.master_heartbeat_ms = 20;
  bench b(mc);
  ASSERT_EQ(b.node().write(0x6007, 0, code), sdo_abort::none);
  b.master().set_target(state::operation_enabled);
  ASSERT_TRUE(b.run_until_reached(2000)) << b.master().failure_text();
  std::int64_t watch = 0;
  b.node().read(0x1016, 1, watch);
  EXPECT_EQ(watch, (127 << 16) | 60);
  b.run_ms(200);
  EXPECT_FALSE(b.node().connection_lost());
  b.run_ms(500, /*master_alive=*/false);
  EXPECT_TRUE(b.node().connection_lost());
  const state expected[4] = {state::operation_enabled, state::fault, state::switch_on_disabled,
                             state::switch_on_disabled};  // 3 = Quick stop, 0x605A = 2 ends in T12
  EXPECT_EQ(b.drive().view().current(), expected[code]);
  if (code == 1) {
    std::int64_t err = 0;
    b.node().read(0x603F, 0, err);
    EXPECT_EQ(err, 0x8130);
  }
}

INSTANTIATE_TEST_SUITE_P(codes_0_to_3, master_heartbeat_loss, ::testing::Range(0, 4));

TEST(drive_master, missing_node_fails_with_no_answer_naming_the_first_request) {
  drive_master_config mc;
  mc.node_id = 9;
  bench b(mc);  // the bus has node 1 only
  b.master().set_target(state::operation_enabled);
  b.run_ms(600);
  EXPECT_EQ(b.master().phase(), master_phase::failed);
  EXPECT_EQ(b.master().failure(), master_failure::no_answer);
  EXPECT_EQ(b.master().failed_index(), 0x1000);
  EXPECT_NE(b.master().failure_text().find("node 9 does not answer"), std::string::npos);
}

TEST(drive_master, refused_configuration_fails_with_the_abort_code) {
  drive_master_config mc;
  mc.master_heartbeat_ms = 50;
  bench b(mc);
  // Another entry already watches node 127: 0x1016 sub 1 for it is refused (0x06040043).
  ASSERT_EQ(b.node().write(0x1016, 2, (127 << 16) | 500), sdo_abort::none);
  b.master().set_target(state::operation_enabled);
  b.run_ms(300);
  EXPECT_EQ(b.master().failure(), master_failure::sdo_refused);
  EXPECT_EQ(b.master().failed_abort(), sdo_abort::general_parameter_incompatibility);
  EXPECT_EQ(b.master().failed_index(), 0x1016);
  EXPECT_NE(b.master().failure_text().find("0x06040043"), std::string::npos);
  EXPECT_EQ(b.drive().view().current(), state::switch_on_disabled) << "nothing was started";
}

TEST(drive_master, lost_drive_heartbeat_fails_the_master) {
  bench b;
  b.master().set_target(state::operation_enabled);
  ASSERT_TRUE(b.run_until_reached(2000));
  b.run_ms(200);
  EXPECT_EQ(b.master().phase(), master_phase::running);
  b.remove_drives();
  b.run_ms(400);
  EXPECT_EQ(b.master().failure(), master_failure::heartbeat_lost);
}

TEST(drive_master, watching_sends_no_control_word) {
  bench b;
  b.run_ms(300);
  EXPECT_EQ(b.master().phase(), master_phase::running);
  EXPECT_TRUE(b.master().status_known());
  EXPECT_EQ(b.master().observed(), state::switch_on_disabled);
  EXPECT_EQ(b.drive().view().control_word(), 0);
}

}  // namespace
}  // namespace cia402::canopen
