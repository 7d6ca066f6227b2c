// The CANopen drive master against virtual drives (the simulator behind CiA 301 slaves) on the
// in-process bus: configuration over SDO, NMT start, the words it carries in RPDO1 and the status
// word it brings back from TPDO1 with SYNC or on change; EMCY, the guard (0x1016) and heartbeat loss
// with each 0x6007 code, and the clear failures for a missing node, a refused SDO and a lost drive
// heartbeat. It does not steer: the words here are the test's own (carried_words.hpp). Steering over
// CAN (enable, disable, quick stop with each 0x605A code, fault reset, two drives) is the axis
// session's, tested over a can_link in session_over_can_test.cpp.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "cia402/canopen/master/drive_master.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/manufacturer_objects.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/words.hpp"
#include "carried_words.hpp"

namespace cia402::canopen {
namespace {

using namespace test;

class bench {
 public:
  explicit bench(drive_master_config mc = {}, std::vector<std::uint8_t> ids = {1}) {
    for (std::uint8_t id : ids) add_drive(id);
    master_ch_ = bus_.attach();
    sniffer_ = bus_.attach();
    master_ = std::make_unique<drive_master>(*master_ch_, mc);
    master_->on_emcy = [this](std::uint16_t code, std::uint8_t, const std::uint8_t*) {
      emcy.push_back(code);
    };
  }
  void add_drive(std::uint8_t id) {
    drives_.push_back(
        std::make_unique<apps::virtual_drive_node>(standard_profile(), bus_.attach(), apps::drive_node_config(id)));
  }
  /// `ms` milliseconds in steps of 1 ms; the master stays silent with `master_alive` false.
  void run_ms(int ms, bool master_alive = true) {
    for (int i = 0; i < ms; ++i) {
      if (master_alive) master_->poll(*master_ch_, 1000);
      for (auto& n : drives_) n->poll(1000);
      if (master_alive) master_->poll(*master_ch_, 0);
      for (auto& n : drives_) n->poll(0);
      if (master_alive) {
        master_->poll(*master_ch_, 0);
      } else {
        frame f;
        while (master_ch_->receive(f)) {}
      }
    }
  }
  /// Runs until the master has set the drive up (or failed), at most `ms`.
  bool run_until_running(int ms = 2000) {
    for (int i = 0; i < ms; ++i) {
      if (master_->phase() == master_phase::running) return true;
      run_ms(1);
    }
    return master_->phase() == master_phase::running;
  }
  /// Carries `word` (with a fault-reset edge if asked) and runs until the status word shows `s` (or
  /// the master failed), at most `ms`.
  bool carry_until(std::uint16_t word, state s, bool reset_edge = false, int ms = 500) {
    master_->send_control_word(word, reset_edge);
    for (int i = 0; i < ms; ++i) {
      run_ms(1);
      if (master_->observed() == s && !master_->words_queued()) return true;
      if (master_->phase() == master_phase::failed) return false;
    }
    return false;
  }
  /// Set up, then the words of T2, T3 and T4: the drive in OPERATION ENABLED.
  bool enable_by_words() {
    return run_until_running() && carry_until(shutdown_word, state::ready_to_switch_on) &&
           carry_until(switch_on_word, state::switched_on) &&
           carry_until(enable_operation_word, state::operation_enabled);
  }
  drive_master& master() { return *master_; }
  /// Another master in this one's place (a new `cia402 master` process), the same channel.
  void replace_master(const drive_master_config& mc) {
    master_.reset();
    master_ = std::make_unique<drive_master>(*master_ch_, mc);
  }
  slave& node(std::size_t i = 0) { return drives_[i]->node(); }
  sim::virtual_drive& drive(std::size_t i = 0) { return drives_[i]->drive(); }
  void remove_drives() { drives_.clear(); }
  virtual_bus& bus() { return bus_; }
  /// Every frame sent on the bus since the last call, in order.
  std::vector<frame> sent() {
    std::vector<frame> out;
    frame f;
    while (sniffer_->receive(f)) out.push_back(f);
    return out;
  }

  std::vector<std::uint16_t> emcy;

 private:
  virtual_bus bus_;
  std::vector<std::unique_ptr<apps::virtual_drive_node>> drives_;
  std::unique_ptr<virtual_channel> master_ch_;
  std::unique_ptr<virtual_channel> sniffer_;
  std::unique_ptr<drive_master> master_;
};

// The settings `serve --can` gives the master: PDOs on change, words of its own, polling, retry.
drive_master_config on_change_config() {
  drive_master_config mc;
  mc.timing = pdo_timing::on_change;
  mc.map_velocity = true;
  mc.heartbeat_required = false;
  mc.poll_us = 100000;
  mc.retry_us = 200000;
  mc.read_at_start = {0x6083, 0x60FF};
  return mc;
}

bool run_until_running(bench& b, int ms) { return b.run_until_running(ms); }

std::vector<std::uint16_t> words_in(const std::vector<frame>& frames, std::uint16_t id) {
  std::vector<std::uint16_t> words;
  for (const frame& f : frames) {
    if (f.id == id) words.push_back(static_cast<std::uint16_t>(get_le(f.data.data(), 2)));
  }
  return words;
}

TEST(drive_master, set_up_maps_the_pdos_and_the_words_it_carries_enable_the_drive) {
  bench b;
  ASSERT_TRUE(b.enable_by_words()) << b.master().failure_text();
  EXPECT_EQ(b.master().phase(), master_phase::running);
  EXPECT_EQ(b.node().state(), nmt_state::operational);
  EXPECT_EQ(b.drive().view().current(), state::operation_enabled);
  EXPECT_EQ(b.master().observed(), state::operation_enabled);
  EXPECT_EQ(b.master().status_word() & 0x6F, 0x27);
  EXPECT_EQ(b.master().last_sent(), enable_operation_word);
  // The master set up TPDO1 = 0x6041 + 0x603F on every SYNC and RPDO1 = 0x6040 on receipt.
  EXPECT_EQ(b.node().tpdo(0).count, 2);
  EXPECT_EQ(b.node().tpdo(0).transmission_type, 1);
  EXPECT_EQ(b.node().rpdo(0).count, 1);
  std::int64_t hb = 0;
  b.node().read(0x1017, 0, hb);
  EXPECT_EQ(hb, 100);
}

TEST(drive_master, with_sync_each_word_goes_out_once_in_rpdo1_and_each_sync_brings_a_status_word) {
  bench b;
  ASSERT_TRUE(b.run_until_running());
  (void)b.sent();
  b.master().send_control_word(shutdown_word);
  b.run_ms(100);
  const std::vector<frame> frames = b.sent();
  EXPECT_EQ(words_in(frames, cob::rpdo1 + 1), (std::vector<std::uint16_t>{shutdown_word}))
      << "a word is carried when given, not repeated: repeating is the session's link's choice";
  int syncs = 0;
  for (const frame& f : frames) syncs += f.id == cob::sync ? 1 : 0;
  EXPECT_EQ(syncs, 10) << "one SYNC every 10 ms";
  EXPECT_GE(words_in(frames, cob::tpdo1 + 1).size(), 9u) << "TPDO1 answers each SYNC";
  EXPECT_EQ(b.master().observed(), state::ready_to_switch_on);
}

TEST(drive_master, a_fault_is_reported_with_its_emcy_and_a_reset_edge_it_carries_sends_the_emcy_reset) {
  bench b;
  ASSERT_TRUE(b.enable_by_words());
  b.drive().view().inject_fault(0x2310);
  b.run_ms(300);
  EXPECT_EQ(b.master().observed(), state::fault);
  EXPECT_EQ(b.master().error_code(), 0x2310);
  ASSERT_FALSE(b.emcy.empty());
  EXPECT_EQ(b.emcy.front(), 0x2310);
  b.drive().view().clear_faults();
  ASSERT_TRUE(b.carry_until(disable_voltage_word, state::switch_on_disabled, /*reset_edge=*/true));
  EXPECT_EQ(b.emcy.back(), 0x0000) << "EMCY error reset after T15";
}

// A master that sends its heartbeat every 20 ms and has the drive watch it (0x1016): the guard
// whose loss the cases below provoke.
drive_master_config heartbeat_guarded() {
  drive_master_config mc;
  mc.master_heartbeat_ms = 20;
  return mc;
}

// 0x6007, what a lost connection makes the drive do, set to `reaction` (1 = fault), then the drive
// enabled by the master's words.
::testing::AssertionResult enable_with_loss_reaction(bench& b, std::int64_t reaction) {
  if (b.node().write(0x6007, 0, reaction) != sdo_abort::none) {
    return ::testing::AssertionFailure() << "0x6007 = " << reaction << " refused";
  }
  if (!b.enable_by_words()) return ::testing::AssertionFailure() << "not enabled: " << b.master().failure_text();
  return ::testing::AssertionSuccess();
}

class master_heartbeat_loss : public ::testing::TestWithParam<int> {};

TEST_P(master_heartbeat_loss, silent_master_makes_the_drive_apply_0x6007) {
  const int code = GetParam();
  bench b(heartbeat_guarded());
  ASSERT_TRUE(enable_with_loss_reaction(b, code));
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

TEST(drive_master, a_master_that_disabled_the_drive_then_went_silent_leaves_no_fault) {
  // An orderly end whose guard outlived the master: the drive was taken to READY TO SWITCH ON
  // first, so the lost heartbeat has nothing to protect (0x6007 acts on an enabled drive only).
  bench b(heartbeat_guarded());
  ASSERT_TRUE(enable_with_loss_reaction(b, 1));
  ASSERT_TRUE(b.carry_until(shutdown_word, state::ready_to_switch_on));  // T8
  b.run_ms(500, /*master_alive=*/false);
  EXPECT_TRUE(b.node().connection_lost());
  EXPECT_EQ(b.drive().view().current(), state::ready_to_switch_on);
  EXPECT_EQ(b.drive().view().outputs().error_code, 0);
}

TEST(drive_master, a_drive_enabled_while_the_heartbeat_is_lost_applies_0x6007_then) {
  // The loss came while the drive was disabled; a control word that enables it while the master
  // is still gone (a second master, a local tool) brings 0x6007 into play at once.
  bench b(heartbeat_guarded());
  ASSERT_TRUE(b.enable_by_words());
  ASSERT_TRUE(b.carry_until(disable_voltage_word, state::switch_on_disabled));  // T9
  b.run_ms(500, /*master_alive=*/false);
  ASSERT_TRUE(b.node().connection_lost());
  ASSERT_EQ(b.drive().view().current(), state::switch_on_disabled);
  for (const std::int64_t cw : {0x06, 0x0F}) {
    ASSERT_EQ(b.node().write(0x6040, 0, cw), sdo_abort::none);
    b.run_ms(20, /*master_alive=*/false);
  }
  EXPECT_EQ(b.drive().view().current(), state::fault);
  EXPECT_EQ(b.drive().view().outputs().error_code, 0x8130);
}

class nmt_stop_of_a_drive : public ::testing::TestWithParam<bool> {};

TEST_P(nmt_stop_of_a_drive, acts_as_0x6007_says_when_enabled_and_changes_nothing_when_not) {
  // CiA 402-2 lists "NMT stopped state entered" among the events 0x6007 reacts to; PRE-OPERATIONAL
  // is not one (SDO still works, the master is there).
  const bool enabled = GetParam();
  bench b;
  const state target = enabled ? state::operation_enabled : state::ready_to_switch_on;
  if (enabled) {
    ASSERT_TRUE(b.enable_by_words());
  } else {
    ASSERT_TRUE(b.run_until_running());
    ASSERT_TRUE(b.carry_until(shutdown_word, state::ready_to_switch_on));
  }
  const auto nmt = b.bus().attach();
  (void)nmt->send(nmt_frame(nmt_command::enter_pre_operational, 1));
  b.run_ms(50, /*master_alive=*/false);
  EXPECT_FALSE(b.node().connection_lost());
  EXPECT_EQ(b.drive().view().current(), target) << "PRE-OPERATIONAL is no lost connection";
  (void)nmt->send(nmt_frame(nmt_command::stop, 1));
  b.run_ms(50, /*master_alive=*/false);
  EXPECT_EQ(b.drive().view().current(), enabled ? state::fault : state::ready_to_switch_on);
  EXPECT_EQ(b.drive().view().outputs().error_code, enabled ? 0x8130 : 0);
}

INSTANTIATE_TEST_SUITE_P(enabled_or_not, nmt_stop_of_a_drive, ::testing::Bool());

TEST(drive_master, a_master_without_guard_clears_the_guard_a_gone_master_left_and_carries_the_reset) {
  bench b(heartbeat_guarded());
  ASSERT_TRUE(enable_with_loss_reaction(b, 1));
  b.run_ms(500, /*master_alive=*/false);
  ASSERT_EQ(b.drive().view().current(), state::fault);
  b.replace_master({});
  ASSERT_TRUE(b.run_until_running(3000)) << b.master().failure_text();
  ASSERT_TRUE(b.carry_until(disable_voltage_word, state::switch_on_disabled, /*reset_edge=*/true))
      << state_name(b.master().observed());
  ASSERT_TRUE(b.enable_by_words()) << b.master().failure_text() << " " << state_name(b.master().observed());
  std::int64_t watch = -1;
  b.node().read(0x1016, 1, watch);
  EXPECT_EQ(watch, 0) << "the entry for node 127 is cleared";
  EXPECT_FALSE(b.node().connection_lost());
  b.run_ms(500);
  EXPECT_EQ(b.drive().view().current(), state::operation_enabled) << "and stays cleared";
}

TEST(drive_master, a_guard_of_another_master_is_left_alone) {
  bench b;
  ASSERT_EQ(b.node().write(0x1016, 1, (5 << 16) | 1000), sdo_abort::none);  // node 5 watched
  ASSERT_TRUE(b.run_until_running());
  b.run_ms(20);
  std::int64_t watch = 0;
  b.node().read(0x1016, 1, watch);
  EXPECT_EQ(watch, (5 << 16) | 1000);
}

TEST(drive_master, missing_node_fails_with_no_answer_naming_the_first_request) {
  drive_master_config mc;
  mc.node_id = 9;
  bench b(mc);  // the bus has node 1 only
  b.master().send_control_word(enable_operation_word);  // waits for a set-up that never ends
  b.run_ms(600);
  EXPECT_EQ(b.master().phase(), master_phase::failed);
  EXPECT_EQ(b.master().failure(), master_failure::no_answer);
  EXPECT_EQ(b.master().failed_index(), 0x1000);
  EXPECT_NE(b.master().failure_text().find("node 9 does not answer"), std::string::npos);
  EXPECT_TRUE(words_in(b.sent(), cob::rpdo1 + 9).empty()) << "no word before the set-up ended";
}

TEST(drive_master, refused_configuration_fails_with_the_abort_code) {
  drive_master_config mc;
  mc.master_heartbeat_ms = 50;
  bench b(mc);
  // Another entry already watches node 127: 0x1016 sub 1 for it is refused (0x06040043).
  ASSERT_EQ(b.node().write(0x1016, 2, (127 << 16) | 500), sdo_abort::none);
  b.master().send_control_word(shutdown_word);  // waits for the set-up, which fails
  b.run_ms(300);
  EXPECT_EQ(b.master().failure(), master_failure::sdo_refused);
  EXPECT_EQ(b.master().failed_abort(), sdo_abort::general_parameter_incompatibility);
  EXPECT_EQ(b.master().failed_index(), 0x1016);
  EXPECT_NE(b.master().failure_text().find("0x06040043"), std::string::npos);
  EXPECT_EQ(b.drive().view().current(), state::switch_on_disabled) << "nothing was started";
  EXPECT_TRUE(words_in(b.sent(), cob::rpdo1 + 1).empty()) << "the word waiting was dropped";
}

TEST(drive_master, lost_drive_heartbeat_fails_the_master) {
  bench b;
  ASSERT_TRUE(b.enable_by_words());
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

TEST(drive_master, on_change_sends_no_sync_and_starts_from_the_drives_present_values) {
  bench b(on_change_config());
  ASSERT_EQ(b.node().write(0x60FF, 0, 1234), sdo_abort::none);
  ASSERT_TRUE(run_until_running(b, 2000)) << b.master().failure_text();
  b.run_ms(50);
  const std::vector<frame> frames = b.sent();
  for (const frame& f : frames) EXPECT_NE(f.id, cob::sync) << "no SYNC with PDOs on change";
  EXPECT_TRUE(words_in(frames, cob::rpdo1 + 1).empty()) << "watching commands nothing";
  EXPECT_EQ(b.node().tpdo(0).transmission_type, 255);
  EXPECT_EQ(b.node().tpdo(1).transmission_type, 255);
  EXPECT_TRUE(b.master().velocity_mapped());
  EXPECT_TRUE(b.master().heartbeat_watched());
  EXPECT_EQ(b.master().device_name(), virtual_drive_device_name);
  EXPECT_TRUE(b.master().fault_injection()) << "a cia402 bus node's 0x2001 answers write-only";
  EXPECT_TRUE(b.master().status_known()) << "read before NMT start: no TPDO says it until it changes";
  EXPECT_EQ(b.master().observed(), state::switch_on_disabled);
  ASSERT_EQ(b.master().start_values().count(0x60FF), 1u);
  EXPECT_EQ(b.master().start_values().at(0x60FF), 1234);
  EXPECT_EQ(b.master().start_values().count(0x605A), 1u) << "the option codes are read too";
}

TEST(drive_master, words_of_its_own_go_out_at_once_and_a_state_change_arrives_unasked) {
  bench b(on_change_config());
  ASSERT_TRUE(run_until_running(b, 2000));
  (void)b.sent();
  b.master().send_control_word(0x0006);
  b.run_ms(20);
  b.master().send_control_word(0x000F);
  b.run_ms(20);
  EXPECT_EQ(b.master().observed(), state::operation_enabled);
  EXPECT_EQ(b.master().last_sent(), 0x000F);
  EXPECT_EQ(words_in(b.sent(), cob::rpdo1 + 1), (std::vector<std::uint16_t>{0x0006, 0x000F}));
}

TEST(drive_master, a_fault_reset_edge_holds_each_level_for_the_pulse_time) {
  drive_master_config mc = on_change_config();
  mc.reset_pulse_us = 20000;
  bench b(mc);
  ASSERT_TRUE(run_until_running(b, 2000));
  b.drive().view().inject_fault(0x2310);
  b.run_ms(50);
  ASSERT_EQ(b.master().observed(), state::fault);
  b.drive().view().clear_faults();
  (void)b.sent();
  b.master().send_control_word(0x0000, true);
  b.run_ms(10);
  EXPECT_EQ(words_in(b.sent(), cob::rpdo1 + 1), (std::vector<std::uint16_t>{0x0080}));
  EXPECT_TRUE(b.master().words_queued()) << "bit 7 is held for the pulse time";
  b.run_ms(15);
  EXPECT_EQ(words_in(b.sent(), cob::rpdo1 + 1), (std::vector<std::uint16_t>{0x0000}));
  EXPECT_FALSE(b.master().words_queued());
  EXPECT_EQ(b.master().observed(), state::switch_on_disabled) << "T15 on the rising edge";
  // With bit 7 still high from before, the edge starts with it low.
  b.master().send_control_word(0x0080);
  b.run_ms(5);
  (void)b.sent();
  b.master().send_control_word(0x0000, true);
  b.run_ms(60);
  EXPECT_EQ(words_in(b.sent(), cob::rpdo1 + 1), (std::vector<std::uint16_t>{0x0000, 0x0080, 0x0000}));
}

TEST(drive_master, requests_carry_the_drives_answer_and_are_refused_before_running) {
  bench b(on_change_config());
  int calls = 0;
  EXPECT_FALSE(b.master().read(0x6041, 0, false, [&](const sdo_result&) { ++calls; }))
      << "nothing is queued before set-up ended";
  ASSERT_TRUE(run_until_running(b, 2000));
  sdo_result wrote, read_back, refused;
  ASSERT_TRUE(b.master().write(0x60FF, 0, -500, 4, [&](const sdo_result& r) { wrote = r; ++calls; }));
  ASSERT_TRUE(b.master().read(0x60FF, 0, true, [&](const sdo_result& r) { read_back = r; ++calls; }));
  ASSERT_TRUE(b.master().read(0x6FFF, 0, false, [&](const sdo_result& r) { refused = r; ++calls; }));
  EXPECT_TRUE(b.master().request_pending());
  b.run_ms(20);
  EXPECT_EQ(calls, 3);
  EXPECT_FALSE(b.master().request_pending());
  EXPECT_TRUE(wrote.ok());
  EXPECT_TRUE(read_back.ok());
  EXPECT_EQ(read_back.value, -500) << "sign-extended as asked";
  EXPECT_FALSE(refused.ok());
  EXPECT_FALSE(refused.cancelled);
  EXPECT_EQ(refused.abort, sdo_abort::object_does_not_exist);
  EXPECT_EQ(b.master().phase(), master_phase::running) << "a refusal is an answer, not a lost node";
}

TEST(drive_master, a_lost_node_cancels_waiting_requests_and_set_up_retries_until_it_is_back) {
  bench b(on_change_config());
  ASSERT_TRUE(run_until_running(b, 2000));
  b.remove_drives();
  std::vector<sdo_result> results;
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(b.master().read(0x6041, 0, false, [&](const sdo_result& r) { results.push_back(r); }));
  }
  b.run_ms(600);
  ASSERT_EQ(results.size(), 2u) << "each request ends once";
  EXPECT_FALSE(results[0].ok());
  EXPECT_TRUE(results[1].cancelled);
  EXPECT_NE(b.master().phase(), master_phase::running);
  EXPECT_NE(b.master().phase_text().find("node 1 does not answer"), std::string::npos)
      << b.master().phase_text();
  b.add_drive(1);
  ASSERT_TRUE(run_until_running(b, 3000)) << b.master().phase_text();
  EXPECT_EQ(b.master().phase_text(), "");
}

TEST(drive_master, a_boot_up_message_sets_the_drive_up_again) {
  bench b(on_change_config());
  ASSERT_TRUE(run_until_running(b, 2000));
  std::vector<phase_reason> why;
  b.master().on_phase = [&](master_phase, phase_reason r) { why.push_back(r); };
  auto other = b.bus().attach();
  (void)other->send(make_frame(cob::heartbeat + 1, {0x00}));
  b.run_ms(1);
  ASSERT_FALSE(why.empty());
  EXPECT_EQ(why.front(), phase_reason::node_restarted);
  EXPECT_NE(b.master().phase_text().find("boot-up"), std::string::npos);
  ASSERT_TRUE(run_until_running(b, 2000));
  EXPECT_EQ(why.back(), phase_reason::running);
}

// A channel that fails on demand, as a socketcand connection whose server went away.
class failing_channel final : public channel {
 public:
  explicit failing_channel(channel& inner) : inner_(&inner) {}
  std::error_code send(const frame& f) noexcept override { return inner_->send(f); }
  bool receive(frame& f) noexcept override { return inner_->receive(f); }
  std::error_code failure() const noexcept override {
    return failed ? std::make_error_code(std::errc::connection_reset) : std::error_code{};
  }
  bool failed = false;

 private:
  channel* inner_;
};

TEST(drive_master, a_failed_channel_ends_the_master_for_good) {
  virtual_bus bus;
  auto ch = bus.attach();
  failing_channel out(*ch);
  drive_master m(out, on_change_config());
  (void)m.process(1000);
  out.failed = true;
  (void)m.process(1000);
  EXPECT_EQ(m.phase(), master_phase::failed);
  EXPECT_EQ(m.failure(), master_failure::bus_failed);
  EXPECT_NE(m.phase_text().find("the bus connection failed"), std::string::npos);
  for (int i = 0; i < 1000; ++i) (void)m.process(1000);
  EXPECT_EQ(m.phase(), master_phase::failed) << "no retry on a dead channel";
}

}  // namespace
}  // namespace cia402::canopen
