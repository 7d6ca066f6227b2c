// The page's remote backend as `cia402 serve --can` builds it, against a `cia402 bus`-equivalent
// node (the simulator's drive behind a CiA 301 slave) on the in-process virtual bus, in virtual
// time, no sockets: shared by remote_drive_test.cpp and remote_scope_test.cpp.
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "blocking_request.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/page/axis_page.hpp"
#include "cia402/profile.hpp"

namespace remote_drive_testing {
namespace co = cia402::canopen;
namespace apps = cia402::apps;
using cia402::page::accepted;
using cia402::page::page_command;
using cia402::page::plant_change;
using cia402::page::refused;
using cia402::page::axis_page;
using cia402::page::reply;
using json = nlohmann::json;

// The page's drive as `cia402 serve --can` builds it: an axis page over a can_link to the node.
struct remote_config {
  co::can_link_config link;
  cia402::page::axis_page_config page;
};

inline remote_config test_config(std::uint8_t node = 1) {
  remote_config c;
  c.link.node_id = node;
  c.link.bus_name = "virtual (test)";
  c.link.master_heartbeat_ms = 100;  // the page's own heartbeat, watched by the drive (0x1016)
  c.link.retry_us = 1000000;         // as serve sets it: a node that comes back is taken up again
  c.link.known_objects = co::node_objects(apps::drive_node_config(node));
  c.page.node = node;
  c.page.reset_pulse_us = 20000;
  c.page.settle_quiet_us = 150000;
  c.page.request_timeout = std::chrono::milliseconds(20000);
  return c;
}

// The virtual bus belongs to one thread, but a request made with blocking() polls the page's link
// on its own thread while the bench's thread runs the node. The page's channel takes the bench's
// lock for each frame and the node runs under it, so the two never touch the bus at once.
class locked_channel final : public co::channel {
 public:
  locked_channel(std::unique_ptr<co::virtual_channel> inner, std::mutex& bus_lock)
      : inner_(std::move(inner)), bus_lock_(&bus_lock) {}
  std::error_code send(const co::frame& f) noexcept override {
    std::lock_guard lock(*bus_lock_);
    return inner_->send(f);
  }
  bool receive(co::frame& f) noexcept override {
    std::lock_guard lock(*bus_lock_);
    return inner_->receive(f);
  }

 private:
  std::unique_ptr<co::virtual_channel> inner_;
  std::mutex* bus_lock_;
};

// One virtual drive as node 1 and the page's backend on the same in-process bus. Each virtual
// millisecond: the backend runs, the node answers and steps its drive, the backend reads the
// answers. `silence()` stops the node (it neither answers nor sends heartbeats).
class remote_bench {
 public:
  explicit remote_bench(remote_config config = test_config(),
                        const cia402::profile& p = cia402::standard_profile())
      : node_(std::make_unique<apps::virtual_drive_node>(p, bus_.attach(), apps::drive_node_config(1))) {
    for (int i = 0; i < 10; ++i) node_->poll(1000);  // power-up: T0, T1
    page_ch_ = std::make_unique<locked_channel>(bus_.attach(), bus_lock_);
    config.link.drive_profile = &p;
    co::channel* ch = page_ch_.get();
    remote_ = std::make_unique<axis_page>(
        p,
        [ch, link = config.link](const cia402::profile&) {
          return cia402::page::drive_connection{std::make_unique<co::can_link>(*ch, link), nullptr};
        },
        config.page);
  }

  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) cycle(1000);
  }

  /// One step() of the page while `drive_us` pass for the drive: a page slowed down by its
  /// machine, whose runner skips the cycles it lost, when drive_us is above cycle_us.
  void cycle(std::uint32_t drive_us) {
    remote_->step();
    run_node(drive_us);
    remote_->advance(0);
    run_node(0);
    remote_->advance(0);
  }

  bool run_until_running(int ms = 2000) {
    for (int i = 0; i < ms; ++i) {
      run_ms(1);
      if (status() == "running") return true;
    }
    return false;
  }

  // A request that waits for a transfer: made on another thread while this one runs the bus.
  template <typename Request>
  reply blocking(Request request) {
    return cia402::page::testing::blocking_request(request, [this] { run_ms(1); });
  }

  void silence() { alive_ = false; }
  /// The node alone, as when the page's process is gone: what it sends is dropped unread.
  void run_drive_only_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      {
        std::lock_guard lock(bus_lock_);
        node_->poll(1000);
      }
      co::frame f;
      while (page_ch_->receive(f)) {}
    }
  }
  apps::virtual_drive_node& drive_node() { return *node_; }
  co::virtual_bus& bus() { return bus_; }
  void revive() { alive_ = true; }

  json snapshot() const { return json::parse(remote_->snapshot_json()); }
  json newest_result() const {
    const json s = snapshot();
    return s["results"].empty() ? json::object() : s["results"][0];
  }
  axis_page& remote() { return *remote_; }
  /// Where the link stands, as the snapshots' `remote` part says it.
  std::string status() const { return snapshot()["remote"]["status"].get<std::string>(); }
  cia402::sim::virtual_drive& drive() { return node_->drive(); }

 private:
  // The node's turn on the bus; a silenced node's frames are taken off unread.
  void run_node(std::uint32_t drive_us) {
    std::lock_guard lock(bus_lock_);
    if (alive_) {
      node_->poll(drive_us);
      return;
    }
    co::frame f;
    while (node_->bus_channel().receive(f)) {}
  }

  std::mutex bus_lock_;
  co::virtual_bus bus_;
  std::unique_ptr<apps::virtual_drive_node> node_;
  std::unique_ptr<locked_channel> page_ch_;
  std::unique_ptr<axis_page> remote_;
  bool alive_ = true;
};

inline bool is_accepted(const reply& r) { return std::holds_alternative<accepted>(r); }

// A command, then time for it to settle (150 ms of quiet after the last change).
inline json command_result(remote_bench& b, page_command c) {
  EXPECT_TRUE(is_accepted(b.remote().command(c)));
  b.run_ms(600);
  return b.newest_result();
}

inline void enable(remote_bench& b) {
  command_result(b, page_command::shutdown);
  command_result(b, page_command::switch_on);
  command_result(b, page_command::enable_operation);
  ASSERT_EQ(b.snapshot()["state"], "OPERATION_ENABLED");
}

}  // namespace remote_drive_testing
