// Hostile request text into the page server's HTTP pieces (issue 42): a path, a query, the headers
// X-Cia402-Client, Host, Content-Length and X-Cia402-Token, a JSON body and a raw value, any bytes
// (text that is not UTF-8 included). The server's routes need a socket (cpp-httplib 0.11.4 has no
// in-process entry), so this drives what they are made of, as server.cpp uses it: cpp-httplib's
// decoding of the path and the query, the checks of the headers (server_http.cpp,
// server_control.cpp), the body parsed and handed to each route's request parser with a virtual
// drive behind it, and every reply written by send_json / send_error / send_refusal.
//
// Promises: nothing throws; every JSON the page writes is valid UTF-8 and parses back, a reason
// that was UTF-8 comes back unchanged and one that was not keeps its ASCII; is_utf8 agrees with
// nlohmann's own UTF-8 check; display_text is UTF-8 and keeps UTF-8 text as it is; a client id is
// taken only as 1..64 of [A-Za-z0-9_-]; one page holds an axis at a time; the header checks agree
// with what they promise.
//
// Input: one selector byte, then up to 8 fields separated by 0x1F: path, query, client id, Host,
// Content-Length, body, token, raw value.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <httplib.h>

#include <nlohmann/json.hpp>

#include "cia402/apps/local_link.hpp"
#include "cia402/page/axis_page.hpp"
#include "cia402/page/server.hpp"
#include "cia402/profile.hpp"
#include "json_text.hpp"
#include "server_control.hpp"
#include "server_http.hpp"

using namespace cia402::page;
using json = nlohmann::json;
using detail::is_utf8;
using detail::request_error;

namespace {

[[noreturn]] void broken(const char* promise, std::string_view text) {
  std::fprintf(stderr, "page_http_text_fuzz: %s\n  text (%zu bytes): ", promise, text.size());
  for (const char c : text.substr(0, 400)) std::fprintf(stderr, "%02x", static_cast<unsigned char>(c));
  std::fprintf(stderr, "\n");
  std::abort();
}

void expect(bool holds, const char* promise, std::string_view text = {}) {
  if (!holds) broken(promise, text);
}

std::string ascii_of(std::string_view s) {
  std::string out;
  for (const char c : s) {
    if (static_cast<unsigned char>(c) < 0x80) out += c;
  }
  return out;
}

// s as a JSON string literal, its bytes >= 0x20 as they are: nlohmann's lexer then checks the UTF-8.
std::string raw_literal(std::string_view s) {
  static constexpr char hex[] = "0123456789abcdef";
  std::string out = "\"";
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20) {
      out += "\\u00";
      out += hex[u >> 4];
      out += hex[u & 15];
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A text a request brings: the UTF-8 check and the Latin-1 fallback keep their promises.
void check_text(std::string_view s) {
  const bool utf8 = is_utf8(s);
  const json lexed = json::parse(raw_literal(s), nullptr, false);
  expect(lexed.is_discarded() == !utf8, utf8 ? "is_utf8 says UTF-8, nlohmann refuses it" : "is_utf8 refuses what nlohmann takes", s);
  if (utf8) expect(lexed.get<std::string>() == s, "a UTF-8 string does not parse back to itself", s);
  const std::string shown = detail::display_text(s);
  expect(is_utf8(shown), "display_text is not UTF-8", s);
  if (utf8) {
    expect(shown == s, "display_text changed UTF-8 text", s);
  } else {
    std::size_t high = 0;
    for (const char c : s) high += static_cast<unsigned char>(c) >= 0x80 ? 1 : 0;
    expect(shown.size() == s.size() + high, "display_text is not Latin-1 of every byte", s);
  }
}

// A reply body as the server writes it: UTF-8, valid JSON, an object.
json reply_body(const httplib::Response& res) {
  expect(is_utf8(res.body), "a reply body is not UTF-8", res.body);
  const json j = json::parse(res.body, nullptr, false);
  expect(!j.is_discarded() && j.is_object(), "a reply body is not a JSON object", res.body);
  return j;
}

// send_error with a reason built from request text: the reason is the body's "error".
void check_error(int status, const std::string& reason) {
  httplib::Response res;
  detail::send_error(res, status, reason);
  expect(res.status == status, "send_error lost the status", reason);
  const json j = reply_body(res);
  expect(j.size() == 1 && j.contains("error") && j["error"].is_string(), "an error body is not {\"error\": text}", res.body);
  const std::string& back = j["error"].get_ref<const std::string&>();
  if (is_utf8(reason)) {
    expect(back == reason, "a UTF-8 reason came back changed", reason);
  } else {
    expect(ascii_of(back) == ascii_of(reason), "a reason that is not UTF-8 lost or gained ASCII", reason);
    expect(back.find("\xEF\xBF\xBD") != std::string::npos, "an invalid byte is not U+FFFD", reason);
  }
}

// What server.cpp's post() answers for a route's result.
void answer(const std::variant<reply, request_error>& r) {
  httplib::Response res;
  if (const auto* e = std::get_if<request_error>(&r)) {
    check_error(e->status, e->reason);
    return;
  }
  const reply& rep = std::get<reply>(r);
  if (const auto* ok = std::get_if<accepted>(&rep)) {
    json j{{"id", ok->id}};
    if (!ok->text.empty()) j["text"] = ok->text;
    detail::send_json(res, 200, j);
  } else {
    detail::send_refusal(res, std::get<refused>(rep));
    expect(res.status >= 400 && res.status < 600, "a refusal without a 4xx/5xx status", res.body);
  }
  reply_body(res);
}

drive_connection virtual_connection(const cia402::profile& p) {
  auto link = std::make_unique<cia402::apps::local_link>(p);
  cia402::sim::virtual_drive* plant = &link->drive();
  return {std::move(link), plant};
}

using route = std::variant<reply, request_error> (*)(backend&, const json&);
struct route_entry {
  const char* key;  // the route's first key, for a body built around the raw value
  route parse;
};
const route_entry routes[] = {
    {"command", &detail::command_request},
    {"target_velocity", &detail::plant_request},
    {"index", &detail::object_request},
    {"profile", &detail::profile_request},
    {"velocity", &detail::jog_request},
    {"method", &detail::homing_request_of},
    {"x", &detail::bare_request<&backend::enable>},
    {"x", &detail::bare_request<&backend::stop>},
    {"x", &detail::bare_request<&backend::read_error_field>},
};
constexpr std::size_t route_count = sizeof routes / sizeof routes[0];

bool valid_id_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
}

void check_client(const std::string& header) {
  const std::string id = detail::valid_client_id(header);
  bool valid = !header.empty() && header.size() <= 64;
  for (const char c : header) valid = valid && valid_id_char(c);
  expect(valid ? id == header : id.empty(), "valid_client_id took or refused the wrong text", header);

  // The control board with this page and another one: one holder at a time, a lapsed hold free.
  using clock = detail::control_board::clock;
  const auto hold = std::chrono::milliseconds(1000);
  detail::control_board board(3, hold);
  const clock::time_point t{std::chrono::hours(1)};
  const std::string other = id == "fuzz-other" ? "fuzz-another" : "fuzz-other";
  expect(board.claim(0, id, t), "a first claim was refused", id);
  if (id.empty()) {
    expect(board.standing(0, id, t) == detail::control_standing::free, "a program holds an axis", id);
    expect(board.renew(id, t).empty(), "a program renews a hold", id);
    return;
  }
  expect(board.standing(0, id, t) == detail::control_standing::here, "a claim does not hold", id);
  expect(board.standing(0, other, t) == detail::control_standing::elsewhere, "another page does not see the hold", id);
  expect(board.standing(0, "", t) == detail::control_standing::elsewhere, "a program does not see the hold", id);
  expect(!board.claim(0, other, t + hold / 2), "a second page took a held axis", id);
  expect(board.claim(0, "", t), "a program was refused", id);
  expect(board.renew(id, t + hold / 2) == std::vector<std::size_t>{0}, "renew does not name the held axis", id);
  expect(board.claim(0, other, t + hold / 2 + hold), "a lapsed hold was not free", id);
  expect(board.standing(0, id, t + hold / 2 + hold) == detail::control_standing::elsewhere, "two pages hold one axis", id);
  board.set_hold(0, id, true, t + 2 * hold);
  expect(board.standing(0, other, t + 2 * hold) == detail::control_standing::elsewhere, "take control did not take", id);
  board.set_hold(0, other, false, t + 2 * hold);
  expect(board.standing(0, id, t + 2 * hold) == detail::control_standing::here, "another page let go of this page's axis", id);
  board.set_hold(0, id, false, t + 2 * hold);
  expect(board.standing(0, other, t + 2 * hold) == detail::control_standing::free, "letting go left a hold", id);
}

void check_headers(const std::string& host, const std::string& length, const std::string& token) {
  const std::string_view h = detail::host_of(host);
  expect(h.empty() || (h.data() >= host.data() && h.data() + h.size() <= host.data() + host.size()),
         "host_of is not a part of the header", host);
  (void)is_loopback_address(h);
  for (const std::size_t most : {std::size_t{0}, std::size_t{4096}, std::size_t{1} << 20}) {
    bool digits = !length.empty();
    for (const char c : length) digits = digits && c >= '0' && c <= '9';
    bool within = false;
    if (digits) {
      const std::size_t first = length.find_first_not_of('0');
      const std::string n = first == std::string::npos ? "0" : length.substr(first);
      const std::string m = std::to_string(most);
      within = n.size() < m.size() || (n.size() == m.size() && n <= m);
    }
    expect(detail::length_within(length, most) == within, "length_within disagrees", length);
  }
  const std::string secret = "0123456789abcdef0123456789abcdef";
  expect(detail::same_secret(token, token), "a token differs from itself", token);
  expect(detail::same_secret(token, secret) == (token == secret), "same_secret disagrees", token);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0 || size > 8192) return 0;
  const std::uint8_t selector = data[0];
  std::vector<std::string> f(8);
  std::size_t n = 0;
  for (std::size_t i = 1; i < size; ++i) {
    if (data[i] == 0x1F && n + 1 < f.size()) {
      ++n;
    } else {
      f[n] += static_cast<char>(data[i]);
    }
  }
  const std::string& raw_path = f[0];
  const std::string& query = f[1];

  // The path and the query as cpp-httplib hands them to a route, and the reasons built from them.
  const std::string path = httplib::detail::decode_url(raw_path, false);
  httplib::Params params;
  httplib::detail::parse_query_text(query, params);
  for (const std::string* s : std::initializer_list<const std::string*>{&raw_path, &path, &query, &f[2], &f[3], &f[5], &f[7]}) {
    check_text(*s);
  }
  check_error(404, "no such resource: " + path);
  for (const auto& [key, value] : params) {
    check_text(key);
    check_text(value);
    check_error(404, "no axis '" + value + "' (1..3)");
  }
  check_client(f[2]);
  check_headers(f[3], f[4], f[6]);

  // The body, as post_body() reads it, into one route; then the same route with the raw value (any
  // bytes, which the JSON parser never lets through) as its first key's value.
  const route_entry& r = routes[selector % route_count];
  axis_page inst(cia402::builtin_profile((selector / route_count) % cia402::builtin_profile_count()), virtual_connection);
  for (int k = 0; k < 3; ++k) inst.step();
  const json body = json::parse(f[5], nullptr, false);
  if (body.is_discarded()) {
    check_error(400, "body is not valid JSON");
  } else if (body.is_object()) {
    answer(r.parse(inst, body));
  }
  answer(r.parse(inst, json{{r.key, f[7]}}));
  answer(r.parse(inst, json{{f[7], 1}}));
  // A parameter file's text, and an entry's value from text (the parameter list's Write).
  if (selector & 0x80) {
    const document d = inst.load_parameter_file(f[5]);
    expect(is_utf8(d.body) && !json::parse(d.body, nullptr, false).is_discarded(), "a parameter file's answer is not UTF-8 JSON", d.body);
  }
  const std::uint16_t entries[] = {0x1008, 0x6099, 0x605A, 0x2001};
  answer(reply{inst.write_entry(entries[(selector >> 4) % 4], static_cast<std::uint8_t>(selector & 3), f[7])});
  inst.step();
  // What the page shows afterwards (/api/info, large and mostly the profile's, now and then).
  std::vector<std::string> shown{inst.snapshot_json(), inst.recording_json(0, 0)};
  if (selector & 0x40) shown.push_back(inst.info_json(true, false));
  for (const std::string& text : shown) {
    expect(is_utf8(text) && !json::parse(text, nullptr, false).is_discarded(), "the page's JSON is not UTF-8 JSON", text);
  }
  return 0;
}
