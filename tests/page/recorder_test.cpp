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

}  // namespace
