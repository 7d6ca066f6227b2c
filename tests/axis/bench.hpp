// A session on a sim_link, run in steps of 1 ms of virtual time.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cia402/axis/session.hpp"
#include "sim_link.hpp"

namespace cia402::axes::test {

struct bench {
  sim_link link;
  std::optional<session> s;
  std::vector<std::pair<progress_kind, result>> progress;
  std::vector<std::string> lapses;

  explicit bench(session_config c = {}, const profile& p = standard_profile(), bool cyclic_setpoints = true)
      : link(p, cyclic_setpoints) {
    if (c.drive_profile == nullptr) c.drive_profile = &p;
    s.emplace(link, c);
    s->on_progress = [this](progress_kind k, const result& r) { progress.emplace_back(k, r); };
    s->on_lease_lapsed = [this](const std::string& what) { lapses.push_back(what); };
  }

  /// Polls every ms until `done` says so, at most `ms`; true if it did.
  bool run_until(const std::function<bool()>& done, int ms = 20000) {
    for (int i = 0; i < ms; ++i) {
      (void)s->poll(1000);
      if (done()) return true;
    }
    return false;
  }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) (void)s->poll(1000);
  }
  /// Issues a request and runs until it has ended; the result (end failed with "no end" if never).
  result finish(const std::function<std::uint64_t(completion)>& request, int ms = 20000) {
    std::optional<result> got;
    request([&got](const result& r) { got = r; });
    if (!run_until([&] { return got.has_value(); }, ms)) {
      result r;
      r.end = outcome::failed;
      r.error = "no end within the test's time";
      return r;
    }
    return *got;
  }
  result enable() {
    return finish([this](completion d) { return s->go_to(state::operation_enabled, std::move(d)); });
  }
  /// Raises a fault (0x603F = code) in the drive and polls until the session sees FAULT, at most
  /// `ms`; true if it did.
  bool fault(std::uint16_t code = 0x2310, int ms = 1000) {
    link.drive.view().inject_fault(code);
    return run_until([this] { return s->observed() == state::fault; }, ms);
  }
  bool sent(std::uint16_t mask, std::uint16_t value) const {
    for (const auto& [t, w] : link.words) {
      if ((w & mask) == value) return true;
    }
    return false;
  }
};

/// The request failed and its error names every one of `parts`: what most failure cases check of a
/// result. When not, the message says which part is missing and shows the whole error.
inline ::testing::AssertionResult failed_naming(const result& r, std::initializer_list<std::string_view> parts) {
  if (r.ok()) return ::testing::AssertionFailure() << "the request succeeded";
  for (const std::string_view part : parts) {
    if (r.error.find(part) == std::string::npos) {
      return ::testing::AssertionFailure() << "the error does not name \"" << part << "\": " << r.error;
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace cia402::axes::test
