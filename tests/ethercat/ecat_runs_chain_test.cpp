// Issue 42: EtherCAT runs chain. A run that ended well (enable, mode pp) closes its link with the
// drive enabled; before the line leaves OP the link brings the drive down to SWITCH ON DISABLED, so
// leaving OP is no lost connection for 0x6007 (1 by default: a fault) and the next run on the same
// line finds the drive without a fault, as on CANopen. The virtual drive on the in-process wire, a
// line, a link and an axis session per run, as `cia402 master --ecat` builds them; virtual time.
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/axis/session.hpp"
#include "cia402/ethercat/axis/ecat_link.hpp"

namespace cia402::ethercat {
namespace {

class wire final : public master_link {
 public:
  wire() { line.add(slave.controller()); }
  bool exchange(std::vector<std::uint8_t>& frame) override { return line.pass(frame) == frame_error::none; }
  std::uint64_t now_us() override { return now; }
  void wait_us(std::uint32_t us) override {
    now += us;
    slave.step(us);
  }
  apps::virtual_drive_slave slave{standard_profile(), 1};
  chain line;
  std::uint64_t now = 0;
};

// One `cia402 master --ecat` run: the line scanned and brought to OP, a session on slave 0.
struct run {
  explicit run(wire& w) : w(&w), line(w, standard_profile(), 1000, "test-line") {
    EXPECT_TRUE(line.scan()) << line.error();
    EXPECT_TRUE(line.bring_to_operational()) << line.error();
    link = std::make_unique<ecat_link>(line, 0);
    session = std::make_unique<axes::session>(*link);
  }
  void pump_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      (void)session->poll(1000);
      w->wait_us(1000);
    }
  }
  // Runs one request to its end (at most 10 s of virtual time).
  axes::result until_done(const std::function<void(axes::completion)>& start) {
    std::optional<axes::result> got;
    start([&](const axes::result& r) { got = r; });
    for (int i = 0; i < 10000 && !got; ++i) pump_ms(1);
    EXPECT_TRUE(got) << "no answer within 10 s";
    return got.value_or(axes::result{});
  }
  void close() {
    session->close(false);
    for (int i = 0; i < 10000 && !session->closed(); ++i) pump_ms(1);
    EXPECT_TRUE(session->closed());
  }
  wire* w;
  ecat_line line;
  std::unique_ptr<ecat_link> link;
  std::unique_ptr<axes::session> session;
};

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "; ";
  return s;
}

TEST(ecat_runs_chain, a_run_that_ended_enabled_leaves_the_drive_so_the_next_run_finds_no_fault) {
  wire w;
  {
    run first(w);
    first.pump_ms(20);
    axes::result r = first.until_done([&](axes::completion c) { first.session->go_to(state::operation_enabled, c); });
    ASSERT_TRUE(r.ok()) << r.error;
    r = first.until_done([&](axes::completion c) { first.session->set_mode(1, c); });
    ASSERT_TRUE(r.ok()) << r.error;
    ASSERT_EQ(first.session->observed(), state::operation_enabled);
    first.close();
    const axes::close_report& report = first.session->closing();
    EXPECT_NE(joined(report.restored).find("slave 0 brought from OPERATION_ENABLED to SWITCH_ON_DISABLED before the line "
                                           "left OP"),
              std::string::npos)
        << joined(report.restored) << " | " << joined(report.left);
    EXPECT_NE(joined(report.left).find("with the drive in SWITCH_ON_DISABLED, not enabled"), std::string::npos)
        << joined(report.left);
  }
  // Time passes between the runs; the drive sits in PRE-OP.
  for (int i = 0; i < 200; ++i) w.wait_us(1000);
  EXPECT_NE(w.slave.device().drive().view().current(), state::fault);

  run second(w);
  second.pump_ms(20);
  const axes::result r = second.until_done([&](axes::completion c) { second.session->read_state(c); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(second.session->observed(), state::switch_on_disabled);
  EXPECT_EQ(second.session->error_code(), 0) << "0x6007 must not have acted on leaving OP";
  const axes::result enabled =
      second.until_done([&](axes::completion c) { second.session->go_to(state::operation_enabled, c); });
  EXPECT_TRUE(enabled.ok()) << enabled.error;
  second.close();
}

TEST(ecat_runs_chain, a_drive_still_turning_is_quick_stopped_before_it_is_disabled) {
  wire w;
  {
    run first(w);
    std::vector<state> seen;
    first.session->on_state = [&](state, state to, std::uint16_t) { seen.push_back(to); };
    first.pump_ms(20);
    axes::result r = first.until_done([&](axes::completion c) { first.session->go_to(state::operation_enabled, c); });
    ASSERT_TRUE(r.ok()) << r.error;
    r = first.until_done([&](axes::completion c) { first.session->velocity(300, c); });
    ASSERT_TRUE(r.ok()) << r.error;
    first.pump_ms(100);
    ASSERT_NE(w.slave.device().drive().view().velocity_rpm(), 0);
    seen.clear();
    first.close();
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.front(), state::quick_stop_active) << "a controlled stop, not a coasting shaft";
    EXPECT_EQ(w.slave.device().drive().view().current(), state::switch_on_disabled);
    EXPECT_NE(joined(first.session->closing().restored).find("brought from OPERATION_ENABLED to SWITCH_ON_DISABLED"),
              std::string::npos);
    EXPECT_EQ(w.slave.device().drive().view().velocity_rpm(), 0);
  }
  run second(w);
  second.pump_ms(20);
  const axes::result r = second.until_done([&](axes::completion c) { second.session->read_state(c); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(second.session->observed(), state::switch_on_disabled);
  EXPECT_EQ(second.session->error_code(), 0);
  second.close();
}

TEST(ecat_runs_chain, a_drive_left_disabled_leaves_op_at_once) {
  wire w;
  run first(w);
  first.pump_ms(20);
  const axes::result r = first.until_done([&](axes::completion c) { first.session->go_to(state::ready_to_switch_on, c); });
  ASSERT_TRUE(r.ok()) << r.error;
  first.session->close(false);
  (void)first.session->poll(0);
  EXPECT_TRUE(first.session->closed()) << "nothing to bring down: out of OP in the same poll";
  EXPECT_TRUE(first.session->closing().restored.empty());
}

}  // namespace
}  // namespace cia402::ethercat
