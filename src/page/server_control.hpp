// Which page controls each axis (issue 42; docs/instrument-page.md, "Control model"). A page names
// itself with a client id (X-Cia402-Client, or ?client= on the event stream, which cannot send a
// header); the id lives in the tab (sessionStorage), so it stays the same when the page shows
// another axis. A page that commands an axis holds it: one page at a time, a second one is refused
// (409, "controlled elsewhere") until it takes control explicitly or the first one is gone (nothing
// renewed its hold for `hold`). Each write of a page's event stream, whichever axis it shows,
// renews every axis it holds, and so their leases. A client without an id (a program) is obeyed as
// before and holds nothing.
#pragma once

#include <chrono>
#include <cstddef>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cia402::page::detail {

/// Where an axis stands for one client.
enum class control_standing { free, here, elsewhere };
const char* standing_name(control_standing s) noexcept;

class control_board {
 public:
  using clock = std::chrono::steady_clock;
  control_board(std::size_t axes, std::chrono::milliseconds hold) : holds_(axes), hold_(hold) {}

  /// Axis k (0-based) for `client` at `now`: held by it, by another page that is still there, or free.
  control_standing standing(std::size_t k, std::string_view client, clock::time_point now) const;
  /// A command from `client` to axis k: true when it may act (it holds k from now on, when it was
  /// free); false when another page holds it. A client without an id always may and holds nothing.
  bool claim(std::size_t k, std::string_view client, clock::time_point now);
  /// `client` takes axis k from whoever holds it (hold true) or lets it go if it holds it (false).
  void set_hold(std::size_t k, std::string_view client, bool hold, clock::time_point now);
  /// `client` is there: each axis it holds (or held last, and no other page took since) is held
  /// anew. Returns those axes, 0-based.
  std::vector<std::size_t> renew(std::string_view client, clock::time_point now);

 private:
  struct holder {
    std::string client;
    clock::time_point seen;
  };
  bool live(const holder& h, clock::time_point now) const { return now - h.seen < hold_; }

  mutable std::mutex mutex_;
  std::vector<std::optional<holder>> holds_;
  std::chrono::milliseconds hold_;
};

/// A client id as a request gives it: 1..64 of [A-Za-z0-9_-]; anything else is no id.
std::string valid_client_id(std::string_view id);

}  // namespace cia402::page::detail
