// The page's HTTP server in-process on a free loopback port, for the server tests: a virtual axis
// page behind it, cpp-httplib's client in front, with or without a token required.
#pragma once

#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "virtual_axis_page.hpp"
#include "cia402/page/runner.hpp"
#include "cia402/page/server.hpp"
#include "cia402/profile.hpp"

namespace cia402::page::testing {

using cia402::page::server;
using cia402::page::server_options;
using json = nlohmann::json;

// A reply that came, with status 200 (its status and body shown when not).
inline ::testing::AssertionResult ok_reply(const httplib::Result& r) {
  if (!r) return ::testing::AssertionFailure() << "no response";
  if (r->status != 200) return ::testing::AssertionFailure() << "status " << r->status << ": " << r->body;
  return ::testing::AssertionSuccess();
}

inline constexpr const char* token = "0123456789abcdef0123456789abcdef";

class page_server : public ::testing::Test {
 protected:
  void start(bool token_required) {
    server_options o;
    o.bind = "127.0.0.1";
    o.port = 0;
    o.token_required = token_required;
    o.token = token;
    o.keep_alive = std::chrono::milliseconds(300);
    http = std::make_unique<server>(inst, o);
    ASSERT_TRUE(http->bind()) << http->error();
    ASSERT_GT(http->bound_port(), 0);
    http->start();
    client = std::make_unique<httplib::Client>("127.0.0.1", http->bound_port());
    client->set_read_timeout(5, 0);
    step(10);  // power-up: T0, T1
  }

  void TearDown() override {
    if (http) http->stop();
  }

  void step(int cycles) {
    for (int i = 0; i < cycles; ++i) inst.step();
  }

  httplib::Result post(const std::string& path, const std::string& body,
                       const httplib::Headers& headers = {},
                       const std::string& type = "application/json") {
    return client->Post(path.c_str(), headers, body, type.c_str());
  }

  // The parts of the snapshot a request could change.
  json observable() {
    json s = json::parse(inst.snapshot_json());
    return {s["state"], s["control_word"], s["dc_link"], s["sto"], s["fault_cause"],
            s["target_velocity"], s["objects"], s["results"]};
  }

  // Sends `requests`, each refused, then runs 5 cycles: what a request could change must be as it
  // was before them (a refused request has no effect that shows up later either).
  void expect_unchanged_by(const std::function<void()>& requests) {
    const json before = observable();
    requests();
    step(5);
    EXPECT_EQ(observable(), before);
  }

  void expect_refused(const httplib::Result& r, int status, const std::string& reason_part) {
    ASSERT_TRUE(r) << "no response";
    EXPECT_EQ(r->status, status) << r->body;
    EXPECT_NE(r->get_header_value("Content-Type").find("application/json"), std::string::npos);
    const json body = json::parse(r->body, nullptr, false);
    ASSERT_TRUE(body.is_object()) << r->body;
    ASSERT_TRUE(body.contains("error")) << r->body;
    EXPECT_NE(body["error"].get<std::string>().find(reason_part), std::string::npos)
        << body["error"];
  }

  virtual_axis_page inst{cia402::standard_profile()};
  std::unique_ptr<server> http;
  std::unique_ptr<httplib::Client> client;
};

}  // namespace cia402::page::testing
