// The page's HTTP server in-process on a free loopback port, driven by cpp-httplib's client: bad
// requests get a 4xx with a JSON reason and change nothing; with a token required the page is
// view-only without it; the event stream delivers snapshots as the drive changes.
#include <gtest/gtest.h>
#include <ifaddrs.h>
#include <unistd.h>
#include <sys/socket.h>
#include <poll.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <atomic>
#include <mutex>
#include <thread>

#include "event_stream_reader.hpp"
#include "page_server_fixture.hpp"

namespace {

using cia402::page::testing::virtual_axis_page;
using cia402::page::server;
using cia402::page::server_options;
using json = nlohmann::json;

using cia402::page::testing::token;
using cia402::page::testing::ok_reply;
using cia402::page::testing::page_server;

// Two servers on one port would answer in turn, so the page could show one drive while its
// commands go to the other: the second bind is refused with a message that says why.
TEST_F(page_server, a_second_server_on_the_same_port_is_refused) {
  start(false);
  virtual_axis_page other{cia402::standard_profile()};
  server_options o;
  o.bind = "127.0.0.1";
  o.port = http->bound_port();
  server second(other, o);
  EXPECT_FALSE(second.bind());
  EXPECT_NE(second.error().find("address in use"), std::string::npos) << second.error();
}

TEST_F(page_server, page_and_its_files_are_served_from_the_binary) {
  start(false);
  const auto page = client->Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<svg id=\"diagram\""), std::string::npos);
  EXPECT_NE(page->get_header_value("Content-Security-Policy").find("script-src 'self'"),
            std::string::npos);
  for (const char* f : {"/app.js", "/style.css"}) {
    const auto r = client->Get(f);
    ASSERT_TRUE(r) << f;
    EXPECT_EQ(r->status, 200) << f;
    EXPECT_GT(r->body.size(), 1000u) << f;
  }
}

TEST_F(page_server, a_valid_command_is_obeyed) {
  start(false);
  ASSERT_TRUE(ok_reply(post("/api/command", R"({"command":"shutdown"})")));
  step(5);
  EXPECT_EQ(json::parse(inst.snapshot_json())["state"], "READY_TO_SWITCH_ON");
}

// The recorder keeps every transition with its time and words, gives the page only what it has not
// seen, and exports the same cycles as CSV and as IEEE 1364 VCD (or GTKWave's form on request).
// The new set-point handshake of profile position over HTTP: refused (409) in profile velocity,
// obeyed in pp.
TEST_F(page_server, new_setpoint_is_a_command_of_profile_position) {
  start(false);
  expect_refused(post("/api/command", R"({"command":"new_setpoint"})"), 409, "profile position");
  auto r = post("/api/object", R"({"index":"0x6060","value":1})");
  ASSERT_TRUE(ok_reply(r));
  step(5);
  r = post("/api/command", R"({"command":"new_setpoint"})");
  ASSERT_TRUE(ok_reply(r));
  const json s = json::parse(inst.snapshot_json());
  EXPECT_EQ(s["results"][0]["action"], "NEW_SET-POINT");
}

TEST_F(page_server, recorder_keeps_every_transition_and_exports_csv_and_vcd) {
  start(false);
  for (const char* c : {"shutdown", "switch_on", "enable_operation", "disable_voltage"}) {
    ASSERT_EQ(post("/api/command", std::string(R"({"command":")") + c + "\"}")->status, 200);
    step(20);
  }
  const auto all = client->Get("/api/recording");
  ASSERT_TRUE(all);
  ASSERT_EQ(all->status, 200);
  const json rec = json::parse(all->body);
  // Power-up (T0, T1), then T2, T3, T4 and T9: OPERATION ENABLED by disable voltage.
  std::vector<int> numbers;
  for (const json& t : rec["transitions"]) numbers.push_back(t["number"].get<int>());
  EXPECT_EQ(numbers, (std::vector<int>{0, 1, 2, 3, 4, 9})) << rec["transitions"].dump();
  const json& t4 = rec["transitions"][4];
  EXPECT_EQ(t4["from"], "SWITCHED_ON");
  EXPECT_EQ(t4["to"], "OPERATION_ENABLED");
  EXPECT_EQ(t4["control_word"], "0x000F");
  EXPECT_EQ(t4["status_word"].get<std::string>().substr(4), "37") << t4;
  EXPECT_GT(t4["time_ms"].get<int>(), rec["transitions"][3]["time_ms"].get<int>());
  // Only what came after: nothing new without a cycle, the next transition after one more command.
  const std::string seen = "?rows_seen=" + std::to_string(rec["rows_seen"].get<std::uint64_t>()) +
                           "&transitions_seen=" +
                           std::to_string(rec["transitions_seen"].get<std::uint64_t>());
  const json none = json::parse(client->Get(("/api/recording" + seen).c_str())->body);
  EXPECT_TRUE(none["transitions"].empty());
  EXPECT_TRUE(none["rows"].empty());
  ASSERT_EQ(post("/api/command", R"({"command":"shutdown"})")->status, 200);
  step(20);
  const json next = json::parse(client->Get(("/api/recording" + seen).c_str())->body);
  ASSERT_EQ(next["transitions"].size(), 1u) << next.dump();
  EXPECT_EQ(next["transitions"][0]["number"], 2);
  EXPECT_FALSE(next["rows"].empty());
  EXPECT_EQ(client->Get("/api/recording?rows_seen=x")->status, 400);

  const auto csv = client->Get("/api/recording.csv");
  ASSERT_TRUE(csv);
  EXPECT_EQ(csv->status, 200);
  EXPECT_EQ(csv->body.rfind("time_us,controlword,statusword,state,transition", 0), 0u) << csv->body;
  EXPECT_NE(csv->get_header_value("Content-Disposition").find("attachment"), std::string::npos);
  // One line per kept row: every transition is a line of its own.
  for (const char* row : {",OPERATION_ENABLED,4,", ",SWITCH_ON_DISABLED,9,"}) {
    EXPECT_NE(csv->body.find(row), std::string::npos) << row;
  }
  const auto vcd = client->Get("/api/recording.vcd");
  ASSERT_TRUE(vcd);
  EXPECT_EQ(vcd->body.find("$var string"), std::string::npos);
  EXPECT_NE(vcd->body.find("$timescale"), std::string::npos);
  const auto gtk = client->Get("/api/recording.vcd?form=gtkwave");
  EXPECT_NE(gtk->body.find("$var string"), std::string::npos);
  EXPECT_EQ(client->Get("/api/recording.vcd?form=svg")->status, 400);
}

TEST_F(page_server, malformed_json_is_400_with_a_reason_and_changes_nothing) {
  start(false);
  expect_unchanged_by([&] {
    expect_refused(post("/api/command", R"({"command":"shutdown")"), 400, "not valid JSON");
    expect_refused(post("/api/command", R"(["shutdown"])"), 400, "JSON object");
    expect_refused(post("/api/plant", ""), 400, "not valid JSON");
  });
}

TEST_F(page_server, unknown_commands_keys_and_values_are_400_and_change_nothing) {
  start(false);
  expect_unchanged_by([&] {
    expect_refused(post("/api/command", R"({"command":"launch"})"), 400, "unknown command");
    expect_refused(post("/api/command", R"({"command":"shutdown","extra":1})"), 400,
                   "unknown key 'extra'");
    expect_refused(post("/api/command", R"({"command":5})"), 400, "'command'");
    expect_refused(post("/api/command", R"({"command":"toggle_bit","bit":16})"), 400, "0..15");
    expect_refused(post("/api/command", R"({"command":"toggle_bit","bit":"x"})"), 400, "0..15");
    expect_refused(post("/api/command", R"({"command":"shutdown","bit":1})"), 400, "toggle_bit");
    expect_refused(post("/api/plant", R"({})"), 400, "nothing to change");
    expect_refused(post("/api/plant", R"({"sto":"yes"})"), 400, "true or false");
    expect_refused(post("/api/plant", R"({"target_velocity":1.5})"), 400, "integer");
    expect_refused(post("/api/object", R"({"index":"0x605A"})"), 400, "required");
    expect_refused(post("/api/object", R"({"index":"0x1FFFF","value":1})"), 400, "'index'");
  });
}

TEST_F(page_server, a_plant_request_with_one_bad_field_applies_none_of_it) {
  start(false);
  const json before = observable();
  expect_refused(post("/api/plant", R"({"sto":true,"dc_link":false,"fault":true,"fault_code":0})"),
                 400, "fault_code");
  expect_refused(post("/api/plant", R"({"sto":true,"fault":true,"fault_class":5})"), 400,
                 "fault_class");
  expect_refused(post("/api/plant", R"({"sto":true,"fault_code":"0x1000"})"), 400,
                 "goes with");
  // The drive refuses the velocity (beyond INT32): the STO in the same request is not applied.
  expect_refused(post("/api/plant", R"({"sto":true,"target_velocity":1099511627776})"), 422,
                 "SDO abort");
  step(5);
  json after = observable();
  // The refused velocity write is reported as a result; everything else is as before.
  EXPECT_EQ(after[0], before[0]);
  EXPECT_EQ(after[1], before[1]);
  EXPECT_EQ(after[2], before[2]);
  EXPECT_EQ(after[3], before[3]);
  EXPECT_EQ(after[4], before[4]);
  EXPECT_EQ(after[5], before[5]);
  EXPECT_EQ(after[6], before[6]);
}

TEST_F(page_server, body_over_4_kib_is_413_with_a_reason_and_changes_nothing) {
  start(false);
  expect_unchanged_by([&] {
    const std::string big = R"({"command":"shutdown","pad":")" + std::string(5000, 'x') + "\"}";
    expect_refused(post("/api/command", big), 413, "4096");
  });
}

TEST_F(page_server, wrong_content_type_is_415_and_changes_nothing) {
  start(false);
  expect_unchanged_by([&] {
    expect_refused(post("/api/command", R"({"command":"shutdown"})", {}, "text/plain"), 415,
                   "application/json");
    // A type that only starts with application/json is another type.
    for (const char* type : {"application/jsonx", "application/json-seq", "application/json5"}) {
      expect_refused(post("/api/command", R"({"command":"shutdown"})", {}, type), 415,
                     "application/json");
    }
  });
  // Parameters are allowed, and the type is case-insensitive.
  const auto ok = post("/api/command", R"({"command":"shutdown"})", {},
                       "Application/JSON; charset=utf-8");
  ASSERT_TRUE(ok_reply(ok));
}

TEST_F(page_server, a_key_given_twice_is_400_and_changes_nothing) {
  start(false);
  expect_unchanged_by([&] {
    expect_refused(post("/api/command", R"({"command":"shutdown","command":"switch_on"})"), 400,
                   "given twice");
    expect_refused(post("/api/plant", R"({"sto":false,"sto":true})"), 400, "given twice");
  });
}

// Requests in a row are answered promptly: the guard's wait for a complete head and the
// connection per request cost no more than a few milliseconds each (kept-alive requests without
// TCP_NODELAY used to wait ~40 ms each for a delayed ACK).
TEST_F(page_server, requests_in_a_row_are_answered_promptly) {
  start(false);
  client->set_tcp_nodelay(true);  // the client's own writes must not wait either
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 20; ++i) {
    const auto r = post("/api/command", R"({"command":"toggle_bit","bit":11})");
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200);
  }
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::steady_clock::now() - t0).count();
  // 20 x 40 ms would be 800 ms; a loaded machine still answers well below that.
  EXPECT_LT(ms, 400) << ms << " ms for 20 requests";
}

TEST_F(page_server, option_write_refused_by_the_drive_is_422_with_its_sdo_abort) {
  start(false);
  const auto r = post("/api/object", R"({"index":"0x605A","value":9})");
  expect_refused(r, 422, "0x06090030");
  EXPECT_EQ(json::parse(r->body)["abort"], "0x06090030");
  EXPECT_EQ(json::parse(inst.snapshot_json())["objects"]["0x605A"], 2);
  const auto ok = post("/api/object", R"({"index":"0x605A","value":6})");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200);
  EXPECT_EQ(json::parse(inst.snapshot_json())["objects"]["0x605A"], 6);
}

TEST_F(page_server, unknown_paths_are_404_and_get_on_a_command_path_is_405_both_json) {
  start(false);
  const auto r = client->Get("/etc/passwd");
  expect_refused(r, 404, "no such resource");
  expect_refused(client->Get("/api/command"), 405, "POST");
}

TEST_F(page_server, cross_origin_post_is_403_and_changes_nothing) {
  start(false);
  expect_unchanged_by([&] {
    expect_refused(post("/api/command", R"({"command":"shutdown"})",
                        {{"Origin", "http://evil.example"}}),
                   403, "cross-origin");
  });
}

TEST_F(page_server, without_token_a_post_naming_a_foreign_host_is_403) {
  // DNS rebinding: a foreign name resolving to 127.0.0.1 arrives with its own Host header.
  start(false);
  expect_unchanged_by([&] {
    expect_refused(post("/api/command", R"({"command":"shutdown"})", {{"Host", "evil.example"}}),
                   403, "loopback");
  });
}

TEST_F(page_server, token_required_refuses_control_without_the_token_and_changes_nothing) {
  start(true);
  expect_unchanged_by([&] {
    expect_refused(post("/api/command", R"({"command":"shutdown"})"), 403, "token");
    expect_refused(post("/api/command", R"({"command":"shutdown"})", {{"X-Cia402-Token", "wrong"}}),
                   403, "token");
    expect_refused(post("/api/plant", R"({"sto":true})"), 403, "token");
    expect_refused(post("/api/object", R"({"index":"0x605A","value":6})"), 403, "token");
  });

  ASSERT_TRUE(ok_reply(post("/api/command", R"({"command":"shutdown"})", {{"X-Cia402-Token", token}})));
  step(5);
  EXPECT_EQ(json::parse(inst.snapshot_json())["state"], "READY_TO_SWITCH_ON");
}

TEST_F(page_server, token_required_info_says_view_only_without_the_token) {
  start(true);
  const auto view = client->Get("/api/info");
  ASSERT_TRUE(view);
  EXPECT_EQ(json::parse(view->body)["control"], false);
  EXPECT_EQ(json::parse(view->body)["token_required"], true);
  const auto control = client->Get("/api/info", {{"X-Cia402-Token", token}});
  ASSERT_TRUE(control);
  EXPECT_EQ(json::parse(control->body)["control"], true);
  // Viewing needs no token: state and events are open.
  const auto state = client->Get("/api/state");
  ASSERT_TRUE(state);
  EXPECT_EQ(state->status, 200);
  EXPECT_NE(http->url().find("?token=" + std::string(token)), std::string::npos);
}

TEST_F(page_server, loopback_without_token_required_gives_control) {
  start(false);
  const auto r = client->Get("/api/info");
  ASSERT_TRUE(r);
  EXPECT_EQ(json::parse(r->body)["control"], true);
  EXPECT_EQ(http->url().find("token"), std::string::npos);
}

// Reads /api/events until `done` says the text is enough.
class event_reader {
 public:
  event_reader(int port, std::function<bool(const std::string&)> done)
      : done_(std::move(done)), stream_(port, [this](std::string_view piece) {
          text_.append(piece);
          finished_ = done_(text_);
          return !finished_;
        }) {}
  void join() { stream_.join(); }
  std::string text() {
    return stream_.locked([this] { return text_; });
  }
  bool finished() {
    return stream_.locked([this] { return finished_; });
  }

 private:
  std::function<bool(const std::string&)> done_;
  std::string text_;
  bool finished_ = false;
  cia402::page::testing::event_stream_reader stream_;  // last: its thread uses the members above
};

TEST_F(page_server, event_stream_sends_a_snapshot_at_once_then_the_states_the_drive_takes) {
  start(false);
  cia402::page::cycle_runner runner(inst, std::chrono::microseconds(1000));
  runner.start();
  event_reader events(http->bound_port(), [](const std::string& t) {
    return t.find(R"("state":"OPERATION_ENABLED")") != std::string::npos;
  });
  // The first event comes at once, before anything changes.
  for (int i = 0; i < 200 && events.text().find("data: {") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_NE(events.text().find(R"(data: {"state":"SWITCH_ON_DISABLED")"), std::string::npos)
      << events.text();
  post("/api/command", R"({"command":"shutdown"})");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  post("/api/command", R"({"command":"enable_operation"})");
  events.join();
  runner.stop();
  const std::string t = events.text();
  EXPECT_TRUE(events.finished()) << t;
  EXPECT_NE(t.find(R"("state":"READY_TO_SWITCH_ON")"), std::string::npos);
  EXPECT_NE(t.find(R"("last_transition":{"number":4)"), std::string::npos);
}

TEST_F(page_server, event_stream_sends_keep_alive_comments_when_nothing_changes) {
  start(false);  // nothing steps: nothing is published
  event_reader events(http->bound_port(), [](const std::string& t) {
    return t.find(": keep-alive\n\n") != std::string::npos;
  });
  events.join();
  EXPECT_TRUE(events.finished()) << events.text();
}

TEST_F(page_server, stop_ends_open_event_streams_promptly) {
  start(false);
  event_reader events(http->bound_port(), [](const std::string&) { return false; });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto t0 = std::chrono::steady_clock::now();
  http->stop();
  events.join();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
}

TEST(page_server_address, loopback_addresses_are_recognised) {
  using cia402::page::is_loopback_address;
  EXPECT_TRUE(is_loopback_address("127.0.0.1"));
  EXPECT_TRUE(is_loopback_address("127.1.2.3"));
  EXPECT_TRUE(is_loopback_address("::1"));
  EXPECT_TRUE(is_loopback_address("localhost"));
  EXPECT_FALSE(is_loopback_address("0.0.0.0"));
  EXPECT_FALSE(is_loopback_address("::"));
  EXPECT_FALSE(is_loopback_address("192.168.1.10"));
  EXPECT_FALSE(is_loopback_address("128.0.0.1"));
  EXPECT_FALSE(is_loopback_address("localhost.evil.example"));
}

TEST(page_server_token, tokens_are_32_hex_digits_and_differ) {
  const std::string a = cia402::page::make_token();
  const std::string b = cia402::page::make_token();
  EXPECT_EQ(a.size(), 32u);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_NE(a, b);
}

}  // namespace

namespace {

// Several drives behind one page: each request names its axis, and one axis's command, profile
// and recording leave the others alone.
TEST(page_server_axes, each_axis_is_its_own_drive_and_may_switch_profile) {
  virtual_axis_page one{cia402::standard_profile()};
  virtual_axis_page two{cia402::standard_profile()};
  server_options o;
  o.port = 0;
  server http({{"axis 1", &one}, {"axis 2", &two}}, o);
  ASSERT_TRUE(http.bind()) << http.error();
  http.start();
  httplib::Client client("127.0.0.1", http.bound_port());
  for (int i = 0; i < 10; ++i) {
    one.step();
    two.step();
  }
  ASSERT_TRUE(ok_reply(client.Post("/api/command?axis=2", R"({"command":"shutdown"})", "application/json")));
  for (int i = 0; i < 10; ++i) {
    one.step();
    two.step();
  }
  const json axes = json::parse(client.Get("/api/axes")->body);
  ASSERT_EQ(axes.size(), 2u);
  EXPECT_EQ(axes[0]["label"], "axis 1");
  EXPECT_EQ(axes[0]["state"], "SWITCH_ON_DISABLED");
  EXPECT_EQ(axes[1]["state"], "READY_TO_SWITCH_ON");
  const json info2 = json::parse(client.Get("/api/info?axis=2")->body);
  EXPECT_EQ(info2["axis"], 2);
  EXPECT_EQ(info2["axes"], 2);
  for (const char* bad : {"/api/state?axis=3", "/api/state?axis=0", "/api/info?axis=x"}) {
    EXPECT_EQ(client.Get(bad)->status, 404) << bad;
  }
  EXPECT_EQ(client.Post("/api/command?axis=3", R"({"command":"shutdown"})", "application/json")->status,
            404);

  // Axis 1 under the PROFIBUS profile of seed 003: from power-up, with its own words.
  ASSERT_TRUE(ok_reply(client.Post("/api/profile?axis=1", R"({"profile":"s300-profibus"})", "application/json")));
  for (int i = 0; i < 10; ++i) one.step();
  const json info1 = json::parse(client.Get("/api/info")->body);
  EXPECT_EQ(info1["profile"]["name"], "s300-profibus");
  EXPECT_EQ(info1["state_names"]["SWITCH_ON_DISABLED"], "Switch-on inhibited");
  EXPECT_EQ(info1["command_labels"]["quick_stop"], "Fast stop");
  const json s1 = json::parse(client.Get("/api/state")->body);
  EXPECT_EQ(s1["profile"], "s300-profibus");
  EXPECT_EQ(s1["state"], "SWITCH_ON_DISABLED");
  const json rec = json::parse(client.Get("/api/recording")->body);
  ASSERT_FALSE(rec["transitions"].empty());
  EXPECT_EQ(rec["transitions"][0]["number"], 0);  // a new recording from power-up
  EXPECT_EQ(json::parse(client.Get("/api/state?axis=2")->body)["profile"], "cia402");
  const auto unknown = client.Post("/api/profile", R"({"profile":"nonesuch"})", "application/json");
  EXPECT_EQ(unknown->status, 400);
  EXPECT_NE(unknown->body.find("ax2000-profibus"), std::string::npos) << unknown->body;
  http.stop();
}

}  // namespace
