// The scope's samples over the event stream (issue 35): a page reading /api/events gets every cycle
// of a drive stepped at 1 kHz while it moves (every signal changing), numbered without a gap from
// the first batch on. It counts numbers, not time: how fast it goes is bench/page_samples_bench.
#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <iostream>
#include <mutex>
#include <thread>

#include "event_stream_reader.hpp"
#include "page_server_fixture.hpp"
#include "sample_batch.hpp"

namespace {

using cia402::page::testing::decode_batch;
using cia402::page::testing::event_stream_reader;
using cia402::page::testing::page_server;
using json = nlohmann::json;

// The `samples` events of /api/events, each batch parsed as it comes, read until told to stop.
class sample_reader {
 public:
  explicit sample_reader(int port)
      : stream_(port, [this](std::string_view piece) {
          bytes_ += piece.size();
          pending_.append(piece);
          for (std::size_t end; (end = pending_.find("\n\n")) != std::string::npos;) {
            const std::string event = pending_.substr(0, end);
            pending_.erase(0, end + 2);
            const std::string head = "event: samples\ndata: ";
            if (event.rfind(head, 0) == 0) batches_.push_back(json::parse(event.substr(head.size())));
          }
          return !stop_;
        }) {}
  ~sample_reader() { stop(); }
  // Ends the reading at the next piece of the stream.
  void stop() {
    stream_.locked([this] { stop_ = true; });
    stream_.join();
  }
  std::vector<json> batches() {
    return stream_.locked([this] { return batches_; });
  }
  std::size_t bytes() {
    return stream_.locked([this] { return bytes_; });
  }

 private:
  std::string pending_;
  std::vector<json> batches_;
  std::size_t bytes_ = 0;
  bool stop_ = false;
  event_stream_reader stream_;  // last: its thread uses the members above
};

TEST_F(page_server, the_event_stream_brings_every_cycle_of_a_moving_drive_at_1_khz_without_a_gap) {
  start(false);
  cia402::page::cycle_runner runner(inst, std::chrono::microseconds(1000));
  runner.start();
  sample_reader reader(http->bound_port());
  ASSERT_EQ(post("/api/enable", "{}")->status, 200);
  // 0x60FF goes after T4, which clears the set-point the motion side follows.
  for (int i = 0; i < 100 && json::parse(inst.snapshot_json())["state"] != "OPERATION_ENABLED"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(post("/api/plant", R"({"target_velocity":1500})")->status, 200);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const std::uint64_t end_before_stop = inst.samples_end();
  // The samples up to here must all arrive: the stream sends what the ring holds.
  for (int i = 0; i < 100; ++i) {
    const auto b = reader.batches();
    if (!b.empty() && b.back()["from"].get<std::uint64_t>() + b.back()["n"].get<std::uint64_t>() >= end_before_stop) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  runner.stop();
  reader.stop();
  const std::vector<json> batches = reader.batches();
  ASSERT_FALSE(batches.empty());
  std::uint64_t expected = batches.front()["from"].get<std::uint64_t>();
  std::uint64_t received = 0, moving = 0;
  std::optional<std::int64_t> last_position;
  for (const json& b : batches) {
    EXPECT_EQ(b["from"].get<std::uint64_t>(), expected) << "samples skipped";
    for (const auto& s : decode_batch(b)) {
      ++received;
      const auto p = s.values.at("position");
      if (last_position && p && *p != *last_position) ++moving;
      last_position = p;
    }
    expected = b["from"].get<std::uint64_t>() + b["n"].get<std::uint64_t>();
  }
  EXPECT_GE(expected, end_before_stop);
  EXPECT_GT(received, 2000u);
  EXPECT_GT(moving, received / 2);  // the position changes from cycle to cycle: no run-length shortcut
  std::cout << "[ measured ] " << received << " samples in " << batches.size() << " batches, "
            << reader.bytes() << " bytes on the stream\n";
}

}  // namespace
