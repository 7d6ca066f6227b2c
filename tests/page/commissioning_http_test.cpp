// POST /api/enable, /api/stop and /api/jog through the page's HTTP server in-process (issue 35;
// docs/instrument-page.md, "HTTP API"): the request conventions of every POST (JSON object, no
// unknown key, values in range, token) hold for them, and they reach the drive.
#include <gtest/gtest.h>

#include <httplib.h>

#include <nlohmann/json.hpp>

#include <memory>
#include <string>

#include "virtual_axis_page.hpp"
#include "cia402/page/server.hpp"
#include "cia402/profile.hpp"

namespace {

using cia402::page::testing::virtual_axis_page;
using cia402::page::server;
using cia402::page::server_options;
using json = nlohmann::json;

constexpr const char* token = "0123456789abcdef0123456789abcdef";

class commissioning_http : public ::testing::Test {
 protected:
  void SetUp() override {
    server_options o;
    o.bind = "127.0.0.1";
    o.port = 0;
    o.token_required = true;
    o.token = token;
    http = std::make_unique<server>(inst, o);
    ASSERT_TRUE(http->bind()) << http->error();
    http->start();
    client = std::make_unique<httplib::Client>("127.0.0.1", http->bound_port());
    client->set_read_timeout(5, 0);
    step(10);
  }
  void TearDown() override {
    if (http) http->stop();
  }
  void step(int cycles) {
    for (int i = 0; i < cycles; ++i) inst.step();
  }
  int post(const std::string& path, const std::string& body, bool with_token = true) {
    httplib::Headers h;
    if (with_token) h.emplace("X-Cia402-Token", token);
    const auto r = client->Post(path.c_str(), h, body, "application/json");
    return r ? r->status : 0;
  }
  json state() { return json::parse(inst.snapshot_json()); }

  virtual_axis_page inst{cia402::standard_profile()};
  std::unique_ptr<server> http;
  std::unique_ptr<httplib::Client> client;
};

TEST_F(commissioning_http, enable_jog_and_stop_reach_the_drive) {
  EXPECT_EQ(post("/api/jog", R"({"velocity":300})"), 409);  // not enabled yet
  EXPECT_EQ(post("/api/enable", "{}"), 200);
  step(50);
  EXPECT_EQ(state()["state"], "OPERATION_ENABLED");
  EXPECT_EQ(post("/api/jog", R"({"velocity":-300,"ttl_ms":500})"), 200);
  step(50);  // the session switches to profile velocity first, confirmed by 0x6061
  EXPECT_EQ(state()["target_velocity"], -300);
  EXPECT_EQ(post("/api/jog", R"({"velocity":0})"), 200);
  step(1);  // 0x60FF = 0 goes out in the next cycle
  EXPECT_EQ(state()["target_velocity"], 0);
  EXPECT_EQ(post("/api/stop", "{}"), 200);
  step(2000);
  EXPECT_EQ(state()["state"], "SWITCH_ON_DISABLED");
}

TEST_F(commissioning_http, bad_or_unauthorised_requests_are_refused_and_change_nothing) {
  const json before = state();
  EXPECT_EQ(post("/api/enable", "{}", false), 403);
  EXPECT_EQ(post("/api/enable", R"({"axis":1})"), 400);
  EXPECT_EQ(post("/api/stop", "[]"), 400);
  EXPECT_EQ(post("/api/jog", "{}"), 400);
  EXPECT_EQ(post("/api/jog", R"({"velocity":"fast"})"), 400);
  EXPECT_EQ(post("/api/jog", R"({"velocity":300,"ttl_ms":5})"), 400);
  EXPECT_EQ(post("/api/jog", R"({"velocity":300,"ttl_ms":1001})"), 400);
  EXPECT_EQ(post("/api/jog", R"({"velocity":300,"hold":true})"), 400);
  const auto get = client->Get("/api/jog");
  ASSERT_TRUE(get);
  EXPECT_EQ(get->status, 405);
  step(50);
  const json after = state();
  EXPECT_EQ(after["state"], before["state"]);
  EXPECT_EQ(after["control_word"], before["control_word"]);
  EXPECT_EQ(after["results"], before["results"]);
}

}  // namespace
