// The steering that ecat_master once did itself (set_target, hold_command), now the axis session's
// over ecat_link: a line of drives on the in-process wire, one ecat_line, a link and a session per
// drive, as `cia402 master --ecat` builds them, in virtual time. Every drive is enabled, quick-stopped
// (QUICK STOP ACTIVE, then SWITCH ON DISABLED as 0x605A = 2 says), a fault injected in one drive
// beside the sessions is seen by its session alone with its code, a request to enable it is refused
// naming the fault, and the session resets it. The master's own tests (master_test.cpp) hold what
// the bus carries: the words, the status words, the error codes and EMCYs.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/axis/session.hpp"
#include "cia402/ethercat/axis/ecat_link.hpp"
#include "cia402/master.hpp"
#include "drive_line.hpp"

namespace cia402::ethercat {
namespace {

using wire = testing::drive_line;

struct sessions {
  explicit sessions(int drives) : w(drives), line(w, standard_profile(), 1000, "test-line") {
    EXPECT_TRUE(line.scan()) << line.error();
    EXPECT_TRUE(line.bring_to_operational()) << line.error();
    for (int i = 0; i < drives; ++i) {
      links.push_back(std::make_unique<ecat_link>(line, static_cast<std::size_t>(i)));
      each.push_back(std::make_unique<axes::session>(*links.back()));
    }
    pump_ms(20);
  }
  void pump_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      for (auto& s : each) (void)s->poll(1000);
      w.wait_us(1000);
    }
  }
  // Starts a request on every session at once and runs them all to their ends (10 s of virtual time).
  std::vector<axes::result> on_all(const std::function<void(axes::session&, axes::completion)>& start) {
    std::vector<std::optional<axes::result>> got(each.size());
    for (std::size_t i = 0; i < each.size(); ++i) start(*each[i], [&got, i](const axes::result& r) { got[i] = r; });
    const auto all_in = [&] {
      for (const auto& g : got) {
        if (!g) return false;
      }
      return true;
    };
    for (int i = 0; i < 10000 && !all_in(); ++i) pump_ms(1);
    std::vector<axes::result> out;
    for (const auto& g : got) {
      EXPECT_TRUE(g) << "no answer within 10 s";
      out.push_back(g.value_or(axes::result{}));
    }
    return out;
  }
  axes::result on_one(std::size_t i, const std::function<void(axes::session&, axes::completion)>& start) {
    std::optional<axes::result> got;
    start(*each[i], [&](const axes::result& r) { got = r; });
    for (int k = 0; k < 10000 && !got; ++k) pump_ms(1);
    EXPECT_TRUE(got) << "no answer within 10 s";
    return got.value_or(axes::result{});
  }
  state drive_state(std::size_t i) { return w.slaves[i]->device().drive().view().current(); }

  wire w;
  ecat_line line;
  std::vector<std::unique_ptr<ecat_link>> links;
  std::vector<std::unique_ptr<axes::session>> each;
};

constexpr int drives = 4;

void enable_all(sessions& l) {
  const auto results = l.on_all([](axes::session& s, axes::completion c) { s.go_to(state::operation_enabled, std::move(c)); });
  for (std::size_t i = 0; i < results.size(); ++i) {
    ASSERT_TRUE(results[i].ok()) << i << ": " << results[i].error;
    ASSERT_EQ(l.each[i]->observed(), state::operation_enabled) << i;
    ASSERT_EQ(l.drive_state(i), state::operation_enabled) << i << ", the drive's own state";
  }
}

TEST(ecat_session_steering, every_drive_on_a_line_is_enabled_by_its_session) {
  sessions l(drives);
  enable_all(l);
  l.pump_ms(50);
  for (std::size_t i = 0; i < drives; ++i) EXPECT_EQ(l.drive_state(i), state::operation_enabled) << "held, " << i;
}

TEST(ecat_session_steering, quick_stop_passes_quick_stop_active_and_ends_as_0x605a_says) {
  sessions l(drives);
  enable_all(l);
  std::vector<std::vector<state>> seen(drives);
  for (std::size_t i = 0; i < drives; ++i) {
    l.each[i]->on_state = [&seen, i](state, state to, std::uint16_t) { seen[i].push_back(to); };
  }
  const auto results = l.on_all([](axes::session& s, axes::completion c) { s.quick_stop(std::move(c)); });
  for (std::size_t i = 0; i < drives; ++i) {
    EXPECT_TRUE(results[i].ok()) << i << ": " << results[i].error;
    ASSERT_FALSE(seen[i].empty()) << i;
    EXPECT_EQ(seen[i].front(), state::quick_stop_active) << i;
    EXPECT_EQ(l.each[i]->observed(), state::switch_on_disabled) << i << ": 0x605A = 2";
    EXPECT_EQ(l.drive_state(i), state::switch_on_disabled) << i;
  }
}

TEST(ecat_session_steering, a_fault_in_one_drive_is_its_sessions_alone_and_its_reset_clears_it) {
  sessions l(drives);
  enable_all(l);
  ASSERT_EQ(l.w.slaves[2]->device().write(0x2001, 0, 0x2310), sdo_abort::none);  // beside the session
  for (int i = 0; i < 1000 && l.each[2]->observed() != state::fault; ++i) l.pump_ms(1);
  ASSERT_EQ(l.each[2]->observed(), state::fault);
  EXPECT_EQ(l.each[2]->error_code(), 0x2310) << "0x603F as the link carried it";
  for (std::size_t i : {0u, 1u, 3u}) EXPECT_EQ(l.each[i]->observed(), state::operation_enabled) << "the others run on, " << i;
  const axes::result refused = l.on_one(2, [](axes::session& s, axes::completion c) { s.go_to(state::operation_enabled, std::move(c)); });
  EXPECT_FALSE(refused.ok());
  EXPECT_NE(refused.error.find("the drive is in FAULT: error code 0x2310"), std::string::npos) << refused.error;
  // The cause gone, the session's reset: the fault-reset edge, then SWITCH ON DISABLED.
  ASSERT_EQ(l.w.slaves[2]->device().write(0x2001, 0, 0), sdo_abort::none);
  const axes::result reset = l.on_one(2, [](axes::session& s, axes::completion c) { s.reset(std::move(c)); });
  EXPECT_TRUE(reset.ok()) << reset.error;
  EXPECT_EQ(l.each[2]->observed(), state::switch_on_disabled);
  EXPECT_EQ(l.drive_state(2), state::switch_on_disabled);
  l.pump_ms(5);
  EXPECT_EQ(l.each[2]->error_code(), 0);
  const axes::result again = l.on_one(2, [](axes::session& s, axes::completion c) { s.go_to(state::operation_enabled, std::move(c)); });
  EXPECT_TRUE(again.ok()) << again.error;
  EXPECT_EQ(l.drive_state(2), state::operation_enabled);
}

}  // namespace
}  // namespace cia402::ethercat
