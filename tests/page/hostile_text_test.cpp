// Text a request or a drive brings that is not UTF-8 (issue 42): it never ends `cia402 serve`.
// nlohmann's dump() throws on such a string; thrown in cpp-httplib's error handler (the 404 of
// GET /%ff) or in the cycle thread (a snapshot with a drive's Latin-1 0x1008 name) it terminated
// the process. Each invalid byte is now U+FFFD in the JSON (json_text.hpp), and a drive's name is
// shown as Latin-1.
#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <future>
#include <memory>
#include <string>

#include "blocking_request.hpp"
#include "cia402/apps/local_link.hpp"
#include "cia402/page/server.hpp"
#include "forwarding_link.hpp"
#include "json_text.hpp"
#include "page_server_fixture.hpp"

namespace {

using cia402::page::axis_page;
using cia402::page::server;
using cia402::page::server_options;
using cia402::page::testing::page_server;
using json = nlohmann::json;
namespace axes = cia402::axes;

constexpr const char* replacement = "\xEF\xBF\xBD";  // U+FFFD in UTF-8
constexpr const char* latin1_name = "Servoverst\xE4rker";

// The answer's body, checked to be valid JSON (parse() throws on bytes that are not UTF-8).
json body_of(const httplib::Result& r) {
  EXPECT_TRUE(r) << "no answer: the server is gone";
  if (!r) return json();
  const json j = json::parse(r->body, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r->body;
  return j;
}

TEST(json_text, bytes_that_are_not_utf8_become_the_replacement_character) {
  const std::string text = cia402::page::detail::json_text(json{{"error", "no such resource: /\xFF"}});
  EXPECT_EQ(text, std::string(R"({"error":"no such resource: /)") + replacement + "\"}");
  EXPECT_EQ(cia402::page::detail::display_text(latin1_name), "Servoverst\xC3\xA4rker");
  EXPECT_EQ(cia402::page::detail::display_text("Servoverst\xC3\xA4rker"), "Servoverst\xC3\xA4rker");
  for (const char* bad : {"\xFF", "\xC0\xAF", "\xED\xA0\x80", "\xE2\x82", "\xF4\x90\x80\x80"}) {
    EXPECT_FALSE(cia402::page::detail::is_utf8(bad)) << bad;
  }
}

TEST_F(page_server, a_path_that_is_not_utf8_gets_a_404_and_the_server_answers_on) {
  start(false);
  const auto r = client->Get("/%ff");
  const json j = body_of(r);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 404);
  EXPECT_NE(j.value("error", "").find(replacement), std::string::npos) << r->body;
  const auto info = client->Get("/api/info");
  ASSERT_TRUE(info) << "the server ended";
  EXPECT_EQ(info->status, 200);
}

TEST_F(page_server, an_axis_that_is_not_utf8_is_refused_with_404_not_500) {
  start(false);
  for (const char* path : {"/api/state?axis=%ff", "/api/info?axis=%c3", "/api/events?axis=%ff%fe"}) {
    const auto r = client->Get(path);
    const json j = body_of(r);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 404) << path << ": " << r->body;
    EXPECT_NE(j.value("error", "").find(replacement), std::string::npos) << r->body;
  }
  const auto post = client->Post("/api/command?axis=%ff", R"({"command":"shutdown"})", "application/json");
  ASSERT_TRUE(post);
  EXPECT_EQ(post->status, 404) << post->body;
  const auto state = client->Get("/api/state");
  ASSERT_TRUE(state) << "the server ended";
  EXPECT_EQ(state->status, 200);
}

// A virtual drive whose 0x1008 answers Latin-1 bytes, as a drive on a bus may: every other object
// as the virtual drive has it. The page takes it for a drive on a bus (no plant in this process).
class latin1_name_link final : public cia402::test::forwarding_link<cia402::apps::local_link> {
 public:
  explicit latin1_name_link(const cia402::profile& p) : forwarding_link(p) {}
  // As a bus's link: nothing is answered before time passes.
  bool work_now() const override { return false; }
  std::string what() const override { return "a drive named in Latin-1"; }
  std::string short_name() const override { return "node 7"; }
  bool upload(std::uint16_t index, std::uint8_t sub, axes::transfer_done done) override {
    if (index != axes::device_name_index) return inner.upload(index, sub, std::move(done));
    return inner.upload(index, sub, [done = std::move(done)](const axes::transfer_result& r) {
      axes::transfer_result latin1 = r;
      const std::string name = latin1_name;
      if (r.ok) latin1.data.assign(name.begin(), name.end());
      done(latin1);
    });
  }
};

TEST(hostile_text, a_drive_named_in_latin1_is_shown_and_the_server_answers_on) {
  axis_page drive(cia402::standard_profile(), [](const cia402::profile& p) {
    return cia402::page::drive_connection{std::make_unique<latin1_name_link>(p), nullptr};
  });
  server_options o;
  o.bind = "127.0.0.1";
  o.port = 0;
  server http(drive, o);
  ASSERT_TRUE(http.bind()) << http.error();
  http.start();
  httplib::Client client("127.0.0.1", http.bound_port());
  client.set_read_timeout(5, 0);
  // The start-up reads answer, 0x1008 among them, and snapshots are published on the way: before
  // issue 42 the first publish after it threw out of step() (in serve, the cycle thread).
  for (int i = 0; i < 500; ++i) drive.step();
  const json s = json::parse(drive.snapshot_json());
  EXPECT_EQ(s["remote"]["device_name"], "Servoverst\xC3\xA4rker");
  ASSERT_TRUE(drive.latest().version > 0);
  EXPECT_NE(drive.latest().json.find("Servoverst\xC3\xA4rker"), std::string::npos);
  const json state = body_of(client.Get("/api/state"));
  EXPECT_EQ(state["remote"]["device_name"], "Servoverst\xC3\xA4rker");
  const json overview = body_of(client.Get("/api/axes"));
  EXPECT_EQ(overview.size(), 1u);
  // The parameter list, read over the link: valid JSON.
  auto list = cia402::page::testing::blocking_request([&] { return client.Get("/api/parameters"); },
                                                      [&] { drive.step(); });
  const json parameters = body_of(list);
  ASSERT_TRUE(list);
  EXPECT_EQ(list->status, 200) << list->body.substr(0, 300);
  http.stop();
}

}  // namespace
