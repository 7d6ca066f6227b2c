// NMT slave (boot-up, states, reset node / communication), heartbeat producer and consumer with
// 0x6007 (S10), and EMCY on every fault and on its reset.
#include <gtest/gtest.h>

#include "network.hpp"

namespace cia402::canopen::test {
namespace {

using namespace cia402::dictionary;

constexpr std::uint8_t id = 7;

std::uint16_t emcy_code(const frame& f) { return static_cast<std::uint16_t>(get_le(f.data.data(), 2)); }

class nmt_test : public ::testing::Test {
 protected:
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t command) {
    return sdo_answer(net, id, sdo_request(id, command, index, sub, value));
  }
  network net;
};

TEST_F(nmt_test, power_on_sends_boot_up_then_node_is_pre_operational) {
  slave& s = net.add(id);
  net.drain();
  ASSERT_EQ(net.received.size(), 1u);
  EXPECT_EQ(net.received[0].id, 0x707u);
  EXPECT_EQ(net.received[0].len, 1);
  EXPECT_EQ(net.received[0].data[0], 0x00);
  EXPECT_EQ(s.state(), nmt_state::pre_operational);
}

TEST_F(nmt_test, nmt_commands_move_between_states_and_node_zero_addresses_all) {
  slave& s = net.add(id);
  slave& other = net.add(id + 1);
  net.send(nmt_frame(nmt_command::start, id));
  net.settle();
  EXPECT_EQ(s.state(), nmt_state::operational);
  EXPECT_EQ(other.state(), nmt_state::pre_operational);
  net.send(nmt_frame(nmt_command::stop, 0));
  net.settle();
  EXPECT_EQ(s.state(), nmt_state::stopped);
  EXPECT_EQ(other.state(), nmt_state::stopped);
  net.send(nmt_frame(nmt_command::enter_pre_operational, id + 1));
  net.settle();
  EXPECT_EQ(other.state(), nmt_state::pre_operational);
  EXPECT_EQ(s.state(), nmt_state::stopped);
}

TEST_F(nmt_test, unknown_nmt_command_and_short_frame_change_nothing) {
  slave& s = net.add(id);
  net.send(make_frame(0, {0x55, id}));
  net.send(make_frame(0, {0x01}));
  net.settle();
  EXPECT_EQ(s.state(), nmt_state::pre_operational);
}

TEST_F(nmt_test, heartbeat_producer_sends_the_state_every_0x1017_ms) {
  net.add(id);
  ASSERT_EQ(write(0x1017, 0, 50, 0x2B), 0u);
  net.received.clear();
  net.run(200000, 1000);
  auto hb = net.with_id(0x707);
  ASSERT_EQ(hb.size(), 4u);
  EXPECT_EQ(hb[0].data[0], 0x7F);  // pre-operational
  net.send(nmt_frame(nmt_command::stop, id));
  net.received.clear();
  net.run(50000, 1000);
  hb = net.with_id(0x707);
  ASSERT_EQ(hb.size(), 1u);
  EXPECT_EQ(hb[0].data[0], 0x04);  // stopped: heartbeats go on
}

TEST_F(nmt_test, heartbeat_time_from_the_config_survives_reset_communication) {
  slave& s = net.add(id, nullptr, 100);
  ASSERT_EQ(write(0x1017, 0, 10, 0x2B), 0u);
  net.send(nmt_frame(nmt_command::reset_communication, id));
  net.settle();
  std::int64_t v = 0;
  s.read(0x1017, 0, v);
  EXPECT_EQ(v, 100);
}

TEST_F(nmt_test, reset_communication_restores_pdo_parameters_and_sends_boot_up) {
  slave& s = net.add(id);
  ASSERT_EQ(write(0x1800, 2, 1, 0x2F), 0u);
  net.send(nmt_frame(nmt_command::start, id));
  net.received.clear();
  net.send(nmt_frame(nmt_command::reset_communication, id));
  net.settle();
  EXPECT_EQ(s.tpdo(0).transmission_type, 255);
  EXPECT_EQ(s.state(), nmt_state::pre_operational);
  ASSERT_FALSE(net.with_id(0x707).empty());
  EXPECT_EQ(net.with_id(0x707)[0].data[0], 0x00);
  EXPECT_EQ(net.device_at(0).resets, 0) << "communication only";
}

TEST_F(nmt_test, reset_node_restarts_the_device_and_every_object) {
  slave& s = net.add(id);
  ASSERT_EQ(write(0x605A, 0, 6, 0x2B), 0u);
  ASSERT_EQ(write(0x2000, 0, 0x00636261, 0x27), 0u);  // "abc"
  net.send(nmt_frame(nmt_command::reset_node, id));
  net.settle();
  EXPECT_EQ(net.device_at(0).resets, 1);
  std::int64_t v = 0;
  s.read(0x605A, 0, v);
  EXPECT_EQ(v, 2);
  std::vector<std::uint8_t> label;
  s.read_bytes(0x2000, 0, label);
  EXPECT_TRUE(label.empty());
}

TEST_F(nmt_test, fault_sends_emcy_with_code_register_and_status_then_reset_sends_0x0000) {
  net.add(id);
  net.run(3000, 1000);
  net.received.clear();
  ASSERT_EQ(write(0x2001, 0, 0x4310, 0x2B), 0u);  // over-temperature
  net.run(3000, 1000);
  auto emcy = net.with_id(0x87);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].len, 8);
  EXPECT_EQ(emcy_code(emcy[0]), 0x4310);
  EXPECT_EQ(emcy[0].data[2], 0x09);  // generic + temperature
  EXPECT_EQ(get_le(&emcy[0].data[3], 2) & 0x4F, 0x0Fu);  // FAULT REACTION ACTIVE when it happened
  EXPECT_EQ(emcy[0].data[5] | emcy[0].data[6] | emcy[0].data[7], 0);
  // Cause gone, fault reset edge: T15 clears 0x603F -> EMCY 0x0000.
  ASSERT_EQ(write(0x2001, 0, 0, 0x2B), 0u);
  ASSERT_EQ(write(0x6040, 0, 0x00, 0x2B), 0u);
  net.run(2000, 1000);
  ASSERT_EQ(write(0x6040, 0, 0x80, 0x2B), 0u);
  net.run(2000, 1000);
  emcy = net.with_id(0x87);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy_code(emcy[0]), 0x0000);
  EXPECT_EQ(emcy[0].data[2], 0x00);
  EXPECT_EQ(net.device_at(0).current(), state::switch_on_disabled);
}

TEST_F(nmt_test, no_emcy_while_stopped) {
  net.add(id);
  net.send(nmt_frame(nmt_command::stop, id));
  net.settle();
  net.device_at(0).write(0x2001, 0, 0x2310);  // fault injection
  net.received.clear();
  net.run(5000, 1000);
  EXPECT_TRUE(net.with_id(0x87).empty());
}

// 0x1003 (CiA 301 §7.5.2.5): the errors the node signalled, newest first, read by SDO uploads.
class error_history_test : public nmt_test {
 protected:
  std::uint32_t read(std::uint8_t sub) {
    net.received.clear();
    net.send(sdo_request(id, 0x40, 0x1003, sub));
    net.settle();
    const auto r = net.with_id(cob::sdo_tx + id);
    EXPECT_FALSE(r.empty());
    if (r.empty()) return 0xDEADBEEF;
    EXPECT_EQ(abort_code_of(r.back()), 0u) << "0x1003:" << int(sub);
    return static_cast<std::uint32_t>(get_le(&r.back().data[4], 4));
  }
  void fault(std::uint16_t code) {
    ASSERT_EQ(write(0x2001, 0, code, 0x2B), 0u);
    net.run(3000, 1000);
    ASSERT_EQ(write(0x2001, 0, 0, 0x2B), 0u);
    ASSERT_EQ(write(0x6040, 0, 0x80, 0x2B), 0u);  // fault reset
    net.run(3000, 1000);
    ASSERT_EQ(write(0x6040, 0, 0x00, 0x2B), 0u);
    net.run(3000, 1000);
  }
};

TEST_F(error_history_test, faults_are_kept_newest_first_with_the_status_word_above_the_code) {
  net.add(id);
  EXPECT_EQ(read(0), 0u) << "no error yet";
  fault(0x2310);
  fault(0x3220);
  ASSERT_EQ(read(0), 2u);
  EXPECT_EQ(read(1) & 0xFFFF, 0x3220u);
  EXPECT_EQ(read(2) & 0xFFFF, 0x2310u);
  EXPECT_EQ((read(1) >> 16) & 0x08, 0x08u) << "the status word at the EMCY, its fault bit 3 set";
  EXPECT_EQ(read(3), 0u) << "an empty entry reads 0";
}

TEST_F(error_history_test, holds_the_newest_8_and_writing_0_to_sub_0_clears_it) {
  net.add(id);
  for (std::uint16_t code = 0x1001; code <= 0x100A; ++code) fault(code);
  EXPECT_EQ(read(0), 8u);
  EXPECT_EQ(read(1) & 0xFFFF, 0x100Au);
  EXPECT_EQ(read(8) & 0xFFFF, 0x1003u) << "0x1001 and 0x1002 were dropped";
  EXPECT_EQ(write(0x1003, 0, 1, 0x2F), 0x06090030u) << "only 0 may be written to sub 0";
  EXPECT_EQ(read(0), 8u) << "refused: nothing changed";
  EXPECT_EQ(write(0x1003, 1, 0, 0x23), 0x06010002u) << "the entries are read-only";
  EXPECT_EQ(write(0x1003, 0, 0, 0x2F), 0u);
  EXPECT_EQ(read(0), 0u);
  EXPECT_EQ(read(1), 0u);
}

TEST_F(error_history_test, the_nodes_own_errors_go_in_too_and_a_reset_node_empties_it) {
  net.add(id);
  ASSERT_EQ(write(0x1016, 1, 0x00200064, 0x23), 0u);
  net.send(heartbeat_frame(0x20, nmt_state::operational));
  net.run(150000, 1000);
  ASSERT_TRUE(net.at(0).connection_lost());
  EXPECT_GE(read(0), 1u);
  EXPECT_EQ(read(read(0)) & 0xFFFF, 0x8130u) << "the heartbeat loss, the node's own error, is the oldest";
  net.send(nmt_frame(nmt_command::reset_node, id));
  net.settle();
  EXPECT_EQ(read(0), 0u);
}

// Heartbeat consumer: node 0x20 plays the master; the drive watches it for 100 ms.
class heartbeat_loss : public nmt_test, public ::testing::WithParamInterface<int> {};

TEST_P(heartbeat_loss, lost_master_heartbeat_applies_0x6007) {
  const int code = GetParam();
  net.add(id);
  ASSERT_EQ(write(0x6007, 0, static_cast<std::uint32_t>(code), 0x2B), 0u);
  ASSERT_EQ(write(0x1016, 1, 0x00200064, 0x23), 0u);
  // Bring the drive to OPERATION ENABLED with SDO writes of the control word.
  for (std::uint32_t cw : {0x06u, 0x0Fu}) {
    ASSERT_EQ(write(0x6040, 0, cw, 0x2B), 0u);
    net.run(3000, 1000);
  }
  ASSERT_EQ(net.device_at(0).current(), state::operation_enabled);
  for (int i = 0; i < 5; ++i) {
    net.send(heartbeat_frame(0x20, nmt_state::operational));
    net.run(50000, 1000);
  }
  EXPECT_FALSE(net.at(0).connection_lost()) << "heartbeats every 50 ms keep the 100 ms watch happy";
  net.received.clear();
  net.run(101000, 1000);
  EXPECT_TRUE(net.at(0).connection_lost());
  EXPECT_TRUE(net.device_at(0).connection_lost);
  net.run(5000, 1000);
  const auto emcy = net.with_id(0x87);
  ASSERT_FALSE(emcy.empty());
  EXPECT_EQ(emcy_code(emcy[0]), 0x8130);  // the consumer's own event
  EXPECT_EQ(emcy[0].data[2] & 0x11, 0x11);
  const state expected[4] = {state::operation_enabled, state::fault, state::switch_on_disabled,
                             state::switch_on_disabled};  // 3: quick stop (0x605A = 2) then T12
  EXPECT_EQ(net.device_at(0).current(), expected[code]);
  if (code == 1) {
    ASSERT_EQ(emcy.size(), 2u);
    EXPECT_EQ(emcy_code(emcy[1]), 0x8130);  // the drive's fault (S10)
  }
  // The master comes back: the loss clears.
  net.send(heartbeat_frame(0x20, nmt_state::operational));
  net.settle();
  EXPECT_FALSE(net.at(0).connection_lost());
  EXPECT_FALSE(net.device_at(0).connection_lost);
}

INSTANTIATE_TEST_SUITE_P(abort_connection_codes, heartbeat_loss, ::testing::Values(0, 1, 2, 3));

TEST_F(nmt_test, consumer_watches_nothing_before_the_first_heartbeat) {
  net.add(id);
  ASSERT_EQ(write(0x1016, 1, 0x00200064, 0x23), 0u);
  net.run(500000, 10000);
  EXPECT_FALSE(net.at(0).connection_lost());
}

}  // namespace
}  // namespace cia402::canopen::test
