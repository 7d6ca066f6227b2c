// The instrument page over HTTP (cpp-httplib): the page's files, embedded in the binary; a JSON API
// for commands, bit toggles, object writes and plant inputs; live snapshots as Server-Sent Events.
//
//   GET  /                 the page (index.html, app.js, style.css)
//   GET  /api/axes         the overview: each axis's label, profile, state, status word, velocity
//   GET  /api/info         profile, bit names, transition rows; "control": may this client control
//   GET  /api/state        the present snapshot
//   GET  /api/events       text/event-stream: a snapshot at once, then each published one
//                          (at most 25 a second, only on change), a comment line as keep-alive
//   GET  /api/recording    the recorder: rows and transitions after ?rows_seen=R&transitions_seen=T
//   GET  /api/recording.csv, /api/recording.vcd[?form=gtkwave]   the whole recording as a file
//   POST /api/command      {"command":"shutdown"|...|"fault_reset"|"halt"} or
//                          {"command":"toggle_bit","bit":N}
//   POST /api/plant        {"target_velocity":N, "fault":true, "fault_code":"0x1000",
//                          "fault_class":2, "dc_link":false, "sto":true} (any of them)
//   POST /api/object       {"index":"0x605A","value":6}
//   POST /api/profile      {"profile":"s300-profibus"}: a virtual drive starts again under it
//
// The sign of life (docs/page.md): each write of an open event stream, each POST and each GET
// /api/state of a client that may control renew the drive's lease (backend::renew_lease); a page
// with a client id renews every axis it holds instead (server_control.hpp).
//
// Every /api/ path but /api/axes takes ?axis=K (1..N) to name one of several drives; without it,
// the first.
//
// Every POST needs Content-Type application/json and a JSON object body of at most
// server_options::max_body bytes; unknown keys, wrong types and out-of-range values are refused
// with a 4xx and {"error": reason}, and change nothing. With a token required, a POST without
// header X-Cia402-Token carrying it is refused with 403 (the page is then view-only). Without a
// token, a POST must come from a loopback Host (no DNS rebinding), and from the page's own origin.
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cia402/page/backend.hpp"

namespace cia402::page {

struct server_options {
  std::string bind = "127.0.0.1";
  int port = 8402;  ///< 0: any free port (bound_port() tells which)
  /// Control needs the token. `cia402 serve` turns it on for any non-loopback --bind address and
  /// for --token-required.
  bool token_required = false;
  std::string token;  ///< the token; make_token() when empty and required
  std::size_t max_body = 4096;
  /// A parameter file's body (POST /api/parameters.dcf): a DCF of a whole drive is tens of KB.
  std::size_t max_file_body = 1 << 20;
  std::size_t max_headers = 64;  ///< header lines a request may have (431 beyond)
  std::size_t max_head = 16384;  ///< bytes of a request's head (431 beyond)
  /// Open connections one client address may hold (beyond loopback; 503 beyond).
  int max_connections_per_client = 32;
  int max_event_streams = 16;
  /// Threads for ordinary requests besides the event streams: a few slow clients cannot take
  /// them all, each is dropped after read_timeout without a byte.
  std::size_t workers = 48;
  /// The whole head of a request must arrive within this (408), and each later read too.
  std::chrono::milliseconds read_timeout{2000};
  std::chrono::milliseconds keep_alive{15000};  ///< SSE comment line when nothing was published
  /// The drive's per-cycle samples (the scope's): a batch (SSE event `samples`) at most this often
  /// per stream, of at most samples_per_batch samples (1 kHz catches up 40 times faster than it comes).
  std::chrono::milliseconds samples_every{50};
  std::size_t samples_per_batch = 2000;
  /// An open event stream renews its drive's lease (backend::renew_lease) with each write that goes
  /// out, and writes a comment at least this often so a closed page is noticed (its second write
  /// after the close fails).
  std::chrono::milliseconds sign_of_life{250};
  /// A page holds the axes it commands while it is there (docs/instrument-page.md, "Control
  /// model"); a hold nothing renewed for this long lets another page command the axis.
  std::chrono::milliseconds control_hold{1000};
};

/// 32 hex digits (128 bits) from std::random_device.
std::string make_token();

/// True for 127.0.0.0/8, ::1 and "localhost".
bool is_loopback_address(std::string_view host);

/// One drive the page serves, and how the overview names it ("axis 2", "node 5").
struct axis {
  std::string label;
  backend* drive = nullptr;
};

class server {
 public:
  /// The backend (axis_page.hpp, or a test's own) must outlive the server.
  server(backend& inst, server_options options);
  /// Several drives (at least one), each an axis of the page: every /api/ path takes ?axis=K
  /// (1..N, the first without it). The backends must outlive the server. Throws
  /// std::invalid_argument for no axis at all.
  server(std::vector<axis> axes, server_options options);
  ~server();
  server(const server&) = delete;
  server& operator=(const server&) = delete;

  /// Binds the socket. Returns false (and error() says why) if that fails.
  bool bind();
  /// The port bound (the real one for port 0), -1 before bind().
  int bound_port() const;
  const std::string& error() const;
  const server_options& options() const;

  /// Serves in a thread of its own until stop(). Requires bind().
  void start();
  /// Stops serving: open event streams end, the thread is joined. Idempotent.
  void stop();

  /// "http://127.0.0.1:8402/" with "?token=..." when a token is required.
  std::string url() const;

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace cia402::page
