// The page's remote backend with the EtherCAT master as its link (`cia402 serve --ecat`), against
// two virtual drives on the in-process EtherCAT wire, in virtual time: the line brought to OP, the
// page's commands in the process data, the actual values from it, an object the drive maps in its
// outputs written there, fault injection over the mailbox with its EMCY, and a line that goes
// silent and comes back. Expected words and states are the standard's (cia402-reference.md §1.3).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <future>
#include <memory>
#include <mutex>
#include <vector>

#include "blocking_request.hpp"
#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/axis/ecat_link.hpp"
#include "cia402/page/axis_page.hpp"
#include "cia402/profile.hpp"

namespace {

using namespace cia402;
using cia402::page::accepted;
using cia402::page::page_command;
using cia402::page::plant_change;
using cia402::page::reply;
using json = nlohmann::json;

class wire final : public ethercat::master_link {
 public:
  wire() {
    for (std::uint32_t i = 0; i < 2; ++i) {
      slaves.push_back(std::make_unique<apps::virtual_drive_slave>(standard_profile(), i + 1));
      line.add(slaves.back()->controller());
    }
  }
  // A request made with blocking() polls the page's link on its own thread while the bench's thread
  // steps the slaves: the wire is one lock, as a cable carries one frame at a time.
  bool exchange(std::vector<std::uint8_t>& frame) override {
    std::lock_guard lock(mutex);
    if (cut) return false;
    return line.pass(frame) == ethercat::frame_error::none;
  }
  std::uint64_t now_us() override {
    std::lock_guard lock(mutex);
    return now;
  }
  void wait_us(std::uint32_t us) override {
    std::lock_guard lock(mutex);
    now += us;
    for (auto& s : slaves) s->step(us);
  }
  std::mutex mutex;
  std::vector<std::unique_ptr<apps::virtual_drive_slave>> slaves;
  ethercat::chain line;
  std::uint64_t now = 0;
  bool cut = false;
};

// The page's drive as `cia402 serve --ecat` builds it: the line brought to OP, then an axis page
// over the ecat_link to the drive at position 1.
struct bench {
  wire link;
  std::unique_ptr<ethercat::ecat_line> line;
  std::unique_ptr<page::axis_page> page;
  bench() {
    line = std::make_unique<ethercat::ecat_line>(link, standard_profile(), 1000, "veth-test");
    EXPECT_TRUE(line->scan()) << line->error();
    EXPECT_TRUE(line->bring_to_operational()) << line->error();
    line->set_retry_us(100000);  // as serve sets it: a line that answers again is brought up again
    page::axis_page_config c;
    c.request_timeout = std::chrono::milliseconds(20000);
    c.reset_pulse_us = 20000;
    c.settle_quiet_us = 150000;
    c.node = 1;
    c.bus = "EtherCAT veth-test";
    c.where = "slave 1 on EtherCAT veth-test";
    ethercat::ecat_line* on_line = line.get();
    page = std::make_unique<page::axis_page>(
        standard_profile(),
        [on_line](const profile&) {
          return page::drive_connection{std::make_unique<ethercat::ecat_link>(*on_line, 1), nullptr};
        },
        c);
  }
  ~bench() { page.reset(); }
  std::string status() const { return snapshot()["remote"]["status"]; }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      page->step();
      link.wait_us(1000);
    }
  }
  template <typename F>
  bool run_until(F done, int ms = 3000) {
    for (int i = 0; i < ms; ++i) {
      run_ms(1);
      if (done()) return true;
    }
    return false;
  }
  // A request that waits for a transfer: made on another thread while this one runs the bus.
  template <typename Request>
  reply blocking(Request request) {
    return cia402::page::testing::blocking_request(request, [this] { run_ms(1); });
  }
  json snapshot() const { return json::parse(page->snapshot_json()); }
  std::string state() const { return snapshot()["state"]; }
  sim::virtual_drive& drive() { return link.slaves[1]->device().drive(); }
  // Shutdown, Switch on and Enable operation, 30 ms apart: false at the first one refused.
  bool enable() {
    for (page_command c : {page_command::shutdown, page_command::switch_on, page_command::enable_operation}) {
      if (!std::holds_alternative<accepted>(page->command(c))) return false;
      run_ms(30);
    }
    return true;
  }
};

bool is_accepted(const reply& r) { return std::holds_alternative<accepted>(r); }

TEST(ecat_page, brings_the_line_up_and_shows_the_drive_at_its_position) {
  bench b;
  ASSERT_TRUE(b.run_until([&] { return b.status() == "running"; }));
  b.run_ms(50);
  const json s = b.snapshot();
  EXPECT_EQ(s["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(s["status_word"], "0x1250");
  EXPECT_EQ(s["remote"]["where"], "slave 1 on EtherCAT veth-test");
  // The line's own state is the link's (the page holds no fieldbus code): as serve brought it up.
  EXPECT_EQ(b.line->master().slaves()[1].mapping_source, "CoE 0x1C12/0x1C13");
  EXPECT_EQ(b.line->master().last_working_counter(), 6);
  EXPECT_EQ(s["mode"], 3) << "0x6061 from the process data";
  EXPECT_TRUE(s["capabilities"]["fault"]) << "a drive of this project takes injected faults at 0x2001";
  EXPECT_EQ(b.link.slaves[0]->state(), ethercat::al_state::operational);
  EXPECT_EQ(b.link.slaves[1]->state(), ethercat::al_state::operational);
}

TEST(ecat_page, commands_go_in_the_process_data_and_the_states_come_back) {
  bench b;
  ASSERT_TRUE(b.run_until([&] { return b.status() == "running"; }));
  ASSERT_TRUE(b.enable());
  EXPECT_EQ(b.state(), "OPERATION_ENABLED");
  EXPECT_EQ(b.snapshot()["last_transition"]["number"], 4);
  EXPECT_EQ(b.drive().view().current(), state::operation_enabled) << "the drive at position 1";
  EXPECT_EQ(b.link.slaves[0]->device().drive().view().current(), state::switch_on_disabled)
      << "the other drive is not commanded";
  // 0x60FF is in the drive's RxPDO: the page's write goes there, and the shaft follows.
  plant_change v;
  v.target_velocity = 300;
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.page->change_plant(v); })));
  EXPECT_TRUE(b.run_until([&] { return b.snapshot()["velocity"] == 300; }));
  EXPECT_GT(b.snapshot()["position"].get<std::int64_t>(), 0) << "0x6064 from the process data";
}

// The scope's samples over EtherCAT (issue 35): one each LRW (1 ms here), numbered without a gap,
// the position from the process data in every one of them, not a polled value.
TEST(ecat_page, each_lrw_gives_one_scope_sample_with_the_process_data_of_that_cycle) {
  bench b;
  ASSERT_TRUE(b.run_until([&] { return b.status() == "running"; }));
  ASSERT_TRUE(b.enable());
  plant_change v;
  v.target_velocity = 300;
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.page->change_plant(v); })));
  ASSERT_TRUE(b.run_until([&] { return b.snapshot()["velocity"] == 300; }));
  const std::uint64_t from = b.page->samples_end();
  b.run_ms(100);
  EXPECT_EQ(b.page->samples_end() - from, 100u);  // 100 ms of a 1 ms LRW
  std::uint64_t next = 0;
  const json batch = json::parse(b.page->samples_json(from, 1000, next));
  EXPECT_EQ(batch["n"], 100);
  EXPECT_EQ(batch["dt"], json({1000, 99}));
  // 300 rpm is 50 increments a cycle: a run of one each sample.
  EXPECT_EQ(batch["columns"]["position"].size(), 200u) << batch["columns"]["position"];
  EXPECT_EQ(batch["columns"]["set_point"], json({300, 100}));
  EXPECT_EQ(batch["columns"]["mode"], json({3, 100}));
  for (const json& name : batch["polled"]) {
    EXPECT_NE(name, "position");
    EXPECT_NE(name, "velocity");
    EXPECT_NE(name, "mode");
  }
}

TEST(ecat_page, an_injected_fault_shows_with_its_code_and_a_reset_clears_it) {
  bench b;
  ASSERT_TRUE(b.run_until([&] { return b.status() == "running"; }));
  plant_change f;
  f.fault = true;
  f.fault_code = 0x2310;
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.page->change_plant(f); })));
  EXPECT_TRUE(b.run_until([&] { return b.state() == "FAULT"; }));
  b.run_ms(20);
  EXPECT_EQ(b.snapshot()["error_code"], "0x2310");
  EXPECT_EQ(b.snapshot()["error_text"], "continuous over-current");  // CiA 402's error code table
  // 0x1001 is not in the process data: the session polls it (every poll_us, 100 ms).
  EXPECT_TRUE(b.run_until([&] { return b.snapshot()["error_register"] == "0x03"; }, 300))
      << "generic + current, read by SDO";
  EXPECT_EQ(b.snapshot()["remote"]["last_emcy"], "0x2310");
  // The slave's own pre-defined error field, read over CoE when 0x603F changed (issue 35).
  EXPECT_TRUE(b.run_until([&] { return b.snapshot()["drive_errors"]["count"] == 1; }, 500))
      << b.snapshot()["drive_errors"];
  EXPECT_EQ(b.snapshot()["drive_errors"]["entries"][0]["code"], "0x2310");
  plant_change clear;
  clear.fault = false;
  ASSERT_TRUE(is_accepted(b.blocking([&] { return b.page->change_plant(clear); })));
  ASSERT_TRUE(is_accepted(b.page->command(page_command::fault_reset)));
  EXPECT_TRUE(b.run_until([&] { return b.state() == "SWITCH_ON_DISABLED"; }));
  EXPECT_EQ(b.snapshot()["last_transition"]["number"], 15);
}

TEST(ecat_page, a_silent_line_shows_why_and_the_page_comes_back_with_it) {
  bench b;
  ASSERT_TRUE(b.run_until([&] { return b.status() == "running"; }));
  b.link.cut = true;
  ASSERT_TRUE(b.run_until([&] { return b.status() == "no_answer"; }, 200));
  b.run_ms(50);
  const json s = b.snapshot();
  EXPECT_EQ(s["state"], "UNKNOWN");
  EXPECT_NE(s["remote"]["text"].get<std::string>().find("does not answer"), std::string::npos) << s["remote"];
  const reply r = b.page->command(page_command::shutdown);
  ASSERT_TRUE(std::holds_alternative<page::refused>(r));
  EXPECT_EQ(std::get<page::refused>(r).http_status, 503);
  b.link.cut = false;
  EXPECT_TRUE(b.run_until([&] { return b.status() == "running"; }));
}

}  // namespace
