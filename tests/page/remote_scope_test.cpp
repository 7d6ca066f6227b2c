// The scope's view of a drive on a bus (issue 35), against a node on the in-process virtual bus in
// virtual time (remote_bench.hpp): one sample each SYNC, /api/info's cycle the SYNC period, and each
// transition inferred from the status word in the recording's row of its cycle, where the scope's
// transition trigger looks for it. Expected numbers are the standard's (cia402-reference.md §2.2).
#include "remote_bench.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace {

using namespace remote_drive_testing;

// The scope's samples over CAN (issue 35): one each SYNC (10 ms here, /api/info's cycle), numbered
// without a gap, the status word the TPDO brought; what the PDOs do not carry is the last polled value.
TEST(remote_drive, each_sync_gives_one_scope_sample_info_names_its_period_the_batch_what_was_polled) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  b.run_ms(100);
  const std::uint64_t from = b.remote().samples_end();
  b.run_ms(500);
  EXPECT_EQ(b.remote().samples_end() - from, 50u);  // 500 ms of a 10 ms SYNC
  std::uint64_t next = 0;
  const json batch = json::parse(b.remote().samples_json(from, 1000, next));
  EXPECT_EQ(batch["from"], from);
  EXPECT_EQ(batch["n"], 50);
  EXPECT_EQ(batch["dt"], json({10000, 49}));
  EXPECT_EQ(json::parse(b.remote().info_json(true, false))["cycle_us"], 10000);  // the cursors' cycle
  const json& sw = batch["columns"]["status_word"];  // one run: SWITCH ON DISABLED throughout
  ASSERT_EQ(sw.size(), 2u) << sw;
  EXPECT_EQ(sw[0].get<int>() & 0x4F, 0x40) << sw;
  EXPECT_EQ(sw[1], 50);
  const std::vector<std::string> polled = batch["polled"].get<std::vector<std::string>>();
  for (const char* name : {"torque", "following_error", "digital_inputs", "mode"}) {
    EXPECT_NE(std::find(polled.begin(), polled.end(), name), polled.end()) << name << " in " << batch["polled"];
  }
}

// The scope's transition trigger reads the recording's rows: behind a bus each inferred number must
// be in the row of the cycle the status word showed it, as the list of transitions has it.
TEST(remote_drive, each_inferred_transition_is_in_the_recordings_row_of_its_cycle) {
  remote_bench b;
  ASSERT_TRUE(b.run_until_running()) << b.remote().link_text();
  enable(b);
  const json rec = json::parse(b.remote().recording_json(0, 0));
  std::vector<std::pair<json, json>> listed;
  std::vector<std::pair<json, json>> in_rows;
  for (const json& t : rec["transitions"]) listed.emplace_back(t["time_ms"], t["number"]);
  for (const json& row : rec["rows"]) {
    if (!row[4].is_null()) in_rows.emplace_back(row[0], row[4]);
  }
  ASSERT_EQ(listed.size(), 3u) << rec["transitions"];
  EXPECT_EQ(listed[0].second, 2);
  EXPECT_EQ(listed[1].second, 3);
  EXPECT_EQ(listed[2].second, 4);
  EXPECT_EQ(in_rows, listed) << rec["rows"];
}

}  // namespace
