#include "server_http.hpp"

#include "commissioning.hpp"
#include "json_text.hpp"

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <random>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <thread>
#include <vector>

namespace cia402::page::detail {

using json = nlohmann::json;

void send_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(json_text(body), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& reason) {
  send_json(res, status, json{{"error", reason}});
}

// A Content-Length of digits only, at most `max`.
bool length_within(const std::string& text, std::size_t max) {
  std::size_t n = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  return ec == std::errc() && end == text.data() + text.size() && !text.empty() && n <= max;
}

bool is_json_content_type(std::string_view content_type) {
  std::string_view media = content_type.substr(0, content_type.find(';'));
  const auto space = [](char c) { return c == ' ' || c == '\t'; };
  while (!media.empty() && space(media.front())) media.remove_prefix(1);
  while (!media.empty() && space(media.back())) media.remove_suffix(1);
  std::string bare(media);
  std::transform(bare.begin(), bare.end(), bare.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return bare == "application/json";
}

// Equal-time comparison, so the time a refusal takes tells nothing about the token.
bool same_secret(std::string_view a, std::string_view b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff |= static_cast<unsigned char>(a[i] ^ (i < b.size() ? b[i] : 0));
  }
  return diff == 0;
}

// The host part of a Host header: "127.0.0.1:8402" -> "127.0.0.1", "[::1]:8402" -> "::1".
std::string_view host_of(std::string_view host_header) {
  if (!host_header.empty() && host_header.front() == '[') {
    const std::size_t close = host_header.find(']');
    return close == std::string_view::npos ? host_header : host_header.substr(1, close - 1);
  }
  const std::size_t colon = host_header.find(':');
  return colon == std::string_view::npos ? host_header : host_header.substr(0, colon);
}

// An integer from a JSON number or a string "0x605A" / "24666"; nothing for anything else.
std::optional<std::int64_t> integer_of(const json& v) {
  if (v.is_number_integer()) return v.get<std::int64_t>();
  if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(INT64_MAX)) return std::nullopt;
    return static_cast<std::int64_t>(u);
  }
  if (!v.is_string()) return std::nullopt;
  const std::string& s = v.get_ref<const std::string&>();
  std::size_t i = 0;
  bool negative = false;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) negative = s[i++] == '-';
  int base = 10;
  if (s.size() - i > 2 && s[i] == '0' && (s[i + 1] == 'x' || s[i + 1] == 'X')) {
    base = 16;
    i += 2;
  }
  if (i >= s.size() || s.size() - i > 12) return std::nullopt;
  std::int64_t value = 0;
  for (; i < s.size(); ++i) {
    const char c = s[i];
    int d = -1;
    if (c >= '0' && c <= '9') d = c - '0';
    if (base == 16 && c >= 'a' && c <= 'f') d = c - 'a' + 10;
    if (base == 16 && c >= 'A' && c <= 'F') d = c - 'A' + 10;
    if (d < 0) return std::nullopt;
    value = value * base + d;
  }
  return negative ? -value : value;
}

// Every key of `body` must be one of `allowed`; the first one that is not is named.
std::optional<std::string> unknown_key(const json& body, std::initializer_list<const char*> allowed) {
  for (auto it = body.begin(); it != body.end(); ++it) {
    bool known = false;
    for (const char* a : allowed) known = known || it.key() == a;
    if (!known) return "unknown key '" + it.key() + "'";
  }
  return std::nullopt;
}

std::variant<reply, request_error> command_request(backend& inst, const json& body) {
  if (auto k = unknown_key(body, {"command", "bit"})) return request_error{400, *k};
  if (!body.contains("command") || !body["command"].is_string()) {
    return request_error{400, "'command' (a string) is required"};
  }
  const std::string& name = body["command"].get_ref<const std::string&>();
  if (name == "toggle_bit") {
    if (!body.contains("bit")) return request_error{400, "toggle_bit needs 'bit' (0..15)"};
    const auto bit = integer_of(body["bit"]);
    if (!bit || *bit < 0 || *bit > 15) return request_error{400, "'bit' must be 0..15"};
    return inst.toggle_control_bit(static_cast<int>(*bit));
  }
  if (body.contains("bit")) return request_error{400, "'bit' belongs to toggle_bit only"};
  if (name == "new_setpoint") return inst.new_setpoint();
  page_command c{};
  if (!parse_page_command(name, c)) {
    return request_error{400, "unknown command '" + name +
                                  "' (shutdown, switch_on, enable_operation, disable_operation, "
                                  "disable_voltage, quick_stop, fault_reset, halt, toggle_bit, "
                                  "new_setpoint)"};
  }
  return inst.command(c);
}

std::variant<reply, request_error> plant_request(backend& inst, const json& body) {
  if (auto k = unknown_key(body, {"target_velocity", "fault", "fault_code", "fault_class",
                                  "dc_link", "sto"})) {
    return request_error{400, *k};
  }
  if (body.empty()) return request_error{400, "nothing to change"};
  plant_change c;
  if (body.contains("target_velocity")) {
    const json& v = body["target_velocity"];
    if (!v.is_number_integer() && !v.is_number_unsigned()) {
      return request_error{400, "'target_velocity' must be an integer (rpm)"};
    }
    const auto n = integer_of(v);
    if (!n) return request_error{400, "'target_velocity' is out of range"};
    c.target_velocity = *n;
  }
  for (const char* key : {"fault", "dc_link", "sto"}) {
    if (body.contains(key) && !body[key].is_boolean()) {
      return request_error{400, "'" + std::string(key) + "' must be true or false"};
    }
  }
  if (body.contains("fault")) c.fault = body["fault"].get<bool>();
  const bool fault_on = c.fault && *c.fault;
  if (body.contains("fault_code")) {
    if (!fault_on) return request_error{400, "'fault_code' goes with \"fault\": true"};
    const auto code = integer_of(body["fault_code"]);
    if (!code || *code < 1 || *code > 0xFFFF) {
      return request_error{400, "'fault_code' must be 0x0001..0xFFFF"};
    }
    c.fault_code = static_cast<std::uint16_t>(*code);
  }
  if (body.contains("fault_class")) {
    if (!fault_on) return request_error{400, "'fault_class' goes with \"fault\": true"};
    const auto cls = integer_of(body["fault_class"]);
    if (!cls || *cls < 0 || *cls > 4) return request_error{400, "'fault_class' must be 0..4"};
    c.fault_class = static_cast<std::uint8_t>(*cls);
  }
  if (body.contains("dc_link")) c.dc_link = body["dc_link"].get<bool>();
  if (body.contains("sto")) c.sto = body["sto"].get<bool>();
  return inst.change_plant(c);
}

std::variant<reply, request_error> profile_request(backend& inst, const json& body) {
  if (auto k = unknown_key(body, {"profile"})) return request_error{400, *k};
  if (!body.contains("profile") || !body["profile"].is_string()) {
    return request_error{400, "'profile' (a profile's name) is required"};
  }
  return inst.select_profile(body["profile"].get_ref<const std::string&>());
}

std::variant<reply, request_error> jog_request(backend& drive, const json& body) {
  if (auto k = unknown_key(body, {"velocity", "ttl_ms"})) return request_error{400, *k};
  const auto velocity = body.contains("velocity") && body["velocity"].is_number_integer()
                            ? integer_of(body["velocity"])
                            : std::nullopt;
  if (!velocity) return request_error{400, "'velocity' (an integer, rpm; 0 releases) is required"};
  std::uint64_t ttl_ms = jog_ttl_default_ms;
  if (body.contains("ttl_ms")) {
    const auto t = body["ttl_ms"].is_number_integer() ? integer_of(body["ttl_ms"]) : std::nullopt;
    if (!t || *t < static_cast<std::int64_t>(jog_ttl_min_ms) ||
        *t > static_cast<std::int64_t>(jog_ttl_max_ms)) {
      return request_error{400, "'ttl_ms' must be " + std::to_string(jog_ttl_min_ms) + ".." +
                                    std::to_string(jog_ttl_max_ms)};
    }
    ttl_ms = static_cast<std::uint64_t>(*t);
  }
  return drive.jog(*velocity, ttl_ms * 1000);
}

std::variant<reply, request_error> homing_request_of(backend& drive, const json& body) {
  if (auto k = unknown_key(body, {"method", "fast", "slow", "acceleration", "offset", "start"})) {
    return request_error{400, *k};
  }
  homing_request r;
  for (const auto& [key, field] : {std::pair{"method", &homing_request::method}, std::pair{"fast", &homing_request::switch_speed},
                                   std::pair{"slow", &homing_request::zero_speed},
                                   std::pair{"acceleration", &homing_request::acceleration},
                                   std::pair{"offset", &homing_request::offset}}) {
    if (!body.contains(key)) continue;
    const auto v = body[key].is_number_integer() ? integer_of(body[key]) : std::nullopt;
    if (!v) return request_error{400, std::string("'") + key + "' must be an integer"};
    r.*field = v;
  }
  if (body.contains("start")) {
    if (!body["start"].is_boolean()) return request_error{400, "'start' must be true (run) or false (stop)"};
    r.start = body["start"].get<bool>();
  }
  if (!r.method && !r.switch_speed && !r.zero_speed && !r.acceleration && !r.offset && !r.start) {
    return request_error{400, "nothing to do: give a parameter or 'start'"};
  }
  return drive.home(r);
}

std::string peer_address(socket_t sock) {
  sockaddr_storage peer{};
  socklen_t len = sizeof peer;
  if (::getpeername(sock, reinterpret_cast<sockaddr*>(&peer), &len) != 0) return {};
  char text[INET6_ADDRSTRLEN] = {};
  if (peer.ss_family == AF_INET) {
    inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(&peer)->sin_addr, text, sizeof text);
  } else if (peer.ss_family == AF_INET6) {
    inet_ntop(AF_INET6, &reinterpret_cast<sockaddr_in6*>(&peer)->sin6_addr, text, sizeof text);
  }
  return text;
}

// A refusal written straight to the socket (the request was never parsed).
void answer_and_close(socket_t sock, int status, const std::string& reason) {
  const char* text = status == 408 ? "Request Timeout"
                     : status == 431 ? "Request Header Fields Too Large"
                                     : "Service Unavailable";
  const std::string body = json_text(json{{"error", reason}});
  const std::string head = "HTTP/1.1 " + std::to_string(status) + " " + text +
                           "\r\nContent-Type: application/json\r\nContent-Length: " +
                           std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n";
  const std::string all = head + body;
  (void)::send(sock, all.data(), all.size(), MSG_NOSIGNAL);
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
}

// Waits (peeking, nothing consumed) until the first request's head is complete. 0: the peer
// went away; otherwise the refusal's status and reason, or 200 to go on.
request_error wait_for_head(socket_t sock, std::chrono::milliseconds read_timeout, std::size_t max_head,
                            std::size_t max_headers) {
  const auto deadline = std::chrono::steady_clock::now() + read_timeout;
  std::vector<char> buf(max_head + 1);
  ssize_t seen = -1;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      return {408, "the request head did not arrive within " +
                       std::to_string(read_timeout.count()) + " ms"};
    }
    pollfd p{sock, POLLIN | POLLRDHUP, 0};
    (void)::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 50)));
    const bool peer_done = (p.revents & (POLLRDHUP | POLLHUP | POLLERR)) != 0;
    const ssize_t n = ::recv(sock, buf.data(), buf.size(), MSG_PEEK | MSG_DONTWAIT);
    if (n == 0) return {0, ""};
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) continue;
      return {0, ""};
    }
    const std::string_view text(buf.data(), static_cast<std::size_t>(n));
    const auto end = text.find("\r\n\r\n");
    const std::string_view head = text.substr(0, end == std::string_view::npos ? text.size() : end);
    std::size_t lines = 0;
    for (std::size_t at = head.find("\r\n"); at != std::string_view::npos; at = head.find("\r\n", at + 2)) {
      ++lines;
    }
    if (lines > max_headers) {
      return {431, "more than " + std::to_string(max_headers) + " header lines"};
    }
    if (end != std::string_view::npos) return {200, ""};
    if (peer_done) return {0, ""};  // it stopped sending before its head was complete
    if (static_cast<std::size_t>(n) > max_head) {
      return {431, "request head larger than " + std::to_string(max_head) + " bytes"};
    }
    // Data waits unread, so poll returns at once: only a grown head is worth another look.
    if (n == seen) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    seen = n;
  }
}

void serve_events(backend& inst, httplib::Response& res, const server_options& options, std::atomic<int>& streams,
                  const std::atomic<bool>& stopping, std::function<void()> renew) {
  if (streams.fetch_add(1) >= options.max_event_streams) {
    streams.fetch_sub(1);
    return send_error(res, 503, "too many event streams open");
  }
  struct stream_state {
    bool started = false;
    std::uint64_t seen = 0;
    std::uint64_t next_sample = 0;  // the number of the next cycle sample this stream sends
    std::chrono::steady_clock::time_point last_write = std::chrono::steady_clock::now();
    std::chrono::steady_clock::time_point last_batch = std::chrono::steady_clock::now();
  };
  auto st = std::make_shared<stream_state>();
  res.set_chunked_content_provider(
      "text/event-stream",
      [st, &inst, &options, &stopping, renew = std::move(renew)](std::size_t, httplib::DataSink& sink) {
        std::string chunk;
        if (!st->started) {
          st->started = true;
          st->seen = inst.latest().version;
          chunk = "retry: 1000\ndata: " + inst.snapshot_json() + "\n\n";
        } else {
          // A comment line this long after the last write: the keep-alive, and the sign of life's
          // probe (a closed page fails the second write after it went at the latest).
          const auto comment_after = std::min(options.keep_alive, options.sign_of_life);
          while (chunk.empty()) {
            if (stopping || inst.closed()) {
              sink.done();
              return true;
            }
            const auto now = std::chrono::steady_clock::now();
            // The drive's cycles, a batch at most every samples_every (each stream from where it
            // is; one that fell behind the ring skips ahead, and the numbers show the page the gap).
            if (inst.samples_end() > st->next_sample && now - st->last_batch >= options.samples_every) {
              st->last_batch = now;
              std::uint64_t next = st->next_sample;
              const std::string batch = inst.samples_json(st->next_sample, options.samples_per_batch, next);
              if (next > st->next_sample && !batch.empty()) {
                st->next_sample = next;
                chunk = "event: samples\ndata: " + batch + "\n\n";
                break;
              }
            }
            // Short waits (at most 200 ms, one batch's time while the drive has samples), so a
            // stopping server ends the stream promptly.
            const auto quiet = std::chrono::duration_cast<std::chrono::milliseconds>(now - st->last_write);
            const auto longest = inst.samples_end() > 0 ? options.samples_every : std::chrono::milliseconds(200);
            const auto slice = std::clamp(comment_after - quiet, std::chrono::milliseconds(1), longest);
            if (auto u = inst.wait_for_update(st->seen, slice)) {
              st->seen = u->version;
              chunk = "data: " + u->json + "\n\n";
            } else if (std::chrono::steady_clock::now() - st->last_write >= comment_after) {
              chunk = ": keep-alive\n\n";
            }
          }
        }
        st->last_write = std::chrono::steady_clock::now();
        if (!sink.write(chunk.data(), chunk.size())) return false;
        // Only a write that went out renews: a page that has gone stops renewing with its stream.
        renew();
        return true;
      },
      [&streams](bool) { streams.fetch_sub(1); });
}

}  // namespace cia402::page::detail

namespace cia402::page {

std::string make_token() {
  std::random_device rd;
  std::string token;
  char buf[9];
  for (int i = 0; i < 4; ++i) {
    std::snprintf(buf, sizeof buf, "%08x", static_cast<unsigned>(rd()));
    token += buf;
  }
  return token;
}

bool is_loopback_address(std::string_view host) {
  if (host == "localhost" || host == "::1") return true;
  in_addr v4{};
  const std::string h(host);
  if (inet_pton(AF_INET, h.c_str(), &v4) == 1) {
    return (ntohl(v4.s_addr) >> 24) == 127;
  }
  in6_addr v6{};
  if (inet_pton(AF_INET6, h.c_str(), &v6) == 1) return IN6_IS_ADDR_LOOPBACK(&v6);
  return false;
}

}  // namespace cia402::page
