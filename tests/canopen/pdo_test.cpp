// PDOs: the CiA 402 default mappings, mapping changes over SDO with the CiA 301 rules and their abort
// codes, and the transmission types (synchronous 0 / 1..240, event-driven 254/255 with inhibit time
// and event timer). The node runs on the test double, so the status word comes from the core.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "network.hpp"

namespace cia402::canopen::test {
namespace {

using namespace cia402::dictionary;

constexpr std::uint8_t id = 3;

// CiA 301's order for a new mapping: the PDO made not valid (COB-ID bit 31), its mapping emptied
// (sub 0 = 0), the entries, their count, the COB-ID valid again. `write` is a fixture's SDO
// download (returns the abort code); every step must be accepted. The mapping record of a
// communication record 0x14xx/0x18xx is 0x200 above it.
template <typename Write>
void remap_pdo(Write write, std::uint16_t communication, std::uint32_t cob_id,
               const std::vector<std::uint32_t>& entries) {
  const auto mapping = static_cast<std::uint16_t>(communication + 0x200);
  ASSERT_EQ(write(communication, 1, 0x80000000u | cob_id, 4), 0u);
  ASSERT_EQ(write(mapping, 0, 0, 1), 0u);
  for (std::size_t k = 0; k < entries.size(); ++k) {
    ASSERT_EQ(write(mapping, static_cast<std::uint8_t>(k + 1), entries[k], 4), 0u) << "entry " << k + 1;
  }
  ASSERT_EQ(write(mapping, 0, static_cast<std::uint32_t>(entries.size()), 1), 0u);
  ASSERT_EQ(write(communication, 1, cob_id, 4), 0u);
}

class pdo_test : public ::testing::Test {
 protected:
  void SetUp() override {
    net.add(id);
    net.settle();
  }
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, unsigned bytes) {
    const std::uint32_t code = sdo_answer(net, id, sdo_download(id, index, sub, value, bytes));
    EXPECT_EQ(net.with_id(cob::sdo_tx + id).size(), 1u);
    return code;
  }
  void remap(std::uint16_t communication, std::uint32_t cob_id, const std::vector<std::uint32_t>& entries) {
    remap_pdo([this](auto... a) { return write(a...); }, communication, cob_id, entries);
  }
  void start() {
    net.send(nmt_frame(nmt_command::start, id));
    net.settle();
  }
  void sync() {
    net.send(make_frame(cob::sync, {}));
    net.settle();
  }
  slave& node() { return net.at(0); }
  test_device& dev() { return net.device_at(0); }

  network net;
};

TEST_F(pdo_test, defaults_are_the_cia402_predefined_set_with_pdo3_synchronous) {
  const pdo_config& r1 = node().rpdo(0);
  EXPECT_TRUE(r1.valid);
  EXPECT_EQ(r1.can_id, 0x203u);
  ASSERT_EQ(r1.count, 1);
  EXPECT_EQ(r1.map[0].index, 0x6040);
  EXPECT_EQ(r1.length, 2);
  const pdo_config& r2 = node().rpdo(1);
  EXPECT_FALSE(r2.valid) << "RPDO2 keeps CiA 402's mapping but starts not valid";
  EXPECT_EQ(r2.can_id, 0x303u);
  ASSERT_EQ(r2.count, 2);
  EXPECT_EQ(r2.map[1].index, 0x6060);
  EXPECT_EQ(r2.length, 3);
  const pdo_config& r3 = node().rpdo(2);
  EXPECT_TRUE(r3.valid);
  EXPECT_EQ(r3.can_id, 0x403u);
  EXPECT_EQ(r3.map[1].index, 0x607A) << "target position for a csp master";
  EXPECT_EQ(r3.transmission_type, 1) << "taken at the next SYNC";
  const pdo_config& r4 = node().rpdo(3);
  EXPECT_EQ(r4.can_id, 0x503u);
  EXPECT_EQ(r4.map[1].index, 0x60FF);
  EXPECT_EQ(r4.length, 6);
  EXPECT_EQ(node().tpdo(0).can_id, 0x183u);
  EXPECT_EQ(node().tpdo(0).map[0].index, 0x6041);
  EXPECT_EQ(node().tpdo(1).map[1].index, 0x6061);
  EXPECT_TRUE(node().tpdo(2).valid);
  EXPECT_EQ(node().tpdo(2).can_id, 0x383u);
  EXPECT_EQ(node().tpdo(2).map[1].index, 0x6064);
  EXPECT_EQ(node().tpdo(3).can_id, 0x483u);
  EXPECT_EQ(node().tpdo(3).map[1].index, 0x606C);
  for (int n = 0; n < 4; ++n) EXPECT_EQ(node().tpdo(n).transmission_type, n == 2 ? 1 : 255) << n;
  // The status word's event-driven TPDOs repeat within python-canopen's 0.2 s wait.
  EXPECT_EQ(node().tpdo(0).event_timer_ms, 100);
  EXPECT_EQ(node().tpdo(1).event_timer_ms, 100);
  EXPECT_EQ(node().tpdo(3).event_timer_ms, 1000);
}

TEST_F(pdo_test, an_unchanged_status_word_repeats_every_100_ms_in_tpdo1_and_tpdo2) {
  start();
  net.run(20000, 1000);
  net.received.clear();
  net.run(1000000, 1000);  // one second, nothing changes
  EXPECT_GE(net.with_id(0x183).size(), 9u);
  EXPECT_LE(net.with_id(0x183).size(), 11u);
  EXPECT_GE(net.with_id(0x283).size(), 9u);
  EXPECT_LE(net.with_id(0x283).size(), 11u);
  EXPECT_LE(net.with_id(0x483).size(), 1u) << "TPDO4 keeps its 1 s";
}

TEST_F(pdo_test, rpdo2_is_taken_only_once_a_master_makes_it_valid) {
  start();
  net.send(make_frame(0x303, {0x06, 0x00, 0x03}));  // 0x6040 = Shutdown, 0x6060 = 3
  net.run(3000, 1000);
  EXPECT_EQ(dev().control_word(), 0u) << "a frame to a PDO that is not valid is ignored";
  ASSERT_EQ(write(0x1401, 1, 0x303, 4), 0u);
  net.send(make_frame(0x303, {0x06, 0x00, 0x03}));
  net.run(3000, 1000);
  EXPECT_EQ(dev().control_word(), 6u);
}

TEST_F(pdo_test, no_pdo_flows_before_operational) {
  net.send(make_frame(0x203, {0x06, 0x00}));
  net.run(5000, 1000);
  EXPECT_EQ(dev().control_word(), 0);
  EXPECT_TRUE(net.with_id(0x183).empty());
}

TEST_F(pdo_test, event_rpdo_acts_at_once_and_event_tpdo_sends_each_new_status_word) {
  start();
  net.run(3000, 1000);  // T0, T1: SWITCH ON DISABLED
  net.received.clear();
  net.send(make_frame(0x203, {0x06, 0x00}));  // Shutdown
  net.settle();
  EXPECT_EQ(dev().control_word(), 0x0006);
  net.run(2000, 1000);
  const auto status = net.with_id(0x183);
  ASSERT_FALSE(status.empty());
  EXPECT_EQ(get_le(status.back().data.data(), 2) & 0x6F, 0x21u);  // READY TO SWITCH ON
  EXPECT_EQ(status.back().len, 2);
}

// CANopenNode's OD_requestTPDO: the node samples an event TPDO when the device reports a change
// of an object it maps (or the node wrote one), not every time it runs.
TEST_F(pdo_test, a_drive_at_rest_is_not_read_and_sends_nothing) {
  start();
  net.run(20000, 1000);  // SWITCH ON DISABLED; every TPDO sent, TPDO4 after its inhibit time
  net.received.clear();
  const int reads_before = dev().reads;
  net.run(50000, 100);  // 500 calls of process(), nothing changes
  EXPECT_EQ(dev().reads, reads_before) << "the node polled the device";
  EXPECT_TRUE(net.received.empty());
}

TEST_F(pdo_test, a_reported_change_is_sampled_and_sent_once) {
  start();
  net.run(20000, 1000);
  net.received.clear();
  const int reads_before = dev().reads;
  net.send(make_frame(0x203, {0x06, 0x00}));  // Shutdown: the status word changes at the next step
  net.run(15000, 100);  // beyond TPDO4's inhibit time of 10 ms
  const auto status = net.with_id(0x183);
  ASSERT_EQ(status.size(), 1u);
  EXPECT_EQ(get_le(status[0].data.data(), 2) & 0x6F, 0x21u);  // READY TO SWITCH ON
  // Each event-driven TPDO that maps the status word is sampled once for the change (TPDO1, 2 and
  // 4: 1 + 2 + 2 objects), none after; TPDO3 waits for a SYNC.
  int mapped = 0;
  for (int n = 0; n < pdo_count; ++n) {
    const pdo_config& t = node().tpdo(n);
    bool maps_status = false;
    for (std::uint8_t i = 0; i < t.count; ++i) maps_status |= t.map[i].index == 0x6041;
    if (t.valid && maps_status && t.transmission_type == 255) mapped += t.count;
  }
  EXPECT_EQ(mapped, 5);
  EXPECT_EQ(dev().reads - reads_before, mapped);
}

TEST_F(pdo_test, a_velocity_the_node_writes_goes_out_in_the_tpdo_that_maps_it) {
  // TPDO4 maps 0x6041 and 0x606C; the test device's 0x606C follows 0x60FF while torque is on, so
  // the change is reported by the device's write, not by a step.
  start();
  net.run(3000, 1000);
  for (const std::uint8_t cw : {0x06, 0x0F}) {
    net.send(make_frame(0x203, {cw, 0x00}));
    net.run(3000, 1000);
  }
  ASSERT_EQ(dev().current(), state::operation_enabled);
  net.received.clear();
  net.send(make_frame(0x503, {0x0F, 0x00, 0xE8, 0x03, 0x00, 0x00}));  // RPDO4: 0x6040, 0x60FF = 1000
  net.run(15000, 1000);  // TPDO4 waits out its inhibit time
  const auto velocity = net.with_id(0x483);
  ASSERT_FALSE(velocity.empty());
  EXPECT_EQ(get_le(velocity.back().data.data() + 2, 4), 1000u);
}

TEST_F(pdo_test, entering_operational_sends_every_event_tpdo_once) {
  net.run(3000, 1000);
  net.received.clear();
  start();
  net.run(100);
  EXPECT_EQ(net.with_id(0x183).size(), 1u);
  EXPECT_EQ(net.with_id(0x283).size(), 1u);
  EXPECT_EQ(net.with_id(0x483).size(), 1u);
  EXPECT_EQ(net.with_id(0x283)[0].len, 3);
  EXPECT_EQ(net.with_id(0x283)[0].data[2], 3);  // 0x6061 = pv
}

TEST_F(pdo_test, synchronous_rpdo_data_waits_for_the_next_sync) {
  ASSERT_EQ(write(0x1400, 2, 1, 1), 0u);
  start();
  net.send(make_frame(0x203, {0x06, 0x00}));
  net.settle();
  EXPECT_EQ(dev().control_word(), 0);
  sync();
  EXPECT_EQ(dev().control_word(), 0x0006);
}

TEST_F(pdo_test, tpdo_type_2_is_sent_on_every_second_sync_only) {
  ASSERT_EQ(write(0x1800, 2, 2, 1), 0u);
  start();
  net.received.clear();
  for (int i = 0; i < 6; ++i) sync();
  EXPECT_EQ(net.with_id(0x183).size(), 3u);
}

TEST_F(pdo_test, tpdo_type_0_is_sent_on_sync_only_when_its_data_changed) {
  ASSERT_EQ(write(0x1800, 2, 0, 1), 0u);
  start();
  net.run(3000, 1000);
  net.received.clear();
  sync();
  sync();
  EXPECT_EQ(net.with_id(0x183).size(), 1u);
  net.send(make_frame(0x203, {0x06, 0x00}));
  net.run(2000, 1000);
  sync();
  EXPECT_EQ(net.with_id(0x183).size(), 2u);
}

TEST_F(pdo_test, event_timer_repeats_an_unchanged_tpdo) {
  ASSERT_EQ(write(0x1800, 5, 10, 2), 0u);  // 10 ms
  start();
  net.run(3000, 1000);
  net.received.clear();
  net.run(50000, 1000);
  const auto n = net.with_id(0x183).size();
  EXPECT_GE(n, 4u);
  EXPECT_LE(n, 5u);
}

TEST_F(pdo_test, inhibit_time_holds_back_a_change_until_it_has_passed) {
  ASSERT_EQ(write(0x1800, 1, 0x80000183, 4), 0u);
  ASSERT_EQ(write(0x1800, 3, 200, 2), 0u);  // 200 x 100 us = 20 ms
  ASSERT_EQ(write(0x1800, 1, 0x183, 4), 0u);
  net.run(3000, 1000);
  start();  // TPDO1 goes at once (SWITCH ON DISABLED); the inhibit time starts
  net.received.clear();
  net.send(make_frame(0x203, {0x06, 0x00}));  // READY TO SWITCH ON 1 ms later
  net.run(19000, 1000);
  EXPECT_TRUE(net.with_id(0x183).empty());
  net.run(2000, 1000);
  const auto sent = net.with_id(0x183);
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(get_le(sent[0].data.data(), 2) & 0x6F, 0x21u);
}

TEST_F(pdo_test, changing_the_mapping_of_a_valid_pdo_aborts_with_0x06010000) {
  EXPECT_EQ(write(0x1A00, 1, 0x60410010, 4), 0x06010000u);
  EXPECT_EQ(write(0x1A00, 0, 0, 1), 0x06010000u);
  EXPECT_EQ(node().tpdo(0).count, 1) << "nothing changed";
}

TEST_F(pdo_test, changing_an_entry_while_sub0_is_not_zero_aborts_with_0x06010000) {
  ASSERT_EQ(write(0x1800, 1, 0x80000183, 4), 0u);
  EXPECT_EQ(write(0x1A00, 1, 0x60410010, 4), 0x06010000u);  // sub 0 is still 1
}

TEST_F(pdo_test, mapping_rules_give_the_standard_abort_codes) {
  ASSERT_EQ(write(0x1800, 1, 0x80000183, 4), 0u);
  ASSERT_EQ(write(0x1A00, 0, 0, 1), 0u);
  EXPECT_EQ(write(0x1A00, 1, 0x20FF0010, 4), 0x06020000u);   // no such object
  EXPECT_EQ(write(0x1A00, 1, 0x60410110, 4), 0x06090011u);   // no such sub-index
  EXPECT_EQ(write(0x1A00, 1, 0x10170010, 4), 0x06040041u);   // not mappable
  EXPECT_EQ(write(0x1A00, 1, 0x60410008, 4), 0x06040041u);   // wrong length
  EXPECT_EQ(write(0x1A00, 1, 0x20010010, 4), 0x06040041u);   // write-only into a TPDO
  EXPECT_EQ(write(0x1600 + 0, 1, 0x60410010, 4), 0x06010000u);  // RPDO1 still valid
  ASSERT_EQ(write(0x1400, 1, 0x80000203, 4), 0u);
  ASSERT_EQ(write(0x1600, 0, 0, 1), 0u);
  EXPECT_EQ(write(0x1600, 1, 0x60410010, 4), 0x06040041u);   // read-only into an RPDO
  // 3 x 32 bits = 96 > 64.
  ASSERT_EQ(write(0x1A00, 1, 0x606C0020, 4), 0u);
  ASSERT_EQ(write(0x1A00, 2, 0x606C0020, 4), 0u);
  ASSERT_EQ(write(0x1A00, 3, 0x606C0020, 4), 0u);
  EXPECT_EQ(write(0x1A00, 0, 3, 1), 0x06040042u);
  ASSERT_EQ(write(0x1A00, 3, 0, 4), 0u);
  EXPECT_EQ(write(0x1A00, 0, 3, 1), 0x06040041u) << "entry 3 is empty";
  EXPECT_EQ(write(0x1A00, 0, 2, 1), 0u);
}

TEST_F(pdo_test, cob_id_rules_give_0x06090030) {
  EXPECT_EQ(write(0x1800, 1, 0x184, 4), 0x06090030u);          // new CAN-ID while valid
  EXPECT_EQ(write(0x1800, 1, 0x00000983, 4), 0x06090030u);      // reserved bits
  ASSERT_EQ(write(0x1800, 1, 0x80000183, 4), 0u);
  EXPECT_EQ(write(0x1800, 1, 0x603, 4), 0x06090030u);           // the SDO server's identifier
  ASSERT_EQ(write(0x1A00, 0, 0, 1), 0u);
  EXPECT_EQ(write(0x1800, 1, 0x183, 4), 0x06090030u);           // enabled without a mapping
  EXPECT_EQ(write(0x1800, 2, 241, 1), 0x06090030u);             // reserved transmission type
  EXPECT_EQ(write(0x1800, 2, 252, 1), 0x06090030u);             // RTR-only: not offered
  EXPECT_EQ(write(0x1400, 2, 253, 1), 0x06090030u);
}

// A node must not be silenced by its own configuration: an identifier of its own services, or one
// another of its PDOs or SYNC uses, is refused for SYNC and for every PDO (0x06090030), and the
// node still answers SDO afterwards.
TEST_F(pdo_test, cob_ids_that_collide_with_the_nodes_own_services_are_refused) {
  const std::uint32_t own_sdo_request = 0x600 + id;
  for (const std::uint32_t taken : {own_sdo_request, 0x580u + id, 0x700u + id, 0x000u,
                                    0x203u /* RPDO1 */, 0x183u /* TPDO1 */}) {
    EXPECT_EQ(write(0x1005, 0, taken, 4), 0x06090030u) << std::hex << taken;
  }
  EXPECT_EQ(write(0x1005, 0, 0x090, 4), 0u);  // a free identifier is taken
  // PDOs: not SYNC, not the node's EMCY, not another PDO in use.
  ASSERT_EQ(write(0x1800, 1, 0x80000183, 4), 0u);
  EXPECT_EQ(write(0x1800, 1, 0x090, 4), 0x06090030u);      // now the SYNC identifier
  EXPECT_EQ(write(0x1800, 1, 0x080 + id, 4), 0x06090030u); // this node's EMCY
  EXPECT_EQ(write(0x1800, 1, 0x283, 4), 0x06090030u);      // TPDO2 sends on it
  EXPECT_EQ(write(0x1800, 1, 0x203, 4), 0x06090030u);      // RPDO1 receives on it
  EXPECT_EQ(write(0x1800, 1, 0x1F3, 4), 0u);               // free
  // Still reachable: an SDO upload is answered, not taken as SYNC.
  EXPECT_EQ(write(0x1017, 0, 100, 2), 0u);
}

TEST_F(pdo_test, inhibit_time_of_a_valid_tpdo_cannot_change) {
  EXPECT_EQ(write(0x1800, 3, 10, 2), 0x06090030u);
  ASSERT_EQ(write(0x1800, 1, 0x80000183, 4), 0u);
  EXPECT_EQ(write(0x1800, 3, 10, 2), 0u);
}

TEST_F(pdo_test, remapped_tpdo_carries_the_new_objects_in_mapping_order) {
  ASSERT_NO_FATAL_FAILURE(remap(0x1800, 0x183, {0x603F0010, 0x60410010, 0x10010008}));
  EXPECT_EQ(node().tpdo(0).length, 5);
  dev().write(0x2001, 0, 0x2310);  // fault injection
  start();
  net.run(5000, 1000);
  const auto sent = net.with_id(0x183);
  ASSERT_FALSE(sent.empty());
  const frame& last = sent.back();
  EXPECT_EQ(last.len, 5);
  EXPECT_EQ(get_le(&last.data[0], 2), 0x2310u);
  EXPECT_EQ(get_le(&last.data[2], 2) & 0x4F, 0x08u);  // FAULT
  EXPECT_EQ(last.data[4], 0x03);                      // generic + current
}

TEST_F(pdo_test, rpdo_shorter_than_its_mapping_is_dropped_with_emcy_0x8210) {
  start();
  net.received.clear();
  net.send(make_frame(0x503, {0x06, 0x00, 0x01}));  // RPDO4 needs 6 bytes
  net.settle();
  EXPECT_EQ(dev().control_word(), 0);
  const auto emcy = net.with_id(0x83);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(get_le(emcy[0].data.data(), 2), 0x8210u);
  EXPECT_EQ(emcy[0].data[2] & 0x11, 0x11);
  net.send(make_frame(0x503, {0x06, 0x00, 0x10, 0x00, 0x00, 0x00}));
  net.settle();
  EXPECT_EQ(dev().control_word(), 0x0006);
  EXPECT_EQ(dev().target_velocity(), 16);
  const auto after = net.with_id(0x83);
  ASSERT_EQ(after.size(), 2u);
  EXPECT_EQ(get_le(after[1].data.data(), 2), 0x0000u) << "error reset";
}

// CiA 301 dummy entries (issue 44): a BOOLEAN dummy (1 bit) and an UNSIGNED8 dummy (8 bits) between
// two objects. The RPDO's dummy bits are skipped whatever they hold; the TPDO sends them as zeros;
// the objects after them sit at bit 25, as the mapping puts them.
constexpr std::uint32_t boolean_dummy = 0x00010001;
constexpr std::uint32_t unsigned8_dummy = 0x00050008;

frame pdo_frame(std::uint32_t id, std::uint64_t payload) {
  frame f;
  f.id = id;
  f.len = 8;
  for (std::size_t i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(payload >> (8 * i));
  return f;
}
std::uint64_t payload_of(const frame& f) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < f.len; ++i) v |= std::uint64_t{f.data[i]} << (8 * i);
  return v;
}

TEST_F(pdo_test, dummy_entries_are_skipped_in_an_rpdo_and_sent_as_zeros_in_a_tpdo) {
  ASSERT_NO_FATAL_FAILURE(remap(0x1400, 0x203, {0x60400010, boolean_dummy, unsigned8_dummy, 0x60FF0020}));
  ASSERT_NO_FATAL_FAILURE(remap(0x1800, 0x183, {0x60410010, boolean_dummy, unsigned8_dummy, 0x606C0020}));
  EXPECT_EQ(node().rpdo(0).length, 8) << "57 bits";
  EXPECT_EQ(node().tpdo(0).length, 8);
  std::int64_t entry = 0;
  ASSERT_EQ(node().read(0x1600, 2, entry), sdo_abort::none);
  EXPECT_EQ(entry, boolean_dummy) << "the entry reads as written";
  ASSERT_EQ(node().read(0x1A00, 3, entry), sdo_abort::none);
  EXPECT_EQ(entry, unsigned8_dummy);
  start();
  net.run(3000, 1000);
  // The dummies' 9 bits (16..24) all set: nothing takes them.
  const std::uint64_t dummy_bits = std::uint64_t{0x1FF} << 16;
  const auto velocity = static_cast<std::uint32_t>(-1000);
  for (const std::uint64_t cw : {0x06u, 0x0Fu}) {
    net.send(pdo_frame(0x203, cw | dummy_bits | (std::uint64_t{velocity} << 25) | (std::uint64_t{0x7F} << 57)));
    net.run(3000, 1000);
  }
  ASSERT_EQ(dev().current(), state::operation_enabled);
  EXPECT_EQ(dev().control_word(), 0x000F);
  EXPECT_EQ(dev().target_velocity(), -1000) << "0x60FF from bit 25, sign kept";
  const auto sent = net.with_id(0x183);
  ASSERT_FALSE(sent.empty());
  EXPECT_EQ(sent.back().len, 8);
  const std::uint64_t tx = payload_of(sent.back());
  EXPECT_EQ(tx & 0x6F, 0x27u) << "OPERATION ENABLED in bits 0..15";
  EXPECT_EQ((tx >> 16) & 0x1FF, 0u) << "the dummies' bits are zeros";
  EXPECT_EQ(static_cast<std::uint32_t>(tx >> 25), velocity) << "0x606C from bit 25";
  EXPECT_EQ(tx >> 57, 0u);
}

TEST_F(pdo_test, a_dummy_of_another_length_or_sub_index_and_an_index_0_gap_are_refused) {
  ASSERT_EQ(write(0x1800, 1, 0x80000183, 4), 0u);
  ASSERT_EQ(write(0x1A00, 0, 0, 1), 0u);
  EXPECT_EQ(write(0x1A00, 1, 0x00050010, 4), 0x06040041u) << "UNSIGNED8 is 8 bits";
  EXPECT_EQ(write(0x1A00, 1, 0x00010008, 4), 0x06040041u) << "a BOOLEAN dummy is 1 bit";
  EXPECT_EQ(write(0x1A00, 1, 0x00070010, 4), 0x06040041u);
  EXPECT_EQ(write(0x1A00, 1, 0x00050108, 4), 0x06040041u) << "sub-index 1";
  EXPECT_EQ(write(0x1A00, 1, 0x00000008, 4), 0x06020000u) << "an index-0 gap is EtherCAT's, no object here";
  EXPECT_EQ(write(0x1A00, 1, 0x00040020, 4), 0u) << "INTEGER32 dummy";
  EXPECT_EQ(write(0x1A00, 2, 0x606C0020, 4), 0u);
  EXPECT_EQ(write(0x1A00, 3, boolean_dummy, 4), 0u);
  EXPECT_EQ(write(0x1A00, 0, 3, 1), 0x06040042u) << "65 bits: a dummy counts in the 64";
  EXPECT_EQ(write(0x1A00, 0, 2, 1), 0u);
}

// Objects with sub-indices map as (index, sub): a device that holds an array (as the virtual drive
// holds 0x607D, 0x6099) is read and written with the sub-index the mapping entry names.
class array_device final : public dictionary::device {
 public:
  static constexpr std::uint16_t index = 0x2100;
  sdo_abort read(std::uint16_t i, std::uint8_t sub, std::int64_t& v) noexcept override {
    if (i != index) return sdo_abort::object_does_not_exist;
    if (sub < 1 || sub > 2) return sdo_abort::sub_index_does_not_exist;
    v = values[sub - 1];
    return sdo_abort::none;
  }
  sdo_abort write(std::uint16_t i, std::uint8_t sub, std::int64_t v) noexcept override {
    if (i != index) return sdo_abort::object_does_not_exist;
    if (sub < 1 || sub > 2) return sdo_abort::sub_index_does_not_exist;
    values[sub - 1] = v;
    return sdo_abort::none;
  }
  std::uint32_t step(std::uint32_t) noexcept override { return 1000; }
  void set_connection_lost(bool) noexcept override {}
  void reset() noexcept override {}
  void report(std::uint8_t sub) noexcept { changed(index, sub); }
  std::int64_t values[2] = {0, 0};
};

class pdo_sub_index_test : public ::testing::Test {
 protected:
  void SetUp() override {
    slave_config c = apps::drive_node_config(id);
    object_entry pair;
    pair.index = array_device::index;
    pair.name = "Pair";
    pair.code = object_code::array;
    sub_entry count;
    count.name = "Highest sub-index supported";
    count.default_value = 2;
    pair.subs.push_back(count);
    for (std::uint8_t sub = 1; sub <= 2; ++sub) {
      sub_entry e;
      e.sub = sub;
      e.name = "Value " + std::to_string(sub);
      e.type = data_type::integer32;
      e.acc = access::rw;
      e.pdo_mappable = true;
      e.where = backing::device;
      if (sub == 1) {  // a limit of the dictionary's own: the device takes any value
        e.has_limits = true;
        e.low = -20000;
        e.high = 20000;
      }
      pair.subs.push_back(e);
    }
    c.objects.push_back(pair);
    ch = bus.attach();
    tester = bus.attach();
    node = std::make_unique<slave>(dev, *ch, c);
    settle();
  }
  void settle() {
    for (int i = 0; i < 4; ++i) node->poll(*ch, 0);
    frame f;
    while (tester->receive(f)) received.push_back(f);
  }
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, unsigned bytes) {
    received.clear();
    EXPECT_FALSE(tester->send(sdo_download(id, index, sub, value, bytes)));
    settle();
    for (const frame& f : received) {
      if (f.id == cob::sdo_tx + id) return abort_code_of(f);
    }
    return 0xFFFFFFFFu;
  }
  void remap(std::uint16_t communication, std::uint32_t cob_id, const std::vector<std::uint32_t>& entries) {
    remap_pdo([this](auto... a) { return write(a...); }, communication, cob_id, entries);
  }
  std::vector<frame> with_id(std::uint32_t can_id) const {
    std::vector<frame> out;
    for (const frame& f : received) {
      if (f.id == can_id) out.push_back(f);
    }
    return out;
  }

  virtual_bus bus;
  array_device dev;
  std::unique_ptr<virtual_channel> ch;
  std::unique_ptr<virtual_channel> tester;
  std::unique_ptr<slave> node;
  std::vector<frame> received;
};

TEST_F(pdo_sub_index_test, a_mapped_sub_index_is_sampled_and_written_with_its_sub) {
  // TPDO4 = 0x2100 sub 2, synchronous; RPDO4 = 0x2100 sub 1, on receipt.
  ASSERT_NO_FATAL_FAILURE(remap(0x1803, 0x483, {0x21000220}));
  ASSERT_EQ(write(0x1803, 2, 1, 1), 0u);
  ASSERT_EQ(write(0x1403, 1, 0x80000503, 4), 0u);
  ASSERT_EQ(write(0x1603, 0, 0, 1), 0u);
  EXPECT_EQ(write(0x1603, 1, 0x21000320, 4), 0x06090011u) << "no sub-index 3";
  ASSERT_EQ(write(0x1603, 1, 0x21000120, 4), 0u);
  ASSERT_EQ(write(0x1603, 0, 1, 1), 0u);
  ASSERT_EQ(write(0x1403, 1, 0x503, 4), 0u);
  EXPECT_EQ(node->tpdo(3).map[0].sub, 2);
  EXPECT_EQ(node->rpdo(3).map[0].sub, 1);

  EXPECT_FALSE(tester->send(nmt_frame(nmt_command::start, id)));
  settle();
  dev.values[1] = -123456;
  received.clear();
  EXPECT_FALSE(tester->send(make_frame(cob::sync, {})));
  settle();
  const auto sent = with_id(0x483);
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(sent[0].len, 4);
  EXPECT_EQ(static_cast<std::int32_t>(get_le(sent[0].data.data(), 4)), -123456);

  EXPECT_FALSE(tester->send(make_frame(0x503, {0x39, 0x30, 0x00, 0x00})));  // 12345
  settle();
  EXPECT_EQ(dev.values[0], 12345);
  EXPECT_EQ(dev.values[1], -123456) << "sub 2 untouched";
}

// A PDO writes through the slot its mapping was bound to with the rules of an SDO write: a value
// beyond the entry's limits is dropped (a PDO has no answer to carry the abort code).
TEST_F(pdo_sub_index_test, an_rpdo_value_beyond_the_dictionarys_limit_is_dropped_as_an_sdo_write_is_refused) {
  ASSERT_NO_FATAL_FAILURE(remap(0x1403, 0x503, {0x21000120}));
  EXPECT_FALSE(tester->send(nmt_frame(nmt_command::start, id)));
  settle();
  EXPECT_FALSE(tester->send(make_frame(0x503, {0x10, 0x27, 0x00, 0x00})));  // 10000
  settle();
  EXPECT_EQ(dev.values[0], 10000);
  EXPECT_FALSE(tester->send(make_frame(0x503, {0x30, 0x75, 0x00, 0x00})));  // 30000
  settle();
  EXPECT_EQ(dev.values[0], 10000) << "above the entry's limit";
  EXPECT_EQ(write(0x2100, 1, 30000, 4), 0x06090031u) << "as an SDO write is refused";
}

}  // namespace
}  // namespace cia402::canopen::test
