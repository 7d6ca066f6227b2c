#include "cia402/page/server.hpp"

#include <httplib.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdio>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>
#include <thread>

#include "server_http.hpp"
#include "json_text.hpp"
#include "server_control.hpp"
#include "web_assets.hpp"

namespace cia402::page {
namespace {

using json = nlohmann::json;

constexpr const char* token_header = "X-Cia402-Token";
constexpr const char* client_header = "X-Cia402-Client";

using detail::answer_and_close;
using detail::host_of;
using detail::integer_of;
using detail::length_within;
using detail::request_error;
using detail::same_secret;
using detail::send_error;
using detail::send_json;
using detail::unknown_key;

// cpp-httplib 0.11.4 (Debian 12's, a compiled library) reads a request's whole head, every header
// line of it, before any hook of ours runs, and its per-connection entry point is private. So the
// page's server is two: `guard_server` only accepts, and checks each connection before anything is
// read (the head complete within the read timeout, at most `max_head` bytes and `max_headers`
// lines, a bounded number of connections per client address); then `inner_server`, which holds the
// routes, processes it. The entry point is reached through its member pointer, named by an
// explicit instantiation (where access rules do not apply).
using process_member = bool (httplib::Server::*)(socket_t);
template <process_member member>
struct process_access {
  friend process_member process_connection() { return member; }
};
process_member process_connection();
template struct process_access<&httplib::Server::process_and_close_socket>;

// The server with the routes: it never listens; it processes the connections the guard admits.
struct inner_server : httplib::Server {
  // Its keep-alive loop runs while this is a valid socket: the guard's listening one.
  void adopt_listener(socket_t s) { svr_sock_ = s; }
  bool process(socket_t sock) { return (this->*process_connection())(sock); }
};

// The listening server: each accepted connection is checked, then handed to `inner`.
struct guard_server : httplib::Server {
  std::function<bool(socket_t)> admit;  // checks, then processes or refuses; closes the socket
  bool process_and_close_socket(socket_t sock) override { return admit(sock); }
};

}  // namespace

struct server::impl {
  impl(std::vector<axis> a, server_options o) : axes(std::move(a)), options(std::move(o)) {
    if (axes.empty()) throw std::invalid_argument("the page needs at least one drive");
    if (options.token_required && options.token.empty()) options.token = make_token();
  }

  std::vector<axis> axes;
  server_options options;
  int listen_fd = -1;  // the listening socket, once bound
  guard_server front;  // accepts and admits
  inner_server http;   // the routes
  std::mutex clients_mutex;
  std::map<std::string, int> connections;  // open connections per non-loopback client address
  std::thread thread;
  std::atomic<bool> stopping{false};
  std::atomic<bool> listen_returned{false};  // the listening thread is done (or never listened)
  std::atomic<int> streams{0};
  detail::control_board control{axes.size(), options.control_hold};  // which page holds each axis
  int port = -1;
  std::string error;

  // --- admission: before cpp-httplib reads a byte ---------------------------------------------

  request_error wait_for_head(socket_t sock) const {
    return detail::wait_for_head(sock, options.read_timeout, options.max_head, options.max_headers);
  }

  bool admit(socket_t sock) {
    // Small answers and event-stream chunks go out at once: with Nagle on, a second small write on
    // a connection waited up to ~40 ms for the client's delayed ACK.
    const int yes = 1;
    ::setsockopt(sock, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
    // Connections per client address, beyond loopback (on loopback every client is one address,
    // the page's own among them).
    const std::string address = detail::peer_address(sock);
    const bool counted = !address.empty() && !is_loopback_address(address);
    if (counted) {
      std::lock_guard lock(clients_mutex);
      if (connections[address] >= options.max_connections_per_client) {
        answer_and_close(sock, 503, "too many connections from " + address);
        return true;
      }
      ++connections[address];
    }
    struct release {
      impl* self;
      const std::string& address;
      bool counted;
      ~release() {
        if (!counted) return;
        std::lock_guard lock(self->clients_mutex);
        if (--self->connections[address] == 0) self->connections.erase(address);
      }
    } on_exit{this, address, counted};
    const request_error head = wait_for_head(sock);
    if (head.status == 0) {
      ::close(sock);
      return true;
    }
    if (head.status != 200) {
      answer_and_close(sock, head.status, head.reason);
      return true;
    }
    return http.process(sock);  // closes the socket
  }

  bool has_token(const httplib::Request& req) const {
    return req.has_header(token_header) &&
           same_secret(req.get_header_value(token_header), options.token);
  }

  bool may_control(const httplib::Request& req) const {
    return !options.token_required || has_token(req);
  }

  // The page a request comes from (server_control.hpp): its header, or ?client= (the event
  // stream's); empty for a program without one.
  static std::string client_of(const httplib::Request& req) {
    if (req.has_header(client_header)) return detail::valid_client_id(req.get_header_value(client_header));
    return req.has_param("client") ? detail::valid_client_id(req.get_param_value("client")) : std::string();
  }
  // A client that may control is there: a program renews the axis it names, a page every axis it holds.
  void renew_for(std::size_t k, const std::string& client) {
    if (client.empty()) return axes[k].drive->renew_lease();
    for (const std::size_t held : control.renew(client, detail::control_board::clock::now())) {
      axes[held].drive->renew_lease();
    }
  }
  std::size_t index_of(const axis* a) const { return static_cast<std::size_t>(a - axes.data()); }
  json control_json(std::size_t k, const std::string& client) const {
    const auto now = detail::control_board::clock::now();
    json held = json::array();
    for (std::size_t i = 0; i < axes.size(); ++i) {
      if (control.standing(i, client, now) == detail::control_standing::here) held.push_back(i + 1);
    }
    return {{"axis", k + 1}, {"control", detail::standing_name(control.standing(k, client, now))}, {"held", held}};
  }
  // GET and POST /api/control: where the axis stands for this page; {"hold": true} takes control of
  // it from any other page, {"hold": false} lets it go.
  void on_control(const httplib::Request& req, httplib::Response& res, bool post) {
    const axis* a = axis_named(req, res);
    if (a == nullptr) return;
    const std::size_t k = index_of(a);
    const std::string client = client_of(req);
    if (post) {
      if (const auto e = check_post(req, options.max_body)) return send_error(res, e->status, e->reason);
      if (client.empty()) return send_error(res, 400, std::string("a page names itself with ") + client_header);
      const json body = json::parse(req.body, nullptr, false);
      if (!body.is_object() || body.size() != 1 || !body.contains("hold") || !body["hold"].is_boolean()) {
        return send_error(res, 400, "the body is {\"hold\": true} (take control) or {\"hold\": false} (let go)");
      }
      control.set_hold(k, client, body["hold"].get<bool>(), detail::control_board::clock::now());
      if (body["hold"].get<bool>()) renew_for(k, client);
    }
    send_json(res, 200, control_json(k, client));
  }

  // The checks every POST passes before its body is read as JSON.
  std::optional<request_error> check_post(const httplib::Request& req, std::size_t max_body) const {
    if (options.token_required) {
      if (!has_token(req)) {
        return request_error{403,
                             "control needs the token printed by cia402 serve (header " +
                                 std::string(token_header) + "); without it the page is view-only"};
      }
    } else if (!is_loopback_address(host_of(req.get_header_value("Host")))) {
      // Bound to loopback without a token: only a page reached by a loopback name may control, so
      // a foreign site cannot reach the drive by DNS rebinding.
      return request_error{403, "control without a token is only for a loopback Host"};
    }
    if (req.has_header("Origin") &&
        req.get_header_value("Origin") != "http://" + req.get_header_value("Host")) {
      return request_error{403, "cross-origin request refused"};
    }
    if (!detail::is_json_content_type(req.get_header_value("Content-Type"))) {
      return request_error{415, "Content-Type must be application/json"};
    }
    if (req.body.size() > max_body) {
      return request_error{413, "body larger than " + std::to_string(max_body) + " bytes"};
    }
    return std::nullopt;
  }

  // Checks and parses a POST body (at most `max_body` bytes): the drive it names and its JSON
  // object, or nothing with the refusal sent.
  std::optional<std::pair<backend*, json>> post_body(const httplib::Request& req, httplib::Response& res,
                                                     std::size_t max_body) {
    if (const auto e = check_post(req, max_body)) {
      send_error(res, e->status, e->reason);
      return std::nullopt;
    }
    const axis* a = axis_named(req, res);
    if (a == nullptr) return std::nullopt;
    backend* inst = a->drive;
    // One page controls an axis at a time: another page's command is refused until it takes control.
    const std::string client = client_of(req);
    if (!control.claim(index_of(a), client, detail::control_board::clock::now())) {
      send_json(res, 409, json{{"error", a->label + " is controlled by another page: take control to command it here"},
                               {"controlled_elsewhere", true}});
      return std::nullopt;
    }
    renew_for(index_of(a), client);  // a client that controls is there
    // A key given twice is refused: "last wins" would act on a value the sender may not have meant.
    std::vector<std::set<std::string>> keys;
    bool duplicate = false;
    json body = json::parse(
        req.body,
        [&](int, json::parse_event_t event, json& parsed) {
          if (event == json::parse_event_t::object_start) keys.emplace_back();
          if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
          if (event == json::parse_event_t::key && !keys.empty() &&
              !keys.back().insert(parsed.get<std::string>()).second) {
            duplicate = true;
          }
          return true;
        },
        false);
    const char* why = body.is_discarded() ? "body is not valid JSON"
                      : duplicate         ? "a key is given twice in the body"
                      : !body.is_object() ? "body must be a JSON object"
                                          : nullptr;
    if (why != nullptr) {
      send_error(res, 400, why);
      return std::nullopt;
    }
    return std::pair{inst, std::move(body)};
  }

  // Checks, parses and hands a POST body to `act`, which returns the instrument's reply or a
  // request error of its own.
  template <typename Act>
  void post(const httplib::Request& req, httplib::Response& res, Act act) {
    auto body = post_body(req, res, options.max_body);
    if (!body) return;
    std::variant<reply, request_error> r = act(*body->first, body->second);
    if (auto* e = std::get_if<request_error>(&r)) return send_error(res, e->status, e->reason);
    const reply& rep = std::get<reply>(r);
    if (const auto* ok = std::get_if<accepted>(&rep)) {
      json j{{"id", ok->id}};
      if (!ok->text.empty()) j["text"] = ok->text;
      return send_json(res, 200, j);
    }
    detail::send_refusal(res, std::get<refused>(rep));
  }

  // The drive a request names with ?axis=K (1..N; the first without it), or nullptr with the
  // refusal sent.
  const axis* axis_named(const httplib::Request& req, httplib::Response& res) const {
    if (!req.has_param("axis")) return &axes.front();
    const std::string v = req.get_param_value("axis");
    std::size_t k = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), k);
    if (ec != std::errc() || end != v.data() + v.size() || k < 1 || k > axes.size()) {
      send_error(res, 404, "no axis '" + v + "' (1.." + std::to_string(axes.size()) + ")");
      return nullptr;
    }
    return &axes[k - 1];
  }
  backend* axis_of(const httplib::Request& req, httplib::Response& res) const {
    const axis* a = axis_named(req, res);
    return a != nullptr ? a->drive : nullptr;
  }

  // The routes by concern, registered in this order (cpp-httplib takes the first that matches).
  void routes() {
    set_up_connections();
    add_asset_routes();
    add_view_routes();
    add_recording_routes();
    add_action_routes();
  }

  // How the two servers take connections and requests: the socket options, the limits on what a
  // request may bring, the headers of every answer, and the answers to errors.
  void set_up_connections() {
    // cpp-httplib's default sets SO_REUSEPORT, so a second `cia402 serve` on the same port would
    // listen too and the two would answer in turn. SO_REUSEADDR alone still allows a restart while
    // old connections linger, and makes the second bind fail.
    front.admit = [this](socket_t sock) { return admit(sock); };
    front.set_socket_options([this](socket_t sock) {
      const int yes = 1;
      ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
      listen_fd = sock;
    });
    http.set_payload_max_length(std::max(options.max_body, options.max_file_body));
    // A client that sends its request slowly holds a worker only this long per read.
    http.set_read_timeout(options.read_timeout);
    http.set_write_timeout(std::chrono::seconds(5));
    // What a request may bring is checked on its head, before any body is read: a chunked body (no
    // length known before it is read whole), a length over max_body. (The head itself the guard
    // checked before it was read.)
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      std::optional<request_error> e;
      if (req.has_header("Transfer-Encoding")) {
        e = request_error{411, "chunked bodies are not accepted: send Content-Length"};
      } else if (const std::size_t most = req.path == detail::parameter_file_path ? options.max_file_body
                                                                                 : options.max_body;
                 req.has_header("Content-Length") && !length_within(req.get_header_value("Content-Length"), most)) {
        e = request_error{413, "body larger than " + std::to_string(most) + " bytes"};
      }
      if (!e) return httplib::Server::HandlerResponse::Unhandled;
      // The unread body must not be taken for the next request: this connection ends here.
      res.set_header("Connection", "close");
      send_error(res, e->status, e->reason);
      return httplib::Server::HandlerResponse::Handled;
    });
    // One request per connection, so every request passes the guard's checks on its head.
    http.set_keep_alive_max_count(1);
    // Event streams hold a thread each while open; leave room for ordinary requests.
    const auto threads = static_cast<std::size_t>(options.max_event_streams) + options.workers;
    front.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
    http.set_default_headers({
        {"Content-Security-Policy",
         "default-src 'self'; img-src 'self' data:; style-src 'self'; script-src 'self'; "
         "connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'"},
        {"X-Content-Type-Options", "nosniff"},
        {"Referrer-Policy", "no-referrer"},
        {"Cache-Control", "no-store"},
    });
    http.set_error_handler(httplib::Server::HandlerWithResponse(
        [this](const httplib::Request& req, httplib::Response& res) {
      if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
      std::string reason;
      switch (res.status) {
        case 404: reason = "no such resource: " + req.path; break;
        case 413: reason = "body larger than " + std::to_string(options.max_body) + " bytes"; break;
        case 400: reason = "malformed request"; break;
        default: reason = "HTTP status " + std::to_string(res.status); break;
      }
      send_error(res, res.status, reason);
      return httplib::Server::HandlerResponse::Handled;
    }));
    http.set_exception_handler(
        [](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
          send_error(res, 500, "internal error");
        });
  }

  // The page itself: its embedded files, "/" for index.html.
  void add_asset_routes() {
    for (const web::asset& a : web::assets()) {
      const std::string content_type = a.content_type;
      const std::string_view data(reinterpret_cast<const char*>(a.data), a.size);
      auto serve = [content_type, data](const httplib::Request&, httplib::Response& res) {
        res.set_content(data.data(), data.size(), content_type);
      };
      http.Get(a.path, serve);
      if (std::string_view(a.path) == "/index.html") http.Get("/", serve);
    }
    http.Get("/favicon.ico", [](const httplib::Request&, httplib::Response& res) { res.status = 204; });
  }

  // What the page reads of an axis (GET): its info, who controls it (and POST to take or leave
  // control), the overview of every axis, its state, its drive's errors, the event stream.
  void add_view_routes() {
    http.Get("/api/info", [this](const httplib::Request& req, httplib::Response& res) {
      const axis* a = axis_named(req, res);
      if (a == nullptr) return;
      json j = json::parse(a->drive->info_json(may_control(req), options.token_required));
      j["axis"] = static_cast<std::size_t>(a - axes.data()) + 1;
      j["axis_label"] = a->label;
      j["axes"] = axes.size();
      res.set_content(detail::json_text(j), "application/json");
    });
    http.Get("/api/control", [this](const httplib::Request& req, httplib::Response& res) { on_control(req, res, false); });
    http.Post("/api/control", [this](const httplib::Request& req, httplib::Response& res) { on_control(req, res, true); });
    http.Get("/api/axes", [this](const httplib::Request& req, httplib::Response& res) {
      // The overview: each axis's present state in a few values.
      json list = json::array();
      for (std::size_t k = 0; k < axes.size(); ++k) {
        const json s = json::parse(axes[k].drive->snapshot_json(), nullptr, false);
        json entry{{"axis", k + 1}, {"label", axes[k].label},
                   {"control", detail::standing_name(control.standing(k, client_of(req), detail::control_board::clock::now()))}};
        if (s.is_object()) {
          for (const char* key : {"profile", "state", "status_word", "velocity", "error_code", "error_text"}) {
            if (s.contains(key)) entry[key] = s[key];
          }
        }
        list.push_back(std::move(entry));
      }
      send_json(res, 200, list);
    });
    http.Get("/api/state", [this](const httplib::Request& req, httplib::Response& res) {
      const axis* a = axis_named(req, res);
      if (a == nullptr) return;
      if (may_control(req)) renew_for(index_of(a), client_of(req));  // a client that polls the state is there
      res.set_content(a->drive->snapshot_json(), "application/json");
    });
    http.Get("/api/errors", [this](const httplib::Request& req, httplib::Response& res) {
      // The drive's 0x1003 as last read (the snapshot's drive_errors); POST /api/errors/read reads anew.
      if (backend* inst = axis_of(req, res)) send_json(res, 200, json::parse(inst->snapshot_json())["drive_errors"]);
    });
    http.Get("/api/events", [this](const httplib::Request& req, httplib::Response& res) {
      const axis* a = axis_named(req, res);
      if (a == nullptr) return;
      // Each write renews: a program's stream its axis, a page's every axis it holds.
      std::function<void()> renew = [] {};
      if (may_control(req)) renew = [this, k = index_of(a), client = client_of(req)] { renew_for(k, client); };
      detail::serve_events(*a->drive, res, options, streams, stopping, std::move(renew));
    });
  }

  // The recorder's rows and transitions: as JSON since what the page has seen, and as files.
  void add_recording_routes() {
    http.Get("/api/recording", [this](const httplib::Request& req, httplib::Response& res) {
      std::uint64_t seen[2] = {0, 0};
      const char* keys[2] = {"rows_seen", "transitions_seen"};
      for (int i = 0; i < 2; ++i) {
        if (!req.has_param(keys[i])) continue;
        const std::string v = req.get_param_value(keys[i]);
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), seen[i]);
        if (ec != std::errc() || end != v.data() + v.size() || v.empty()) {
          return send_error(res, 400, std::string(keys[i]) + " must be a count (0, 1, 2, ...)");
        }
      }
      if (backend* inst = axis_of(req, res)) {
        res.set_content(inst->recording_json(seen[0], seen[1]), "application/json");
      }
    });
    http.Get("/api/recording.csv", [this](const httplib::Request& req, httplib::Response& res) {
      backend* inst = axis_of(req, res);
      if (inst == nullptr) return;
      res.set_header("Content-Disposition", "attachment; filename=\"cia402-recording.csv\"");
      res.set_content(inst->recording_file(recording_format::csv), "text/csv");
    });
    http.Get("/api/recording.vcd", [this](const httplib::Request& req, httplib::Response& res) {
      const std::string form = req.has_param("form") ? req.get_param_value("form") : "ieee";
      if (form != "ieee" && form != "gtkwave") {
        return send_error(res, 400, "form must be ieee (IEEE 1364) or gtkwave ($var string)");
      }
      backend* inst = axis_of(req, res);
      if (inst == nullptr) return;
      res.set_header("Content-Disposition", "attachment; filename=\"cia402-recording.vcd\"");
      res.set_content(inst->recording_file(form == "gtkwave" ? recording_format::vcd_gtkwave
                                                            : recording_format::vcd),
                      "text/plain");
    });
  }

  // What commands an axis (POST with a JSON body, checked by post()): commands, the plant, object
  // writes, the profile, enable and stop, jog, homing, the drive's error field, the parameter list;
  // a GET to one of them is told to POST.
  void add_action_routes() {
    http.Post("/api/command", [this](const httplib::Request& req, httplib::Response& res) {
      post(req, res, &detail::command_request);
    });
    http.Post("/api/plant", [this](const httplib::Request& req, httplib::Response& res) {
      post(req, res, &detail::plant_request);
    });
    http.Post("/api/object", [this](const httplib::Request& req, httplib::Response& res) {
      post(req, res, &detail::object_request);
    });
    http.Post("/api/profile", [this](const httplib::Request& req, httplib::Response& res) {
      post(req, res, &detail::profile_request);
    });
    // One-click enable and stop, and the jog with its dead-man (commissioning.hpp).
    for (const auto& [path, act] : {std::pair{"/api/enable", &detail::bare_request<&backend::enable>},
                                    std::pair{"/api/stop", &detail::bare_request<&backend::stop>},
                                    std::pair{"/api/jog", &detail::jog_request},
                                    std::pair{"/api/homing", &detail::homing_request_of},
                                    std::pair{"/api/errors/read", &detail::bare_request<&backend::read_error_field>},
                                    std::pair{"/api/errors/clear", &detail::bare_request<&backend::clear_error_field>}}) {
      http.Post(path, [this, act = act](const httplib::Request& req, httplib::Response& res) {
        post(req, res, act);
      });
    }
    detail::add_parameter_routes(
        http, {[this](const httplib::Request& req, httplib::Response& res) { return axis_of(req, res); },
               [this](const httplib::Request& req, httplib::Response& res) {
                 return post_body(req, res, options.max_file_body);
               }});
    for (const char* path : {"/api/command", "/api/plant", "/api/profile", "/api/enable",
                             "/api/stop", "/api/jog", "/api/homing", "/api/errors/read",
                             "/api/errors/clear"}) {
      http.Get(path, [](const httplib::Request&, httplib::Response& res) {
        send_error(res, 405, "use POST with a JSON body");
      });
    }
  }
};

server::server(backend& inst, server_options options)
    : server(std::vector<axis>{{"axis 1", &inst}}, std::move(options)) {}

server::server(std::vector<axis> axes, server_options options)
    : impl_(std::make_unique<impl>(std::move(axes), std::move(options))) {
  impl_->routes();
}

server::~server() { stop(); }

bool server::bind() {
  impl& m = *impl_;
  if (m.port >= 0) return true;
  if (m.options.port < 0 || m.options.port > 65535) {
    m.error = "port must be 0..65535";
    return false;
  }
  int port = -1;
  if (m.options.port == 0) {
    port = m.front.bind_to_any_port(m.options.bind);
  } else if (m.front.bind_to_port(m.options.bind, m.options.port)) {
    port = m.options.port;
  }
  if (port < 0) {
    m.error = "cannot listen on " + m.options.bind + " port " + std::to_string(m.options.port) +
              " (address in use, or not an address of this machine)";
    return false;
  }
  m.port = port;
  // cpp-httplib listens with a queue of 5: a burst of connects then waits for SYN retries (1 s
  // each). Listening again on the bound socket sets the queue's length.
  if (m.listen_fd >= 0) ::listen(m.listen_fd, SOMAXCONN);
  m.http.adopt_listener(m.listen_fd);
  return true;
}

int server::bound_port() const { return impl_->port; }
const std::string& server::error() const { return impl_->error; }
const server_options& server::options() const { return impl_->options; }

void server::start() {
  if (impl_->port < 0 || impl_->thread.joinable()) return;
  impl_->thread = std::thread([this] {
    impl_->front.listen_after_bind();
    impl_->listen_returned = true;
  });
}

void server::stop() {
  impl_->stopping = true;
  // A stop before the thread has begun to listen would be lost and the join below would wait for
  // ever: wait until it listens (or has given up) first.
  if (impl_->thread.joinable()) {
    while (!impl_->front.is_running() && !impl_->listen_returned) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  impl_->front.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
  impl_->http.adopt_listener(INVALID_SOCKET);
}

std::string server::url() const {
  const std::string& host = impl_->options.bind;
  const bool v6 = host.find(':') != std::string::npos;
  std::string u = "http://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(impl_->port) + "/";
  if (impl_->options.token_required) u += "?token=" + impl_->options.token;
  return u;
}

}  // namespace cia402::page
