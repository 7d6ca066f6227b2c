// The operation modes over the virtual CAN bus, frame by frame as any CANopen master sends them: the
// mode switched by SDO and by RPDO2 (0x6040 + 0x6060), a profile position move with its set-point
// handshake (bits 4 / 12 / 10), homing methods 37 and 3 ending at the home offset, a cyclic
// synchronous position stream in RPDO3 (0x6040 + 0x607A) on SYNC read back by TPDO3 (0x6041 +
// 0x6064); objects with sub-indices by SDO; and the drive master's own PDO 3 (map_position).
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "cia402/canopen/master/drive_master.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "carried_words.hpp"
#include "network.hpp"

namespace cia402::canopen {
namespace {

using test::abort_code_of;
using test::sdo_request;

constexpr std::uint8_t id = 1;
constexpr std::uint32_t rpdo1 = 0x200 + id, rpdo2 = 0x300 + id, rpdo3 = 0x400 + id;
constexpr std::uint32_t tpdo1 = 0x180 + id, tpdo2 = 0x280 + id, tpdo3 = 0x380 + id;
constexpr std::uint16_t bit10 = 1u << 10, bit12 = 1u << 12, bit13 = 1u << 13;

class modes_test : public ::testing::Test {
 protected:
  void SetUp() override {
    node_ = std::make_unique<apps::virtual_drive_node>(standard_profile(), bus_.attach(), apps::drive_node_config(id));
    tester_ = bus_.attach();
    run_ms(10);  // power-up
    send(nmt_frame(nmt_command::start, id));
    settle();
  }

  void send(const frame& f) { ASSERT_FALSE(tester_->send(f)); }
  void send(std::uint32_t can_id, std::vector<std::uint8_t> data) {
    frame f;
    f.id = can_id;
    f.len = static_cast<std::uint8_t>(data.size());
    for (std::size_t i = 0; i < data.size(); ++i) f.data[i] = data[i];
    send(f);
  }
  void settle() {
    node_->poll(0);
    drain();
  }
  void drain() {
    frame f;
    while (tester_->receive(f)) {
      if (f.id == tpdo1 && f.len >= 2) status_words.push_back(static_cast<std::uint16_t>(get_le(f.data.data(), 2)));
      received.push_back(f);
    }
  }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      node_->poll(1000);
      drain();
    }
  }
  /// Runs until a status word (TPDO1) satisfies `ok`, at most `ms`; the word, or nullopt.
  std::optional<std::uint16_t> run_until_status(const std::function<bool(std::uint16_t)>& ok, int ms) {
    std::size_t seen = status_words.size();
    for (int i = 0; i <= ms; ++i) {
      for (; seen < status_words.size(); ++seen) {
        if (ok(status_words[seen])) return status_words[seen];
      }
      run_ms(1);
    }
    return std::nullopt;
  }
  /// An expedited SDO download; the abort code, 0 when done.
  std::uint32_t sdo_write(std::uint16_t index, std::uint8_t sub, std::int64_t value, unsigned bytes) {
    received.clear();
    send(test::sdo_download(id, index, sub, static_cast<std::uint32_t>(value), bytes));
    settle();
    for (const frame& f : received) {
      if (f.id == cob::sdo_tx + id) return f.data[0] == 0x60 ? 0 : abort_code_of(f);
    }
    ADD_FAILURE() << "no SDO answer";
    return 0xFFFFFFFFu;
  }
  /// An expedited SDO upload of a 32-bit signed value (or narrower, sign-extended by `bytes`).
  std::int64_t sdo_read(std::uint16_t index, std::uint8_t sub, unsigned bytes = 4) {
    received.clear();
    send(sdo_request(id, 0x40, index, sub));
    settle();
    for (const frame& f : received) {
      if (f.id != cob::sdo_tx + id) continue;
      EXPECT_EQ(f.data[0] & 0xE3, 0x43) << "expedited upload with size";
      const std::uint64_t raw = get_le(&f.data[4], bytes);
      const std::uint64_t sign = 1ull << (8 * bytes - 1);
      return static_cast<std::int64_t>((raw ^ sign) - sign);
    }
    ADD_FAILURE() << "no SDO answer";
    return 0;
  }
  /// SYNC; 0x6064 from the TPDO3 it brings.
  std::int32_t position_on_sync() {
    received.clear();
    send(make_frame(cob::sync, {}));
    settle();
    for (const frame& f : received) {
      if (f.id == tpdo3 && f.len == 6) return static_cast<std::int32_t>(get_le(&f.data[2], 4));
    }
    ADD_FAILURE() << "no TPDO3 after SYNC";
    return 0;
  }
  void enable() {
    send(rpdo1, {0x06, 0x00});
    run_ms(20);
    send(rpdo1, {0x0F, 0x00});
    ASSERT_TRUE(run_until_status([](std::uint16_t w) { return (w & 0x6F) == 0x27; }, 200)) << "not enabled";
    run_ms(50);  // the holding brake opens
  }

  virtual_bus bus_;
  std::unique_ptr<apps::virtual_drive_node> node_;
  std::unique_ptr<virtual_channel> tester_;
  std::vector<frame> received;
  std::vector<std::uint16_t> status_words;
};

TEST_F(modes_test, mode_switches_by_sdo_and_by_rpdo2_and_0x6061_follows) {
  EXPECT_EQ(sdo_read(0x6502, 0), 0x3AD);
  ASSERT_EQ(sdo_write(0x6060, 0, 1, 1), 0u);
  run_ms(2);
  EXPECT_EQ(sdo_read(0x6061, 0, 1), 1);
  EXPECT_EQ(static_cast<std::uint32_t>(sdo_read(0x1401, 1)), 0x80000000u + rpdo2) << "RPDO2 starts not valid";
  ASSERT_EQ(sdo_write(0x1401, 1, rpdo2, 4), 0u);  // a master that wants RPDO2 makes it valid
  received.clear();
  send(rpdo2, {0x00, 0x00, 8});  // RPDO2 = 0x6040 + 0x6060, on receipt
  run_ms(2);
  bool shown = false;
  for (const frame& f : received) shown = shown || (f.id == tpdo2 && f.len == 3 && f.data[2] == 8);
  EXPECT_TRUE(shown) << "TPDO2 (0x6041 + 0x6061) shows csp";
  EXPECT_EQ(sdo_read(0x6061, 0, 1), 8);
  EXPECT_EQ(sdo_write(0x6060, 0, 2, 1), 0x06090030u) << "vl is not among 0x6502's modes";
  EXPECT_EQ(sdo_read(0x6060, 0, 1), 8);
}

TEST_F(modes_test, pp_move_acknowledges_the_set_point_then_reaches_the_target) {
  ASSERT_EQ(sdo_write(0x6060, 0, 1, 1), 0u);
  ASSERT_EQ(sdo_write(0x6081, 0, 600, 4), 0u);
  enable();
  ASSERT_EQ(sdo_write(0x607A, 0, 20000, 4), 0u);
  send(rpdo1, {0x1F, 0x00});  // bit 4: new set-point
  const auto ack = run_until_status([](std::uint16_t w) { return (w & bit12) != 0; }, 50);
  ASSERT_TRUE(ack) << "no set-point acknowledge";
  EXPECT_EQ(*ack & bit10, 0) << "moving: not at the target";
  send(rpdo1, {0x0F, 0x00});  // bit 4 down: bit 12 follows it
  const auto reached = run_until_status([](std::uint16_t w) { return (w & bit10) != 0; }, 3000);
  ASSERT_TRUE(reached) << "no target reached";
  EXPECT_EQ(*reached & bit12, 0);
  EXPECT_EQ(*reached & bit13, 0) << "no following error";
  EXPECT_EQ(position_on_sync(), 20000);
  EXPECT_EQ(sdo_read(0x6064, 0), 20000);
  // Relative (bit 6): adds to the last target.
  ASSERT_EQ(sdo_write(0x607A, 0, -5000, 4), 0u);
  send(rpdo1, {0x5F, 0x00});
  ASSERT_TRUE(run_until_status([](std::uint16_t w) { return (w & bit12) != 0; }, 50));
  send(rpdo1, {0x4F, 0x00});
  ASSERT_TRUE(run_until_status([](std::uint16_t w) { return (w & (bit10 | bit12)) == bit10; }, 3000));
  EXPECT_EQ(position_on_sync(), 15000);
}

TEST_F(modes_test, homing_37_and_3_end_at_the_home_offset_with_bits_12_and_10) {
  ASSERT_EQ(sdo_write(0x1401, 1, rpdo2, 4), 0u);  // RPDO2 made valid
  for (const int method : {37, 3}) {
    SCOPED_TRACE(method);
    send(rpdo2, {0x00, 0x00, 6});  // homing, by RPDO2
    ASSERT_EQ(sdo_write(0x6098, 0, method, 1), 0u);
    ASSERT_EQ(sdo_write(0x607C, 0, 4321, 4), 0u);
    enable();
    EXPECT_EQ(sdo_read(0x6061, 0, 1), 6);
    send(rpdo1, {0x1F, 0x00});  // bit 4: homing operation start
    const auto ended = run_until_status(
        [](std::uint16_t w) { return (w & bit13) != 0 || (w & (bit10 | bit12)) == (bit10 | bit12); }, 20000);
    ASSERT_TRUE(ended) << "homing did not end";
    EXPECT_EQ(*ended & bit13, 0) << "no homing error";
    EXPECT_EQ(position_on_sync(), 4321);
    send(rpdo1, {0x06, 0x00});  // back to READY TO SWITCH ON for the next method
    run_ms(50);
  }
}

TEST_F(modes_test, csp_stream_in_rpdo3_is_followed_sync_by_sync) {
  ASSERT_EQ(sdo_write(0x6060, 0, 8, 1), 0u);  // csp
  run_ms(2);
  const std::int32_t start = static_cast<std::int32_t>(sdo_read(0x6064, 0));
  ASSERT_EQ(sdo_write(0x607A, 0, start, 4), 0u);
  enable();
  std::int32_t previous = start;
  std::int32_t target = start;
  for (int k = 1; k <= 200; ++k) {
    target = start + 50 * k;  // 300 rpm at 10,000 increments a revolution and 1 ms a SYNC
    const std::int32_t t = target;
    send(rpdo3, {0x0F, 0x00, static_cast<std::uint8_t>(t), static_cast<std::uint8_t>(t >> 8),
                 static_cast<std::uint8_t>(t >> 16), static_cast<std::uint8_t>(t >> 24)});
    settle();
    // The position at this SYNC is the set-point of the one before: one cycle to reach it.
    EXPECT_EQ(position_on_sync(), previous) << k;
    previous = target;
    run_ms(1);
  }
  EXPECT_EQ(position_on_sync(), target);
  const auto sw = static_cast<std::uint16_t>(sdo_read(0x6041, 0, 2));
  EXPECT_NE(sw & bit12, 0) << "the drive follows the command value";
  EXPECT_EQ(sw & bit13, 0) << "no following error";
  EXPECT_EQ(sdo_read(0x60F4, 0), 0);
}

TEST_F(modes_test, rpdo3_data_waits_for_sync) {
  const std::int32_t before = static_cast<std::int32_t>(sdo_read(0x607A, 0));
  send(rpdo3, {0x00, 0x00, 0x10, 0x27, 0x00, 0x00});  // 10,000
  run_ms(5);
  EXPECT_EQ(sdo_read(0x607A, 0), before) << "RPDO3 is synchronous: nothing before the SYNC";
  (void)position_on_sync();
  EXPECT_EQ(sdo_read(0x607A, 0), 10000);
}

TEST_F(modes_test, objects_with_sub_indices_go_through_sdo_to_the_drive) {
  EXPECT_EQ(sdo_read(0x607D, 0, 1), 2) << "sub 0: the count";
  ASSERT_EQ(sdo_write(0x607D, 1, -50000, 4), 0u);
  ASSERT_EQ(sdo_write(0x607D, 2, 50000, 4), 0u);
  EXPECT_EQ(sdo_read(0x607D, 1), -50000);
  EXPECT_EQ(sdo_read(0x607D, 2), 50000);
  std::int64_t v = 0;
  ASSERT_EQ(node_->drive().read(0x607D, 1, v), sdo_abort::none);
  EXPECT_EQ(v, -50000) << "the drive holds it, not the dictionary";
  ASSERT_EQ(sdo_write(0x6099, 1, 700, 4), 0u);
  EXPECT_EQ(sdo_read(0x6099, 1), 700);
  EXPECT_EQ(sdo_read(0x608F, 1), 10000);
  EXPECT_EQ(sdo_write(0x607D, 3, 0, 4), 0x06090011u) << "no sub-index 3";
}

// The drive master with PDO 3 mapped and a virtual drive on one in-process bus, SYNC every cycle_us;
// run_ms() steps both a millisecond at a time, each seeing what the other sent in the same step.
struct pdo3_bench {
  explicit pdo3_bench(std::uint32_t cycle_us)
      : drive(standard_profile(), bus.attach(), apps::drive_node_config(id)), ch(bus.attach()),
        m(*ch, config(cycle_us)) {}
  static drive_master_config config(std::uint32_t cycle_us) {
    drive_master_config mc;
    mc.cycle_us = cycle_us;
    mc.map_position = true;
    return mc;
  }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      m.poll(*ch, 1000);
      drive.poll(1000);
      m.poll(*ch, 0);
      drive.poll(0);
      m.poll(*ch, 0);
    }
  }
  // Set up, in OPERATION ENABLED in `mode` with the set-point at 0: the words of T2, T3 and T4,
  // each carried in RPDO1 (or RPDO3 with a new set-point) until the status word shows its state.
  void enable_in(std::int64_t mode) {
    run_ms(100);
    ASSERT_EQ(m.phase(), master_phase::running) << m.failure_text();
    ASSERT_EQ(drive.drive().write(0x6060, 0, mode), sdo_abort::none);
    m.set_position_set_point(0);
    const std::pair<std::uint16_t, state> steps[] = {{test::shutdown_word, state::ready_to_switch_on},
                                                     {test::switch_on_word, state::switched_on},
                                                     {test::enable_operation_word, state::operation_enabled}};
    for (const auto& [word, reached] : steps) {
      m.send_control_word(word);
      for (int i = 0; i < 300 && m.observed() != reached; ++i) run_ms(1);
      ASSERT_EQ(m.observed(), reached) << "after 0x" << std::hex << word;
    }
  }
  virtual_bus bus;
  apps::virtual_drive_node drive;
  std::unique_ptr<channel> ch;
  drive_master m;
};

// The drive master's PDO 3: set up over SDO, a set-point in RPDO3 before every SYNC, the position
// from TPDO3.
TEST(modes_master, map_position_streams_rpdo3_and_reads_tpdo3) {
  pdo3_bench b(1000);
  drive_master& m = b.m;
  b.run_ms(100);
  ASSERT_EQ(m.phase(), master_phase::running) << m.failure_text();
  EXPECT_TRUE(m.position_mapped());
  ASSERT_TRUE(m.position().has_value());
  EXPECT_EQ(*m.position(), 0);
  ASSERT_NO_FATAL_FAILURE(b.enable_in(8));  // cyclic synchronous position
  b.run_ms(50);
  std::int32_t sp = 0;
  m.before_sync = [&] {
    if (sp < 5000) sp += 25;
    m.set_position_set_point(sp);
  };
  b.run_ms(250);
  EXPECT_EQ(sp, 5000);
  EXPECT_EQ(*m.position(), 5000);
  std::int64_t v = 0;
  ASSERT_EQ(b.drive.drive().read(0x6064, 0, v), sdo_abort::none);
  EXPECT_EQ(v, 5000);
  EXPECT_EQ(m.status_word() & bit13, 0);
}

// A pp move with PDO 3 mapped: the target goes in the synchronous RPDO3, so the new-set-point bit
// must not reach the drive before it (by RPDO1, which acts at once) or the drive takes the old target
// and never moves. Both take effect at one SYNC.
TEST(modes_master, with_pdo_3_mapped_a_pp_target_and_its_new_set_point_bit_arrive_together) {
  pdo3_bench b(10000);  // a SYNC every 10 ms: a word given between two goes out before the next
  drive_master& m = b.m;
  ASSERT_NO_FATAL_FAILURE(b.enable_in(1));  // profile position
  b.run_ms(20);
  constexpr std::uint16_t enable_operation = 0x000F, new_set_point = 1u << 4;
  m.set_position_set_point(20000);
  m.send_control_word(enable_operation | new_set_point);
  for (int i = 0; i < 200 && (m.status_word() & bit12) == 0; ++i) b.run_ms(1);
  ASSERT_NE(m.status_word() & bit12, 0) << "the set-point was never acknowledged";
  m.send_control_word(enable_operation);
  for (int i = 0; i < 5000 && (m.status_word() & bit10) == 0; ++i) b.run_ms(1);
  std::int64_t at = 0;
  ASSERT_EQ(b.drive.drive().read(0x6064, 0, at), sdo_abort::none);
  EXPECT_EQ(at, 20000) << "the drive took the old target";
  EXPECT_NE(m.status_word() & bit10, 0);
}

}  // namespace
}  // namespace cia402::canopen

namespace cia402::canopen {
namespace {

// Issue 34 over the bus, as python-canopen asked it: the top speed and the homing methods are
// objects a master reads by SDO, and pv keeps to the top speed with bit 11 while it cuts.
TEST_F(modes_test, the_speed_limits_and_the_homing_methods_read_by_sdo_and_pv_keeps_to_them_with_bit_11) {
  constexpr std::uint16_t bit11 = 1u << 11;
  EXPECT_EQ(sdo_read(0x607F, 0), 6000);
  EXPECT_EQ(sdo_read(0x6080, 0), 6000);
  const std::int64_t count = sdo_read(0x60E3, 0, 1);
  ASSERT_EQ(count, 32);
  std::vector<std::int64_t> methods;
  for (int sub = 1; sub <= count; ++sub) methods.push_back(sdo_read(0x60E3, static_cast<std::uint8_t>(sub), 1));
  EXPECT_EQ(methods.front(), 1);
  EXPECT_EQ(methods.back(), 37);
  for (const std::int64_t m : methods) EXPECT_EQ(sdo_write(0x6098, 0, m, 1), 0u) << m;
  EXPECT_EQ(sdo_write(0x6098, 0, 15, 1), 0x06090030u) << "not in 0x60E3: refused";
  EXPECT_EQ(sdo_write(0x607F, 0, 2000, 4), 0u);
  EXPECT_EQ(sdo_write(0x6083, 0, 20000, 4), 0u);
  ASSERT_EQ(sdo_write(0x6060, 0, 3, 1), 0u);
  enable();
  ASSERT_EQ(sdo_write(0x60FF, 0, 20000, 4), 0u);
  run_ms(500);
  EXPECT_EQ(sdo_read(0x606C, 0), 2000) << "20,000 rpm asked, 0x607F = 2000 given";
  EXPECT_NE(status_words.back() & bit11, 0) << "internal limit active";
  run_ms(500);
  EXPECT_EQ(sdo_read(0x606C, 0), 2000) << "and it stays there";
}

}  // namespace
}  // namespace cia402::canopen
