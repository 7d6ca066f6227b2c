// The page's recorder on its own: which cycles it keeps and how it stays bounded.
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>

#include "recorder.hpp"

namespace {

using cia402::page::detail::recorder;
using cia402::sim::trace_row;

trace_row at(std::uint64_t t_us, std::int64_t rpm, std::uint16_t sw = 0x0237) {
  trace_row r;
  r.time_us = t_us;
  r.velocity = rpm * 1000000;
  r.status_word = sw;
  r.current = cia402::state::operation_enabled;
  return r;
}

TEST(page_recorder, a_drive_standing_still_costs_one_row) {
  recorder rec;
  for (std::uint64_t c = 0; c < 10000; ++c) rec.record(at(c * 1000, 0));
  EXPECT_EQ(rec.rows(), 1u);
}

TEST(page_recorder, a_ramp_is_sampled_every_20_ms_and_every_word_change_is_kept) {
  recorder rec;
  // 1 s of a ramp, 1 rpm a cycle: 1 + 1000 / 20 samples.
  for (std::uint64_t c = 0; c <= 1000; ++c) rec.record(at(c * 1000, static_cast<std::int64_t>(c)));
  EXPECT_EQ(rec.rows(), 51u);
  rec.record(at(1001000, 1001, 0x0233));  // a status word change is kept at once
  EXPECT_EQ(rec.rows(), 52u);
  const auto j = rec.since_json(51, 0);
  ASSERT_EQ(j["rows"].size(), 1u);
  EXPECT_EQ(j["rows"][0][2], 0x0233);
  EXPECT_EQ(j["rows"][0][5], 1001);
}

TEST(page_recorder, the_oldest_rows_and_transitions_go_first_and_are_counted) {
  recorder rec(recorder::limits{10, 3, 20000});
  for (std::uint64_t c = 0; c < 25; ++c) rec.record(at(c * 1000, 0, static_cast<std::uint16_t>(c)));
  EXPECT_EQ(rec.rows(), 10u);
  const auto j = rec.since_json(0, 0);
  EXPECT_EQ(j["dropped_rows"], 15);
  EXPECT_EQ(j["rows_seen"], 25);
  EXPECT_EQ(j["rows"][0][2], 15);  // the oldest kept is the 16th
  for (int i = 0; i < 5; ++i) rec.note_transition({0, 1000u * i, i, cia402::state::start,
                                                   cia402::state::start, 0, 0, false});
  const auto t = rec.since_json(0, 0);
  ASSERT_EQ(t["transitions"].size(), 3u);
  EXPECT_EQ(t["transitions"][0]["number"], 2);
  EXPECT_EQ(t["transitions_seen"], 5);
  std::ostringstream csv;
  rec.write_csv(csv);
  const std::string text = csv.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 11);  // header + 10 rows
}

// The operation modes: a move at constant velocity is sampled by its position, a mode change is
// kept at once, and the timeline rows and the CSV end with the position and the torque.
TEST(page_recorder, position_and_torque_are_sampled_and_exported_at_the_end_of_each_row) {
  recorder rec;
  for (std::uint64_t c = 0; c <= 1000; ++c) {
    trace_row r = at(c * 1000, 600);  // constant velocity: only the position moves
    r.position = static_cast<std::int64_t>(c) * 100;
    r.position_demand = r.position;
    r.torque_permille = 25;
    r.mode = 1;
    rec.record(r);
  }
  EXPECT_EQ(rec.rows(), 51u);
  trace_row homing = at(1001000, 600);
  homing.position = 100100;
  homing.position_demand = 100100;
  homing.torque_permille = -7;
  homing.mode = 6;  // a mode change is kept at once
  rec.record(homing);
  EXPECT_EQ(rec.rows(), 52u);
  const auto j = rec.since_json(51, 0);
  ASSERT_EQ(j["rows"].size(), 1u);
  ASSERT_EQ(j["rows"][0].size(), 8u);
  EXPECT_EQ(j["rows"][0][5], 600);
  EXPECT_EQ(j["rows"][0][6], 100100);
  EXPECT_EQ(j["rows"][0][7], -7);

  std::ostringstream csv;
  rec.write_csv(csv);
  const std::string text = csv.str();
  const auto ends_with = [](const std::string& line, const std::string& tail) {
    return line.size() >= tail.size() && line.compare(line.size() - tail.size(), tail.size(), tail) == 0;
  };
  const std::string header = text.substr(0, text.find('\n'));
  EXPECT_TRUE(ends_with(header, ",position,position_demand,torque_permille,mode")) << header;
  const std::string last = text.substr(text.rfind('\n', text.size() - 2) + 1);
  EXPECT_TRUE(ends_with(last, ",100100,100100,-7,6\n")) << last;
}

}  // namespace
