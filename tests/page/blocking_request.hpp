// A page request that waits for a transfer on a bus the test runs itself, in virtual time: made on a
// thread of its own while the test's thread runs the bus a millisecond at a time. Shared by the
// CAN and EtherCAT benches (remote_bench.hpp, ecat_drive_test.cpp).
#pragma once

#include <chrono>
#include <future>

namespace cia402::page::testing {

/// `request`'s answer; the bus runs (`run_one_ms`) until it comes, for 20 s of wall time at most.
template <typename Request, typename RunOneMs>
auto blocking_request(Request request, RunOneMs run_one_ms) {
  auto result = std::async(std::launch::async, request);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (result.wait_for(std::chrono::microseconds(50)) != std::future_status::ready &&
         std::chrono::steady_clock::now() < give_up) {
    run_one_ms();
  }
  return result.get();
}

}  // namespace cia402::page::testing
