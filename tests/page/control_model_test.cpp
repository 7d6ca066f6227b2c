// The page's control model (issue 42; docs/instrument-page.md, "Control model"), on three virtual
// drives behind the server in-process, each stepped in real time: a page holds every axis it
// commands while it is open, whichever axis it shows; one page controls an axis at a time, a second
// is refused with "controlled elsewhere" and can take control; a fresh server that no page has opened
// has lost no sign of life.
#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "cia402/page/runner.hpp"
#include "cia402/page/server.hpp"
#include "cia402/profile.hpp"
#include "virtual_axis_page.hpp"

namespace {

using cia402::page::axis_page_config;
using cia402::page::cycle_runner;
using cia402::page::server;
using cia402::page::server_options;
using cia402::page::testing::virtual_axis_page;
using json = nlohmann::json;
using namespace std::chrono_literals;

constexpr int lease_ms = 300;

bool lost_sign_of_life(const json& snapshot) {
  for (const json& r : snapshot["results"]) {
    if (r["action"].get<std::string>().find("SIGN OF LIFE LOST") != std::string::npos) return true;
  }
  return false;
}

class control_model : public ::testing::Test {
 protected:
  void SetUp() override {
    axis_page_config c;
    c.lease_us = lease_ms * 1000;
    std::vector<cia402::page::axis> axes;
    for (int k = 0; k < 3; ++k) {
      drives.push_back(std::make_unique<virtual_axis_page>(cia402::standard_profile(), c));
      axes.push_back({"axis " + std::to_string(k + 1), drives.back().get()});
    }
    server_options o;
    o.bind = "127.0.0.1";
    o.port = 0;
    o.sign_of_life = 50ms;
    o.control_hold = 400ms;
    http = std::make_unique<server>(axes, o);
    ASSERT_TRUE(http->bind()) << http->error();
    http->start();
    for (auto& d : drives) {
      runners.push_back(std::make_unique<cycle_runner>(*d, 1000us));
      runners.back()->start();
    }
  }
  void TearDown() override {
    for (auto& r : runners) r->stop();
    if (http) http->stop();
  }

  // A request of page `page` ("" for a program without a client id).
  httplib::Result post(const std::string& page, const std::string& path, const std::string& body) {
    httplib::Client c("127.0.0.1", http->bound_port());
    httplib::Headers h;
    if (!page.empty()) h.emplace("X-Cia402-Client", page);
    return c.Post(path.c_str(), h, body, "application/json");
  }
  json control_of(const std::string& page, int axis) {
    httplib::Client c("127.0.0.1", http->bound_port());
    const auto r = c.Get(("/api/control?axis=" + std::to_string(axis)).c_str(), {{"X-Cia402-Client", page}});
    EXPECT_TRUE(r && r->status == 200);
    return r ? json::parse(r->body) : json();
  }
  json snapshot(int axis) { return json::parse(drives[axis - 1]->snapshot_json()); }
  bool wait_state(int axis, const std::string& state, std::chrono::milliseconds within = 3s) {
    const auto end = std::chrono::steady_clock::now() + within;
    while (std::chrono::steady_clock::now() < end) {
      if (snapshot(axis)["state"] == state) return true;
      std::this_thread::sleep_for(5ms);
    }
    return false;
  }

  std::vector<std::unique_ptr<virtual_axis_page>> drives;
  std::vector<std::unique_ptr<cycle_runner>> runners;
  std::unique_ptr<server> http;
};

// An event stream of page `client` on `axis`, open until stop().
class open_stream {
 public:
  open_stream(int port, int axis, const std::string& client) {
    thread_ = std::thread([this, port, axis, client] {
      httplib::Client c("127.0.0.1", port);
      c.set_read_timeout(5, 0);
      const std::string path = "/api/events?axis=" + std::to_string(axis) + "&client=" + client;
      c.Get(path.c_str(), [this](const char*, std::size_t) { return !stop_; });
    });
  }
  ~open_stream() { stop(); }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST_F(control_model, a_fresh_server_that_no_page_opened_has_lost_no_sign_of_life) {
  std::this_thread::sleep_for(std::chrono::milliseconds(3 * lease_ms));
  for (int k = 1; k <= 3; ++k) {
    const json s = snapshot(k);
    EXPECT_FALSE(lost_sign_of_life(s)) << "axis " << k << ": " << s["results"];
    EXPECT_EQ(s["state"], "SWITCH_ON_DISABLED");
  }
}

TEST_F(control_model, a_page_holds_the_axis_it_left_while_it_views_another) {
  ASSERT_EQ(post("page-a", "/api/enable?axis=1", "{}")->status, 200);
  ASSERT_TRUE(wait_state(1, "OPERATION_ENABLED"));
  EXPECT_EQ(control_of("page-a", 1)["control"], "here");
  {
    // The page shows axis 2 now: its stream there renews axis 1, which it holds, for many leases.
    open_stream viewing(http->bound_port(), 2, "page-a");
    std::this_thread::sleep_for(std::chrono::milliseconds(5 * lease_ms));
    EXPECT_EQ(snapshot(1)["state"], "OPERATION_ENABLED");
    EXPECT_FALSE(lost_sign_of_life(snapshot(1))) << snapshot(1)["results"];
    EXPECT_EQ(control_of("page-a", 2)["held"], json::array({1}));
  }
  // The page is gone: axis 1's lease lapses and the drive is stopped, as before.
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(5 * lease_ms);
  while (!lost_sign_of_life(snapshot(1)) && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(5ms);
  EXPECT_TRUE(lost_sign_of_life(snapshot(1))) << snapshot(1)["results"];
}

TEST_F(control_model, a_second_page_sees_the_axis_controlled_elsewhere_and_can_take_control) {
  const std::string shutdown = R"({"command":"shutdown"})";
  open_stream a_is_there(http->bound_port(), 1, "page-a");
  ASSERT_EQ(post("page-a", "/api/command?axis=1", shutdown)->status, 200);
  const auto refused = post("page-b", "/api/command?axis=1", shutdown);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 409);
  const json why = json::parse(refused->body);
  EXPECT_EQ(why["controlled_elsewhere"], true);
  EXPECT_NE(why["error"].get<std::string>().find("controlled by another page"), std::string::npos);
  EXPECT_EQ(control_of("page-b", 1)["control"], "elsewhere");
  EXPECT_EQ(control_of("page-a", 1)["control"], "here");
  // The other axes stay free for page B.
  EXPECT_EQ(post("page-b", "/api/command?axis=2", shutdown)->status, 200);
  // B takes control explicitly: now A is the one refused.
  const auto take = post("page-b", "/api/control?axis=1", R"({"hold":true})");
  ASSERT_TRUE(take);
  ASSERT_EQ(take->status, 200);
  EXPECT_EQ(json::parse(take->body)["control"], "here");
  EXPECT_EQ(json::parse(take->body)["held"], json::array({1, 2}));
  EXPECT_EQ(post("page-b", "/api/command?axis=1", shutdown)->status, 200);
  EXPECT_EQ(post("page-a", "/api/command?axis=1", shutdown)->status, 409);
  EXPECT_EQ(control_of("page-a", 1)["control"], "elsewhere");
  // A program without a client id is obeyed as before and holds nothing.
  EXPECT_EQ(post("", "/api/command?axis=1", shutdown)->status, 200);
  // B lets go: A may command again.
  ASSERT_EQ(post("page-b", "/api/control?axis=1", R"({"hold":false})")->status, 200);
  EXPECT_EQ(post("page-a", "/api/command?axis=1", shutdown)->status, 200);
  // A take without a client id, or with another body, is refused.
  EXPECT_EQ(post("", "/api/control?axis=1", R"({"hold":true})")->status, 400);
  EXPECT_EQ(post("page-b", "/api/control?axis=1", R"({"hold":1})")->status, 400);
}

TEST_F(control_model, a_page_that_is_gone_leaves_its_axis_to_the_next) {
  const std::string shutdown = R"({"command":"shutdown"})";
  ASSERT_EQ(post("page-a", "/api/command?axis=3", shutdown)->status, 200);
  EXPECT_EQ(post("page-b", "/api/command?axis=3", shutdown)->status, 409);
  // No stream, no request of page A for longer than the hold: it is gone.
  std::this_thread::sleep_for(600ms);
  EXPECT_EQ(control_of("page-b", 3)["control"], "free");
  EXPECT_EQ(post("page-b", "/api/command?axis=3", shutdown)->status, 200);
  EXPECT_EQ(control_of("page-b", 3)["control"], "here");
}

}  // namespace
