// Where a backend puts its snapshots for the page, and where the HTTP threads wait for a newer one
// (the page's long poll). Both backends publish alike: a new version only when the snapshot changed,
// not when only its clock moved on, so an idle drive sends the page nothing.
//
// It has a lock of its own, so a page waiting for news never holds up the drive. A backend
// publishes while it holds its own lock; the order is always the backend's lock, then this one.
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "cia402/page/backend.hpp"

namespace cia402::page::detail {

class snapshot_board {
 public:
  using json = nlohmann::ordered_json;

  /// Publishes the next version unless the snapshot without its time fields is the one published
  /// last (the first is always published). `snapshot(with_time)` builds the backend's snapshot;
  /// the one with time is built only when it is published, under the board's lock (so it must
  /// not call the board).
  void publish(const std::function<json(bool with_time)>& snapshot);

  /// The present snapshot as text, carrying the newest published version (the page compares it
  /// with the version it has).
  std::string present_json(json snapshot) const;

  /// See backend::wait_for_update, backend::latest, backend::close.
  std::optional<published> wait_for_update(std::uint64_t seen, std::chrono::milliseconds timeout);
  published latest() const;
  void close();
  bool closed() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable updated_;
  bool closed_ = false;
  std::string published_body_;  // the newest snapshot without its time fields
  published newest_;
};

}  // namespace cia402::page::detail
