#include "server_control.hpp"

namespace cia402::page::detail {

const char* standing_name(control_standing s) noexcept {
  switch (s) {
    case control_standing::here: return "here";
    case control_standing::elsewhere: return "elsewhere";
    case control_standing::free: break;
  }
  return "free";
}

control_standing control_board::standing(std::size_t k, std::string_view client, clock::time_point now) const {
  std::lock_guard lock(mutex_);
  const std::optional<holder>& h = holds_.at(k);
  if (!h) return control_standing::free;
  if (!client.empty() && h->client == client) return control_standing::here;
  return live(*h, now) ? control_standing::elsewhere : control_standing::free;
}

bool control_board::claim(std::size_t k, std::string_view client, clock::time_point now) {
  if (client.empty()) return true;
  std::lock_guard lock(mutex_);
  std::optional<holder>& h = holds_.at(k);
  if (h && h->client != client && live(*h, now)) return false;
  h = holder{std::string(client), now};
  return true;
}

void control_board::set_hold(std::size_t k, std::string_view client, bool hold, clock::time_point now) {
  if (client.empty()) return;
  std::lock_guard lock(mutex_);
  std::optional<holder>& h = holds_.at(k);
  if (hold) {
    h = holder{std::string(client), now};
  } else if (h && h->client == client) {
    h.reset();
  }
}

std::vector<std::size_t> control_board::renew(std::string_view client, clock::time_point now) {
  std::vector<std::size_t> held;
  if (client.empty()) return held;
  std::lock_guard lock(mutex_);
  for (std::size_t k = 0; k < holds_.size(); ++k) {
    if (holds_[k] && holds_[k]->client == client) {
      holds_[k]->seen = now;
      held.push_back(k);
    }
  }
  return held;
}

std::string valid_client_id(std::string_view id) {
  if (id.empty() || id.size() > 64) return {};
  for (const char c : id) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
    if (!ok) return {};
  }
  return std::string(id);
}

}  // namespace cia402::page::detail
