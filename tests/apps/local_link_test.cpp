// The link to a virtual drive in this process: an axis session over it reaches the drive as over a
// bus (the same dictionary rules and abort codes, a cycle per simulator step, every mappable object
// each cycle), and it keeps 0x1003 as a CiA 301 node does.
#include <gtest/gtest.h>

#include <functional>
#include <optional>

#include "cia402/apps/local_link.hpp"
#include "cia402/axis/session.hpp"
#include "cia402/objects.hpp"

namespace cia402::apps {
namespace {

struct local_bench {
  local_link link{standard_profile()};
  axes::session s{link};

  bool run_until(const std::function<bool()>& done, int ms = 5000) {
    for (int i = 0; i < ms; ++i) {
      (void)s.poll(1000);
      if (done()) return true;
    }
    return false;
  }
  axes::result finish(const std::function<std::uint64_t(axes::completion)>& request) {
    std::optional<axes::result> got;
    request([&](const axes::result& r) { got = r; });
    EXPECT_TRUE(run_until([&] { return got.has_value(); }, 20000));
    return got.value_or(axes::result{});
  }
  axes::result read(std::uint16_t index, std::uint8_t sub) {
    return finish([&](axes::completion d) { return s.read_object(index, sub, std::move(d)); });
  }
  axes::result write(std::uint16_t index, std::uint8_t sub, std::int64_t v) {
    return finish([&](axes::completion d) {
      return s.write_object(index, sub, axes::object_value::of_integer(v), std::move(d));
    });
  }
};

TEST(local_link, one_cycle_per_simulator_step_and_the_status_word_of_each) {
  local_link link(standard_profile());
  int cycles = 0;
  link.before_cycle = [&] { ++cycles; };
  (void)link.poll(10'500);
  EXPECT_EQ(cycles, 10);
  EXPECT_EQ(link.status_count(), 10u);
  EXPECT_EQ(link.drive().cycle(), 10u);
  EXPECT_EQ(link.status_word(), link.drive().view().outputs().status_word);
}

TEST(local_link, a_session_enables_the_drive_and_moves_it_in_pp) {
  local_bench b;
  const axes::result r = b.finish([&](axes::completion d) { return b.s.move({12345, false, 600u}, std::move(d)); });
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(b.link.drive().view().position(), 12345);
  EXPECT_EQ(b.link.drive().view().current(), state::operation_enabled);
}

TEST(local_link, every_mappable_object_is_a_cyclic_input) {
  local_bench b;
  (void)b.s.poll(5000);
  const auto fd = b.link.cyclic_input(object_index::digital_inputs, 0);
  ASSERT_TRUE(fd) << "0x60FD each cycle";
  EXPECT_EQ(*fd, b.link.drive().view().digital_inputs());
  EXPECT_FALSE(b.link.cyclic_input(0x605A, 0)) << "0x605A is not mappable";
}

TEST(local_link, refusals_carry_the_abort_codes_of_the_buses) {
  local_bench b;
  const axes::result bad = b.write(0x605A, 0, 9);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.error.find("0x06090030"), std::string::npos) << bad.error;
  const axes::result ro = b.write(0x1018, 1, 5);
  EXPECT_NE(ro.error.find("0x06010002"), std::string::npos) << ro.error;
  const axes::result none = b.read(0x2FFF, 0);
  EXPECT_NE(none.error.find("0x06020000"), std::string::npos) << none.error;
  const axes::result name = b.read(0x1008, 0);
  ASSERT_TRUE(name.ok()) << name.error;
  EXPECT_EQ(name.value->text, "cia402 virtual drive");
}

TEST(local_link, error_history_0x1003_keeps_each_new_code_newest_first_and_0_empties_it) {
  local_bench b;
  b.run_until([] { return false; }, 20);
  EXPECT_EQ(b.read(0x1003, 0).value->number, 0);
  EXPECT_NE(b.read(0x1003, 1).error.find("0x08000024"), std::string::npos) << "no entry: no data";
  for (const std::uint16_t code : {std::uint16_t{0x2310}, std::uint16_t{0x4210}}) {
    b.link.drive().view().inject_fault(code);
    ASSERT_TRUE(b.run_until([&] { return b.link.drive().view().outputs().error_code == code; }));
    b.link.drive().view().clear_faults();
    ASSERT_TRUE(b.finish([&](axes::completion d) { return b.s.reset(std::move(d)); }).ok());
  }
  EXPECT_EQ(b.read(0x1003, 0).value->number, 2);
  EXPECT_EQ(b.read(0x1003, 1).value->number, 0x4210);
  EXPECT_EQ(b.read(0x1003, 2).value->number, 0x2310);
  EXPECT_NE(b.write(0x1003, 0, 1).error.find("0x06090030"), std::string::npos) << "only 0 may be written";
  ASSERT_TRUE(b.write(0x1003, 0, 0).ok());
  EXPECT_EQ(b.read(0x1003, 0).value->number, 0);
}

TEST(local_link, an_emergency_for_each_change_of_the_error_code) {
  local_link link(standard_profile());
  std::vector<std::uint16_t> codes;
  link.on_emergency = [&](std::uint16_t code, std::uint8_t, std::span<const std::uint8_t>) { codes.push_back(code); };
  (void)link.poll(20'000);
  link.drive().view().inject_fault(0x2310);
  (void)link.poll(20'000);
  link.drive().view().clear_faults();
  link.set_control_word(0x0080);
  (void)link.poll(5'000);
  ASSERT_EQ(codes.size(), 2u);
  EXPECT_EQ(codes[0], 0x2310);
  EXPECT_EQ(codes[1], 0x0000) << "the error reset";
}

}  // namespace
}  // namespace cia402::apps
