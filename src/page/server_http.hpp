// The page server's HTTP pieces below the routes: JSON replies, the checks a request's values get,
// and the admission of a connection before cpp-httplib reads a byte of it (server.cpp explains why
// the page's server is two). Split from server.cpp.
#pragma once

#include <httplib.h>

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "cia402/page/backend.hpp"
#include "cia402/page/server.hpp"

namespace cia402::page::detail {

void send_json(httplib::Response& res, int status, const nlohmann::json& body);
void send_error(httplib::Response& res, int status, const std::string& reason);

/// A Content-Length of digits only, at most `max`.
bool length_within(const std::string& text, std::size_t max);

/// A Content-Type that is application/json exactly, parameters (charset) allowed, in any case: not
/// a type that merely starts so.
bool is_json_content_type(std::string_view content_type);

/// Equal-time comparison, so the time a refusal takes tells nothing about the token.
bool same_secret(std::string_view a, std::string_view b);

/// The host part of a Host header: "127.0.0.1:8402" -> "127.0.0.1", "[::1]:8402" -> "::1".
std::string_view host_of(std::string_view host_header);

/// An integer from a JSON number or a string "0x605A" / "24666"; nothing for anything else.
std::optional<std::int64_t> integer_of(const nlohmann::json& v);

/// Every key of `body` must be one of `allowed`; the first one that is not is named.
std::optional<std::string> unknown_key(const nlohmann::json& body, std::initializer_list<const char*> allowed);

struct request_error {
  int status;
  std::string reason;
};

/// POST /api/command: {"command": a page command's name, "toggle_bit" with "bit" (0..15), or
/// "new_setpoint"}.
std::variant<reply, request_error> command_request(backend& drive, const nlohmann::json& body);
/// POST /api/plant: any of target_velocity, fault (with fault_code, fault_class), dc_link, sto.
std::variant<reply, request_error> plant_request(backend& drive, const nlohmann::json& body);
/// POST /api/profile: {"profile": a profile's name}.
std::variant<reply, request_error> profile_request(backend& drive, const nlohmann::json& body);
/// POST /api/jog: {"velocity": rpm (signed; 0 releases), "ttl_ms": 20..1000, 300 if not given}.
std::variant<reply, request_error> jog_request(backend& drive, const nlohmann::json& body);
/// A request with an empty object for its body, which asks `action` of the drive: POST /api/enable
/// and /api/stop, /api/errors/read (the drive's 0x1003 read again) and /api/errors/clear (emptied,
/// sub 0 = 0). Any key in the body is refused.
template <reply (backend::*action)()>
std::variant<reply, request_error> bare_request(backend& drive, const nlohmann::json& body) {
  if (auto k = unknown_key(body, {})) return request_error{400, *k};
  return (drive.*action)();
}

/// POST /api/homing: {"method", "fast" (0x6099:1, rpm), "slow" (0x6099:2, rpm), "acceleration"
/// (0x609A, rpm/s), "offset" (0x607C), "start" (true: run, false: stop)}, each optional, integers.
std::variant<reply, request_error> homing_request_of(backend& drive, const nlohmann::json& body);
/// A refusal of the drive's: its status, {"error": reason} and, where the drive's object interface
/// refused, "abort" (0x%08X) and "abort_text".
void send_refusal(httplib::Response& res, const refused& no);

/// POST /api/object: {"index": 0x6099 or "0x6099:1" (INDEX:SUB), "value": a number, or a string
/// (a number's text, or a string entry's value)}.
std::variant<reply, request_error> object_request(backend& drive, const nlohmann::json& body);

/// The parameter list's routes (server_parameters.cpp): GET /api/parameters, GET and POST
/// /api/parameters.dcf. What they need of the server: the drive a request names, and a checked POST
/// body (the drive and the JSON object; nothing with the refusal sent).
inline constexpr const char* parameter_file_path = "/api/parameters.dcf";
struct parameter_route_hooks {
  std::function<backend*(const httplib::Request&, httplib::Response&)> axis_of;
  std::function<std::optional<std::pair<backend*, nlohmann::json>>(const httplib::Request&, httplib::Response&)>
      post_body;
};
void add_parameter_routes(httplib::Server& http, parameter_route_hooks hooks);

/// The address of the connection's peer as text ("192.0.2.7", "::1"); empty when it has none.
std::string peer_address(socket_t sock);

/// A refusal written straight to the socket (the request was never parsed); closes it.
void answer_and_close(socket_t sock, int status, const std::string& reason);

/// Waits (peeking, nothing consumed) until the first request's head is complete. 0: the peer went
/// away; otherwise the refusal's status and reason (408 not within `read_timeout`, 431 over
/// `max_head` bytes or `max_headers` lines), or 200 to go on.
request_error wait_for_head(socket_t sock, std::chrono::milliseconds read_timeout, std::size_t max_head,
                            std::size_t max_headers);

/// GET /api/events for one drive: its present snapshot at once, then each one published, and a
/// comment line after min(keep_alive, sign_of_life) without a write; each write that goes out calls
/// `renew` (the leases of the client's axes). At most `max_event_streams` open (`streams` counts
/// them); ends when `stopping` is set or the drive is closed.
void serve_events(backend& inst, httplib::Response& res, const server_options& options, std::atomic<int>& streams,
                  const std::atomic<bool>& stopping, std::function<void()> renew);

}  // namespace cia402::page::detail
