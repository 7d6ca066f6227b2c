#include "snapshot_board.hpp"

#include "json_text.hpp"

namespace cia402::page::detail {

void snapshot_board::publish(const std::function<json(bool with_time)>& snapshot) {
  std::string body = json_text(snapshot(false));
  {
    std::lock_guard lock(mutex_);
    if (body == published_body_ && newest_.version != 0) return;
    published_body_ = std::move(body);
    json j = snapshot(true);
    j["version"] = newest_.version + 1;
    newest_.version += 1;
    newest_.json = json_text(j);
  }
  updated_.notify_all();
}

std::string snapshot_board::present_json(json snapshot) const {
  std::lock_guard lock(mutex_);
  snapshot["version"] = newest_.version;
  return json_text(snapshot);
}

std::optional<published> snapshot_board::wait_for_update(std::uint64_t seen,
                                                         std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  updated_.wait_for(lock, timeout, [&] { return closed_ || newest_.version > seen; });
  if (newest_.version > seen) return newest_;
  return std::nullopt;
}

published snapshot_board::latest() const {
  std::lock_guard lock(mutex_);
  return newest_;
}

void snapshot_board::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  updated_.notify_all();
}

bool snapshot_board::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

}  // namespace cia402::page::detail
