// Homing made visible and the drive's own error list (issue 35; docs/instrument-page.md, "Modes and
// homing"): POST /api/homing writes the homing objects and runs method 3 on the virtual drive; the
// snapshot's homing phase is inferred from the status bits and the speed (mode_view.hpp), exhaustive
// over the homing status bits; a bit toggle of bit 4 names it as the mode does; the drive's 0x1003
// is read when the error code changes and on request, and POST /api/errors/clear empties it.
#include <set>
#include <string>

#include "mode_view.hpp"
#include "page_server_fixture.hpp"

namespace cia402::page::testing {
namespace {

using detail::mode_reading;
using motion::homing_phase;

class homing_page : public page_server {
 protected:
  void SetUp() override { start(false); }
  json state() { return json::parse(inst.snapshot_json()); }
  json body_of(const httplib::Result& r) { return r ? json::parse(r->body, nullptr, false) : json(); }
};

TEST_F(homing_page, parameters_are_written_through_the_session_and_shown_in_the_snapshot) {
  const auto r = post("/api/homing", R"({"method":3,"fast":400,"slow":40,"acceleration":20000,"offset":-5})");
  ASSERT_TRUE(ok_reply(r));
  EXPECT_EQ(body_of(r)["text"], "0x6098 = 3, 0x6099:1 = 400, 0x6099:2 = 40, 0x609A = 20000, 0x607C = -5");
  const json h = state()["homing"];
  EXPECT_EQ(h["method"], 3);
  EXPECT_EQ(h["fast"], 400);
  EXPECT_EQ(h["slow"], 40);
  EXPECT_EQ(h["acceleration"], 20000);
  EXPECT_EQ(h["offset"], -5);
  EXPECT_EQ(h["phase"], nullptr) << "not in homing mode";
}

TEST_F(homing_page, a_value_outside_the_object_table_is_refused_and_nothing_is_written) {
  const json before = state()["homing"];
  const auto r = post("/api/homing", R"({"method":3,"acceleration":0})");
  expect_refused(r, 422, "0x609A = 0");
  EXPECT_EQ(body_of(r)["abort"], "0x06090032") << "value too low";
  EXPECT_EQ(state()["homing"], before) << "the method before it was not written either";
  expect_refused(post("/api/homing", R"({"fast":"fast"})"), 400, "'fast' must be an integer");
  expect_refused(post("/api/homing", R"({"start":1})"), 400, "'start' must be true");
  expect_refused(post("/api/homing", R"({})"), 400, "nothing to do");
  expect_refused(post("/api/homing", R"({"axis":1})"), 400, "unknown key 'axis'");
}

// Method 3 at the table's default speeds on the default plant (home switch 5 revolutions up):
// the phases in order, the home switch bit of 0x60FD on the way, attained within 3 s of drive time.
// The mode panel's set-point follows the mode the drive shows: pv's 0x60FF, then pp's 0x607A.
TEST_F(homing_page, the_set_point_shown_is_the_one_of_the_mode_the_drive_shows) {
  const json pv = state()["set_point"];
  EXPECT_EQ(pv["index"], "0x60FF") << pv;
  EXPECT_EQ(pv["name"], "Target velocity") << pv;
  EXPECT_EQ(pv["cyclic"], true) << "the local drive's own value, each cycle";
  ASSERT_TRUE(post("/api/object", R"({"index":"0x60FF","value":250})"));
  ASSERT_TRUE(post("/api/object", R"({"index":"0x607A","value":-1234})"));
  ASSERT_TRUE(post("/api/object", R"({"index":"0x6060","value":1})"));
  step(20);
  const json pp = state()["set_point"];
  EXPECT_EQ(pp["index"], "0x607A") << pp;
  EXPECT_EQ(pp["value"], -1234) << pp;
}

TEST_F(homing_page, method_3_at_the_default_speeds_is_attained_within_3_s_with_its_phases) {
  const auto r = post("/api/homing", R"({"method":3,"start":true})");
  ASSERT_TRUE(ok_reply(r));
  std::set<std::string> phases;
  bool home_switch_seen = false;
  int cycles = 0;
  json s;
  for (; cycles < 3000; ++cycles) {
    step(1);
    s = state();
    if (s["homing"]["phase"].is_string()) phases.insert(s["homing"]["phase"].get<std::string>());
    if (s["digital_inputs"].is_number() && (s["digital_inputs"].get<std::int64_t>() & 4) != 0) home_switch_seen = true;
    if (s["homing"]["phase"] == "homing attained" && !s["homing"]["running"].get<bool>()) break;
  }
  ASSERT_LT(cycles, 3000) << "not attained in 3 s; phases seen: " << json(phases).dump();
  EXPECT_TRUE(home_switch_seen);
  EXPECT_TRUE(phases.count("searching home switch at 0x6099:1 = 1000 rpm")) << json(phases).dump();
  EXPECT_TRUE(phases.count("searching index pulse at 0x6099:2 = 100 rpm")) << json(phases).dump();
  EXPECT_EQ(s["doing_now"], "homing: homing attained");
  EXPECT_TRUE(s["set_point"].is_null()) << "homing has no set-point of its own: " << s["set_point"];
  EXPECT_EQ(s["results"][0]["text"], "done: homing attained, 0x6064 = 0");
}

TEST_F(homing_page, a_start_where_the_profile_names_bit_4_itself_is_refused) {
  inst.select_profile("s300-profibus");
  step(10);
  const json before = state()["control_word"];
  expect_refused(post("/api/homing", R"({"start":true})"), 409, "no homing operation start on it");
  step(3);
  EXPECT_EQ(state()["control_word"], before);
}

TEST_F(homing_page, a_run_stopped_from_the_page_ends_superseded_and_stands) {
  ASSERT_EQ(post("/api/homing", R"({"method":1,"start":true})")->status, 200);  // 100 revolutions away
  step(500);
  EXPECT_EQ(state()["homing"]["phase"], "searching limit switch at 0x6099:1 = 1000 rpm");
  ASSERT_EQ(post("/api/homing", R"({"start":false})")->status, 200);
  step(100);
  EXPECT_EQ(state()["homing"]["phase"], "stopping") << "on the profile deceleration 0x6084 (1000 rpm/s)";
  step(1500);
  const json s = state();
  EXPECT_EQ(s["homing"]["phase"], "interrupted or not started");
  EXPECT_FALSE(s["homing"]["running"].get<bool>());
  EXPECT_EQ(s["velocity"], 0);
  EXPECT_EQ(s["results"][0]["text"], "done: stopped");
  EXPECT_EQ(s["results"][1]["text"], "refused: superseded by another homing request");
}

TEST_F(homing_page, bit_4_toggled_in_homing_mode_says_homing_operation_start) {
  ASSERT_EQ(post("/api/object", R"({"index":"0x6060","value":6})")->status, 200);
  step(5);
  const auto r = post("/api/command", R"({"command":"toggle_bit","bit":4})");
  ASSERT_TRUE(ok_reply(r));
  const std::string text = state()["results"][0]["text"];
  EXPECT_EQ(text, "done: Homing operation start (bit 4 in mode 6)");
}

TEST_F(homing_page, a_fault_enters_the_drive_error_field_and_clear_empties_it) {
  EXPECT_EQ(state()["drive_errors"]["count"], 0);
  ASSERT_EQ(post("/api/plant", R"({"fault":true,"fault_code":"0x2310"})")->status, 200);
  step(5);
  const json d = state()["drive_errors"];
  ASSERT_EQ(d["count"], 1) << d.dump();
  EXPECT_EQ(d["entries"][0]["code"], "0x2310");
  EXPECT_EQ(d["entries"][0]["text"], "continuous over-current");
  const auto listed = client->Get("/api/errors");
  ASSERT_TRUE(listed);
  EXPECT_EQ(json::parse(listed->body)["entries"][0]["code"], "0x2310") << listed->body;
  const auto read = post("/api/errors/read", "{}");
  ASSERT_TRUE(ok_reply(read));
  EXPECT_EQ(body_of(read)["text"], "0x1003 holds 1 error(s)");
  ASSERT_EQ(post("/api/errors/clear", "{}")->status, 200);
  step(3);
  EXPECT_EQ(state()["drive_errors"]["count"], 0);
  EXPECT_TRUE(state()["drive_errors"]["entries"].empty());
  expect_refused(post("/api/errors/clear", R"({"sub":0})"), 400, "unknown key 'sub'");
}

// --- the inference, on its own -----------------------------------------------------------------

mode_reading homing_run(std::uint16_t status_bits, bool bit4) {
  mode_reading r;
  r.enabled = true;
  r.mode = 6;
  r.status_word = status_bits;
  r.control_word = bit4 ? 0x001F : 0x000F;
  r.velocity_rpm = 0;
  r.homing_method = 3;
  r.switch_speed_rpm = 1000;
  r.zero_speed_rpm = 100;
  return r;
}

// CiA 402-2's table of status bits 13 / 12 / 10, each combination with bit 4 up and down.
TEST(homing_phase_inference, every_combination_of_bits_13_12_10_and_control_bit_4) {
  for (int bits = 0; bits < 8; ++bits) {
    for (const bool start : {false, true}) {
      const bool b10 = (bits & 1) != 0, b12 = (bits & 2) != 0, b13 = (bits & 4) != 0;
      const std::uint16_t sw = static_cast<std::uint16_t>((b10 ? 1u << 10 : 0) | (b12 ? 1u << 12 : 0) | (b13 ? 1u << 13 : 0));
      const homing_phase p = detail::infer_homing_phase(homing_run(sw, start));
      homing_phase expected = homing_phase::not_started;
      if (b13) expected = homing_phase::error;
      else if (b12) expected = b10 ? homing_phase::attained : homing_phase::moving_to_zero;
      else if (b10) expected = start ? homing_phase::interrupted : homing_phase::not_started;
      else expected = start ? homing_phase::stopping_past_home : homing_phase::not_started;
      EXPECT_EQ(static_cast<int>(p), static_cast<int>(expected)) << "bits " << bits << " start " << start;
    }
  }
}

TEST(homing_phase_inference, the_speed_tells_the_switch_search_from_the_index_search) {
  mode_reading r = homing_run(0, true);
  r.velocity_rpm = 1000;
  EXPECT_EQ(detail::homing_phase_text(r), "searching home switch at 0x6099:1 = 1000 rpm");
  r.velocity_rpm = -95;
  EXPECT_EQ(detail::homing_phase_text(r), "searching index pulse at 0x6099:2 = 100 rpm");
  r.homing_method = 19;  // without an index pulse: the edge itself
  EXPECT_EQ(detail::homing_phase_text(r), "searching the switch edge at 0x6099:2 = 100 rpm");
  r.homing_method = 1;
  r.velocity_rpm = -1000;
  EXPECT_EQ(detail::homing_phase_text(r), "searching limit switch at 0x6099:1 = 1000 rpm");
  r.control_word = 0x000F;  // bit 4 down: the run was stopped
  EXPECT_EQ(detail::homing_phase_text(r), "stopping") << "still turning";
  r.velocity_rpm = 0;
  r.status_word = 1u << 10;
  EXPECT_EQ(detail::homing_phase_text(r), "interrupted or not started") << "CiA 402-2's words for 0/0/1";
  r.mode = 3;
  EXPECT_EQ(detail::infer_homing_phase(r), homing_phase::not_started) << "not in homing mode";
}

TEST(doing_now, says_what_the_active_mode_does_from_its_handshake_bits) {
  mode_reading r;
  r.enabled = true;
  r.mode = 1;
  r.target_position = 20000;
  r.control_word = 0x001F;
  r.status_word = 1u << 12;
  EXPECT_EQ(detail::doing_now(r), "moving to 20000 (set-point acknowledged)");
  r.status_word = 1u << 10;
  EXPECT_EQ(detail::doing_now(r), "target reached (0x607A = 20000)");
  r.mode = 8;
  r.status_word = 0;
  EXPECT_EQ(detail::doing_now(r), "ignoring the command value (status bit 12 = 0)");
  r.status_word = 1u << 12;
  EXPECT_EQ(detail::doing_now(r), "following the command value (0x607A = 20000)");
  r.mode = 3;
  r.target_velocity = 500;
  r.status_word = 1u << 10;
  EXPECT_EQ(detail::doing_now(r), "at 0x60FF = 500 rpm (target reached)");
  r.control_word = 0x010F;
  EXPECT_EQ(detail::doing_now(r), "halted (control bit 8), standing");
  r.enabled = false;
  EXPECT_EQ(detail::doing_now(r), "no motion: not OPERATION ENABLED");
}

}  // namespace
}  // namespace cia402::page::testing
