// session::poll_until_idle(): what needs no time runs at once over a drive in this process
// (apps::local_link), stops at its bound over a link whose work never ends, and polls once over a
// bus, where nothing is answered before time passes.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <optional>

#include "cia402/apps/local_link.hpp"
#include "cia402/axis/session.hpp"
#include "cia402/objects.hpp"
#include "forwarding_link.hpp"
#include "sim_link.hpp"

namespace cia402::axes::test {
namespace {

// A bus-like link around sim_link that counts its polls and says work_now() as a test sets it:
// false as a bus's link does, true as a broken link that always claims more.
class counting_link final : public cia402::test::forwarding_link<sim_link> {
 public:
  explicit counting_link(bool busy) : busy_(busy) {}
  int polls = 0;

  std::uint32_t poll(std::uint32_t elapsed_us) override {
    ++polls;
    return inner.poll(elapsed_us);
  }
  bool work_now() const override { return busy_; }

 private:
  bool busy_;
};

// A link that refuses a download of no bytes while running, as the CANopen and EtherCAT links do
// (an SDO carries at least one byte).
class no_empty_download_link final : public cia402::test::forwarding_link<apps::local_link> {
 public:
  no_empty_download_link() : forwarding_link(standard_profile()) {}
  bool download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes,
                transfer_done done) override {
    if (bytes.empty()) return false;
    return inner.download(index, sub, std::move(bytes), std::move(done));
  }
};

TEST(poll_until_idle, a_transfer_a_running_link_refuses_fails_and_the_next_one_runs) {
  no_empty_download_link link;
  session s(link);
  ASSERT_TRUE(s.poll_until_idle());
  std::optional<result> written, read;
  s.write_object(0x2100, 0, object_value::of_bytes({}), [&](const result& r) { written = r; });
  s.read_object(0x6041, 0, [&](const result& r) { read = r; });
  EXPECT_TRUE(s.poll_until_idle());
  ASSERT_TRUE(written.has_value()) << "the refused download was never answered";
  EXPECT_FALSE(written->ok());
  EXPECT_NE(written->error.find("a download of no bytes"), std::string::npos) << written->error;
  ASSERT_TRUE(read.has_value()) << "the read behind the refused download never ran";
  EXPECT_TRUE(read->ok()) << read->error;
}

TEST(poll_until_idle, a_drive_in_this_process_is_prepared_at_start_without_time_passing) {
  apps::local_link link(standard_profile());
  session s(link);
  ASSERT_FALSE(s.prepared());
  EXPECT_TRUE(s.poll_until_idle());
  EXPECT_TRUE(s.prepared());
  EXPECT_FALSE(link.work_now());
  EXPECT_EQ(s.now_us(), 0u);
  EXPECT_EQ(link.status_count(), 0u) << "no cycle of the drive ran";
}

TEST(poll_until_idle, a_drive_in_this_process_answers_every_read_queued_at_once) {
  apps::local_link link(standard_profile());
  session s(link);
  ASSERT_TRUE(s.poll_until_idle());
  std::size_t asked = 0, answered = 0;
  for (std::size_t i = 0; i < drive_object_count(); ++i) {
    const object_description& o = drive_object(i);
    if (o.access == object_access::write_only) continue;
    ++asked;
    s.read_object(o.index, o.sub, [&](const result& r) {
      EXPECT_TRUE(r.ok()) << r.error;
      ++answered;
    });
  }
  ASSERT_GT(asked, 8u) << "more reads than the page's old guess of 8 polls";
  EXPECT_TRUE(s.poll_until_idle());
  EXPECT_EQ(answered, asked);
  EXPECT_EQ(s.now_us(), 0u);
}

TEST(poll_until_idle, a_chain_of_reads_each_asking_the_next_ends_without_time_passing) {
  apps::local_link link(standard_profile());
  session s(link);
  ASSERT_TRUE(s.poll_until_idle());
  // Longer than the 300 polls the page used to give 0x1003.
  constexpr int chain = 400;
  int done = 0;
  std::function<void()> next = [&] {
    s.read_object(device_name_index, 0, [&](const result& r) {
      EXPECT_TRUE(r.ok()) << r.error;
      if (++done < chain) next();
    });
  };
  next();
  EXPECT_TRUE(s.poll_until_idle());
  EXPECT_EQ(done, chain);
  EXPECT_EQ(s.now_us(), 0u);
}

TEST(poll_until_idle, a_link_whose_work_never_ends_is_polled_no_more_than_the_bound) {
  counting_link link(true);
  session s(link);
  EXPECT_FALSE(s.poll_until_idle()) << "it did not come to rest";
  EXPECT_EQ(link.polls, session::max_zero_time_polls);
  EXPECT_EQ(s.now_us(), 0u);
}

TEST(poll_until_idle, a_bus_is_polled_once_and_its_answer_comes_with_time) {
  counting_link link(false);
  session s(link);
  ASSERT_TRUE(s.poll_until_idle());  // the start-up reads go as on a bus: with time
  link.polls = 0;
  bool answered = false;
  s.read_object(object_index::modes_of_operation, 0, [&](const result&) { answered = true; });
  EXPECT_TRUE(s.poll_until_idle()) << "nothing on a bus is answered without time: at rest at once";
  EXPECT_EQ(link.polls, 1);
  EXPECT_EQ(s.now_us(), 0u);
  for (int i = 0; i < 100 && !answered; ++i) s.poll(1000);
  EXPECT_TRUE(answered) << "the timed polls bring it";
}

TEST(poll_until_idle, a_completion_that_asks_again_is_said_in_the_next_round_even_on_a_bus) {
  counting_link link(false);
  session s(link);
  ASSERT_TRUE(s.poll_until_idle());
  link.polls = 0;
  // Text into an integer object is refused before anything is sent; its answer comes from the
  // next poll, and the second refusal, asked from the first's completion, from the one after.
  int refusals = 0;
  const object_value text = object_value::of_text("x");
  s.write_object(object_index::target_velocity, 0, text, [&](const result& r) {
    EXPECT_TRUE(r.bad_input);
    ++refusals;
    s.write_object(object_index::target_velocity, 0, text, [&](const result& r2) {
      EXPECT_TRUE(r2.bad_input);
      ++refusals;
    });
  });
  EXPECT_TRUE(s.poll_until_idle());
  EXPECT_EQ(refusals, 2);
  EXPECT_EQ(link.polls, 2);
}

}  // namespace
}  // namespace cia402::axes::test
