// The scope's per-cycle samples (issue 35): the ring numbers them without a gap, keeps the newest,
// lets a reader that fell behind skip ahead and see it; a batch decodes back to every sample; a
// drive in this process gives one sample per step, each transition in the sample of its cycle.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "page_steps.hpp"
#include "sample_batch.hpp"
#include "sample_ring.hpp"

namespace {

using cia402::page::detail::cycle_sample;
using cia402::page::detail::sample_ring;
using cia402::page::detail::signal;
using cia402::page::testing::decode_batch;
using cia402::page::testing::decoded_sample;
using json = nlohmann::json;

cycle_sample sample_at(std::uint64_t k) {
  cycle_sample s;
  s.time_us = 1000 * k;
  s.set(signal::position, static_cast<std::int64_t>(k / 3));  // runs of three
  s.set(signal::velocity, -7);
  if (k % 5 == 0) s.set(signal::transition, 2);
  return s;
}

// Pushes sample_at(0) .. sample_at(count - 1): every case fills its ring with the same numbered
// samples and checks what it keeps of them.
void push_samples(sample_ring& ring, std::uint64_t count) {
  for (std::uint64_t k = 0; k < count; ++k) ring.push(sample_at(k));
}

std::vector<decoded_sample> read(const sample_ring& ring, std::uint64_t from, std::size_t max, std::uint64_t& next) {
  return decode_batch(json::parse(ring.batch_json(from, max, next, {"torque"})));
}

TEST(sample_ring, numbers_every_sample_without_a_gap_and_decodes_each_value) {
  sample_ring ring(64);
  push_samples(ring, 40);
  EXPECT_EQ(ring.begin(), 0u);
  EXPECT_EQ(ring.end(), 40u);
  std::uint64_t next = 0;
  const auto got = read(ring, 0, 100, next);
  ASSERT_EQ(got.size(), 40u);
  EXPECT_EQ(next, 40u);
  for (std::uint64_t k = 0; k < 40; ++k) {
    EXPECT_EQ(got[k].number, k);
    EXPECT_EQ(got[k].time_us, 1000 * k);
    EXPECT_EQ(got[k].values.at("position"), static_cast<std::int64_t>(k / 3));
    EXPECT_EQ(got[k].values.at("velocity"), -7);
    EXPECT_EQ(got[k].values.at("transition"), k % 5 == 0 ? std::optional<std::int64_t>(2) : std::nullopt);
    EXPECT_EQ(got[k].values.at("status_word"), std::nullopt);
  }
}

TEST(sample_ring, a_batch_is_run_length_coded_and_names_the_polled_signals) {
  sample_ring ring(64);
  push_samples(ring, 30);
  std::uint64_t next = 0;
  const json b = json::parse(ring.batch_json(0, 100, next, {"torque"}));
  EXPECT_EQ(b["dt"], json({1000, 29}));                        // a steady cycle: one pair
  EXPECT_EQ(b["columns"]["velocity"], json({-7, 30}));         // a standing value: one pair
  EXPECT_EQ(b["columns"]["status_word"], json({nullptr, 30}));
  EXPECT_EQ(b["columns"]["position"].size(), 20u);             // ten runs of three
  EXPECT_EQ(b["polled"], json({"torque"}));
}

TEST(sample_ring, a_batch_holds_at_most_max_and_the_next_one_goes_on_from_there) {
  sample_ring ring(64);
  push_samples(ring, 50);
  std::uint64_t next = 0;
  auto first = read(ring, 0, 20, next);
  ASSERT_EQ(first.size(), 20u);
  EXPECT_EQ(next, 20u);
  auto second = read(ring, next, 100, next);
  ASSERT_EQ(second.size(), 30u);
  EXPECT_EQ(second.front().number, 20u);
  EXPECT_EQ(second.front().time_us, 20000u);
  EXPECT_EQ(next, 50u);
  EXPECT_TRUE(read(ring, next, 100, next).empty());
}

TEST(sample_ring, the_oldest_go_when_full_and_a_reader_behind_skips_ahead_to_the_oldest_kept) {
  sample_ring ring(16);
  push_samples(ring, 100);
  EXPECT_EQ(ring.begin(), 84u);
  EXPECT_EQ(ring.end(), 100u);
  std::uint64_t next = 0;
  const json b = json::parse(ring.batch_json(10, 100, next, {}));
  EXPECT_EQ(b["from"], 84);  // the reader sees the gap: it asked for 10
  const auto got = decode_batch(b);
  ASSERT_EQ(got.size(), 16u);
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].number, 84 + i);
    EXPECT_EQ(got[i].values.at("position"), static_cast<std::int64_t>((84 + i) / 3));  // wrapped right
  }
  EXPECT_EQ(next, 100u);
}

TEST(sample_ring, clear_forgets_the_samples_but_the_numbers_go_on) {
  sample_ring ring(64);
  push_samples(ring, 10);
  ring.clear();
  std::uint64_t next = 0;
  EXPECT_TRUE(read(ring, 0, 100, next).empty());
  EXPECT_EQ(next, 10u);
  ring.push(sample_at(10));
  const auto got = read(ring, 0, 100, next);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].number, 10u);
}

using cia402::page::testing::virtual_axis_page;
namespace steps = cia402::page::testing::steps;

std::vector<decoded_sample> all_samples(const virtual_axis_page& inst) {
  std::uint64_t next = 0;
  return decode_batch(json::parse(inst.samples_json(0, 1'000'000, next)));
}

TEST(page_samples, a_drive_in_this_process_gives_one_sample_per_step_numbered_without_a_gap) {
  virtual_axis_page inst(cia402::standard_profile());
  const std::uint64_t before = inst.samples_end();
  steps::run(inst, 500);
  EXPECT_EQ(inst.samples_end() - before, 500u);
  const auto got = all_samples(inst);
  ASSERT_GE(got.size(), 500u);
  for (std::size_t i = 1; i < got.size(); ++i) {
    EXPECT_EQ(got[i].number, got[i - 1].number + 1);
    EXPECT_EQ(got[i].time_us, got[i - 1].time_us + 1000);  // the drive's own cycle, each once
  }
  std::uint64_t next = 0;
  EXPECT_EQ(json::parse(inst.samples_json(0, 10, next))["polled"], json::array());  // all the cycle's
}

TEST(page_samples, a_transition_is_in_the_sample_of_the_cycle_it_was_taken_with_the_state_after_it) {
  virtual_axis_page inst(cia402::standard_profile());
  steps::run(inst, 20);
  ASSERT_TRUE(std::holds_alternative<cia402::page::accepted>(inst.command(cia402::page::page_command::shutdown)));
  steps::run(inst, 20);
  const json rec = json::parse(inst.recording_json(0, 0));
  std::optional<std::int64_t> t2_ms;
  for (const json& t : rec["transitions"]) {
    if (t["number"] == 2) t2_ms = t["time_ms"].get<std::int64_t>();
  }
  ASSERT_TRUE(t2_ms);
  int found = 0;
  for (const decoded_sample& s : all_samples(inst)) {
    if (s.values.at("transition") != 2) continue;
    ++found;
    EXPECT_EQ(static_cast<std::int64_t>(s.time_us / 1000), *t2_ms);
    EXPECT_EQ(s.values.at("state"), static_cast<std::int64_t>(cia402::state::ready_to_switch_on));
    EXPECT_EQ(s.values.at("status_word").value_or(0) & 0x6F, 0x21);  // READY TO SWITCH ON
    EXPECT_EQ(s.values.at("control_word").value_or(0) & 0x87, 0x06);  // the word that asked for it
  }
  EXPECT_EQ(found, 1);
}

TEST(page_samples, a_profile_switch_starts_the_samples_afresh_with_the_numbers_going_on) {
  virtual_axis_page inst(cia402::standard_profile());
  steps::run(inst, 30);
  const std::uint64_t end = inst.samples_end();
  ASSERT_TRUE(std::holds_alternative<cia402::page::accepted>(inst.select_profile(cia402::standard_profile().name)));
  EXPECT_TRUE(all_samples(inst).empty());
  steps::run(inst, 5);
  const auto got = all_samples(inst);
  ASSERT_EQ(got.size(), 5u);
  EXPECT_EQ(got[0].number, end);
}

}  // namespace
