// The page's sign of life (issue 33): an open page renews a lease (its event stream, each request of
// a client that may control); when nothing renewed it for the lease time, a drive left in OPERATION
// ENABLED is stopped as its 0x6007 says (cia402::stop_for_lost_client), as its master would stop it
// for a lost connection. Without this, a drive enabled through the page kept turning after the tab
// was closed. Both backends run it on their own clock (the cycles they stepped).
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>

#include "cia402/profile.hpp"
#include "word_change.hpp"

namespace cia402::page::detail {

class sign_of_life {
 public:
  /// `lease_us` 0: no lease, never lapses.
  explicit sign_of_life(std::uint64_t lease_us) noexcept : lease_us_(lease_us) {}

  /// A client is there (any thread).
  void renew() noexcept { renewed_.store(true, std::memory_order_relaxed); }

  /// The cycle thread, at `now_us` of its clock: true once, when `lease_us` passed since the last
  /// renewal. Nothing lapses before the first renewal (no client has commanded the drive yet).
  bool lapsed(std::uint64_t now_us) noexcept {
    if (renewed_.exchange(false, std::memory_order_relaxed)) {
      last_us_ = now_us;
      armed_ = true;
    }
    if (lease_us_ == 0 || !armed_ || now_us - last_us_ < lease_us_) return false;
    armed_ = false;
    return true;
  }

  std::uint64_t lease_us() const noexcept { return lease_us_; }

 private:
  std::atomic<bool> renewed_{false};
  std::uint64_t lease_us_;
  std::uint64_t last_us_ = 0;
  bool armed_ = false;
};

/// The control-word change that stops a drive whose page went silent, as its 0x6007 value
/// `abort_connection` says: Disable voltage, Quick stop, or halt (bit 8 set) — nothing when the
/// halt is already set. Its action is named "SIGN OF LIFE LOST (...): " and the stop.
std::optional<word_change> stop_for_silent_page(const profile& p, std::uint16_t control_word,
                                                int abort_connection, std::uint64_t lease_us);

}  // namespace cia402::page::detail
