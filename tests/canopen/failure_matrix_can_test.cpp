// Issue 42 / S20 over the real CAN link: tests/axis/failure_matrix_test.cpp's matrix (every motion
// command against every failure injected at a grid of moments of its way), but through
// canopen::can_link to the virtual drive as a CiA 301 node on the in-process virtual bus, in virtual
// time. Whatever happens, the request ends within a bound, its error names the cause, the shaft ends
// at standstill wherever the bus still reaches the drive (read from the virtual drive itself), and
// a drive that did not fault takes the next command without a reset.
//
// The node is apps::virtual_drive_node's composition (a drive402::sim_device behind a
// canopen::slave with apps::drive_node_config), with two things a test needs between them: the
// node's channel can be cut (the node goes silent both ways: no heartbeat, no PDO, no SDO answer),
// and the device can refuse writes of chosen objects (a drive that answers an SDO download with an
// abort). The failures are injected beside the session, never through it: 0x2001 written into the
// device, STO and the DC link set on the virtual drive.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/axis/session.hpp"
#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/objects.hpp"
#include "failure_matrix.hpp"

namespace cia402::canopen {
namespace {

using namespace cia402::dictionary;

// A device in front of the virtual drive's that refuses writes of the objects in `refused` with
// 0x06090030 (invalid value for parameter); everything else, the drive's reports too, passes through.
class refusing_device final : public dictionary::device {
 public:
  explicit refusing_device(drive402::sim_device& inner) : inner_(&inner), relay_{this} { inner.attach(&relay_); }
  ~refusing_device() override { inner_->attach(nullptr); }

  sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& value) noexcept override {
    return inner_->read(index, sub, value);
  }
  sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t value) noexcept override {
    if (refused.count(index) != 0) return sdo_abort::invalid_value;
    return inner_->write(index, sub, value);
  }
  std::uint32_t step(std::uint32_t elapsed_us) noexcept override { return inner_->step(elapsed_us); }
  void set_connection_lost(bool lost) noexcept override { inner_->set_connection_lost(lost); }
  void reset() noexcept override { inner_->reset(); }
  std::array<std::uint8_t, 5> manufacturer_error_field() const noexcept override {
    return inner_->manufacturer_error_field();
  }

  std::set<std::uint16_t> refused;

 private:
  struct relay final : device_events {
    explicit relay(refusing_device* d) : owner(d) {}
    void object_changed(std::uint16_t index, std::uint8_t sub) noexcept override { owner->changed(index, sub); }
    void error_changed(std::uint16_t code) noexcept override { owner->device::error_changed(code); }
    refusing_device* owner;
  };
  drive402::sim_device* inner_;
  relay relay_;
};

// The node's attachment to the bus; cut, it neither hears nor says anything.
class gated_channel final : public channel {
 public:
  explicit gated_channel(std::unique_ptr<virtual_channel> inner) : inner_(std::move(inner)) {}
  std::error_code send(const frame& f) noexcept override { return cut ? std::error_code{} : inner_->send(f); }
  bool receive(frame& f) noexcept override {
    if (!cut) return inner_->receive(f);
    while (inner_->receive(f)) {}
    return false;
  }
  bool cut = false;

 private:
  std::unique_ptr<virtual_channel> inner_;
};

constexpr std::uint8_t node_id = 1;

// One drive on the virtual bus and a session over a can_link to it, run in steps of 1 ms.
struct bench {
  virtual_bus bus;
  drive402::sim_device drive_device{standard_profile()};
  refusing_device dev{drive_device};
  gated_channel node_ch{bus.attach()};
  std::unique_ptr<slave> node;
  std::unique_ptr<virtual_channel> master_ch = bus.attach();
  std::unique_ptr<can_link> link;
  std::optional<axes::session> s;
  bool streaming;  // the link maps 0x607A into RPDO3 (a csp stream)
  /// Master heartbeats (0x700 + 127) the bus carried: the node's guard (0x1016) starts watching
  /// with the first one after the link wrote it (CiA 301), not before.
  int master_heartbeats = 0;

  explicit bench(bool streaming_) : streaming(streaming_) {
    node = std::make_unique<slave>(dev, node_ch, apps::drive_node_config(node_id));
    for (int i = 0; i < 10; ++i) node->poll(node_ch, 1000);  // past power-up (T0, T1)
    frame f;
    while (master_ch->receive(f)) {}  // the boot-up message
    can_link_config c;
    c.node_id = node_id;
    c.bus_name = "virtual (test)";
    c.drive_profile = &standard_profile();
    c.map_position = streaming;
    c.master_heartbeat_ms = 100;  // the drive watches the master: a silent bus acts through its 0x6007
    c.known_objects = node_objects(apps::drive_node_config(node_id));
    link = std::make_unique<can_link>(*master_ch, c);
    bus.observe([this](const frame& f) {
      if (!f.extended && f.id == 0x700 + drive_master_config{}.master_node_id) ++master_heartbeats;
    });
    axes::session_config sc;
    sc.drive_profile = &standard_profile();
    s.emplace(*link, sc);
  }

  sim::drive_view view() { return drive_device.drive().view(); }
  void tick() {
    (void)s->poll(1000);
    (void)node->poll(node_ch, 1000);
  }
  bool run_until(const std::function<bool()>& done, int ms) {
    for (int i = 0; i < ms; ++i) {
      tick();
      if (done()) return true;
    }
    return false;
  }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) tick();
  }
  axes::result finish(const std::function<void(axes::completion)>& request, int ms = 20000) {
    std::optional<axes::result> got;
    request([&got](const axes::result& r) { got = r; });
    if (!run_until([&] { return got.has_value(); }, ms)) {
      axes::result r;
      r.end = axes::outcome::failed;
      r.error = "no end within the test's time";
      return r;
    }
    return *got;
  }
};

using namespace failure_matrix;

// How this bus says a lost link.
const std::string link_lost_words = "node 1 does not answer";

// The command of kind `k` on this bench's session.
void start(bench& b, kind k, axes::completion done) { failure_matrix::start(*b.s, k, std::move(done)); }

void inject(bench& b, failure f) {
  switch (f) {
    case failure::cancel: b.s->cancel("the client gave up"); break;
    case failure::link_lost: b.node_ch.cut = true; break;
    case failure::fault: ASSERT_EQ(b.drive_device.write(0x2001, 0, 0x7121), sdo_abort::none); break;
    case failure::sto: b.view().set_sto(true); break;
    case failure::dc_link_lost: b.view().set_dc_link(false); break;
    case failure::refused_sdo:
      // Every object the command writes by SDO from now on is refused, as a drive that changed its
      // mind. RPDO3's 0x607A (a csp stream's set-point) is not an SDO and stays taken.
      b.dev.refused = {object_index::target_velocity, object_index::target_torque, object_index::profile_velocity,
                       object_index::homing_method,   object_index::home_offset,   object_index::modes_of_operation};
      if (!b.streaming) b.dev.refused.insert(object_index::target_position);
      break;
  }
}

// One run: the command, the failure after `at_ms`, then the checks.
void run_one(kind k, failure f, int at_ms) {
  SCOPED_TRACE(std::string(name(k)) + ", " + name(f) + " at " + std::to_string(at_ms) + " ms");
  bench b(k == kind::csp);
  std::optional<axes::result> got;
  start(b, k, [&](const axes::result& res) { got = res; });
  b.run_ms(at_ms);
  const bool ended_before = got.has_value();
  const bool enabled = b.view().current() == state::operation_enabled;
  inject(b, f);
  // The bound: the failure stop's three stages, and the time to say it.
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 3 * 10'000 + 2000)) << "the request never ended";
  if (ended_before || got->ok()) return;  // the failure came after the end, or changed nothing the command needed
  EXPECT_TRUE(names_one(got->error, cause_words(f, link_lost_words))) << got->error;
  if (f == failure::link_lost) {
    if (enabled) EXPECT_NE(got->error.find("0x6007"), std::string::npos) << got->error;
    // Out of the session's hands: the drive watches the master's heartbeat and stops as 0x6007 says.
    if (enabled) {
      EXPECT_TRUE(b.run_until([&] { return std::abs(b.view().velocity_rpm()) <= 1; }, 30'000))
          << got->error << " (" << b.view().velocity_rpm() << " rpm)";
    }
    return;
  }
  // At standstill: at once where the session stopped it; after the drive's own fault reaction (or a
  // coast under STO) where the drive took over.
  const bool stands = b.run_until([&] { return std::abs(b.view().velocity_rpm()) <= 1; },
                                  f == failure::cancel || f == failure::refused_sdo ? 200 : 30'000);
  EXPECT_TRUE(stands) << got->error << " (" << b.view().velocity_rpm() << " rpm)";
  if (f == failure::cancel || f == failure::refused_sdo) {
    EXPECT_NE(b.view().current(), state::fault) << got->error;
    b.dev.refused.clear();
    // The next command runs without a reset.
    const axes::result next = b.finish([&](axes::completion d) { b.s->velocity(100, std::move(d)); });
    EXPECT_TRUE(next.ok()) << next.error;
  }
}

// The moments: every 10 ms of the first 150 ms, where the link reads the drive, sets up its PDOs and
// starts the node, the session reads the option codes and limits and enables the drive (by SDO, at
// one SYNC every 10 ms); then every 50 ms to 400 ms, where the command runs.
std::vector<int> moments() {
  std::vector<int> at;
  for (int ms = 0; ms <= 150; ms += 10) at.push_back(ms);
  for (int ms = 200; ms <= 400; ms += 50) at.push_back(ms);
  return at;
}

TEST(failure_matrix_can, every_motion_command_every_failure_at_every_moment_of_its_first_400_ms) {
  for (const kind k : kinds) {
    for (const failure f : failures) {
      for (const int at : moments()) run_one(k, f, at);
    }
  }
}

// A gap the matrix found (issue 42): the link writes the drive's guard (0x1016 on the master's
// heartbeat) at set-up, and CiA 301 arms a consumer with the first heartbeat it hears; the master's
// first heartbeat went a full period after it was made, so a drive enabled and turning before that
// never saw a bus that fell silent. The master now sends one as the cyclic stage starts, before any
// control word.
TEST(failure_matrix_can, a_drive_enabled_right_after_set_up_stops_when_the_bus_goes_silent) {
  bench b(false);
  std::optional<axes::result> got;
  b.s->velocity(3000, [&](const axes::result& r) { got = r; });
  ASSERT_TRUE(b.run_until([&] { return b.view().velocity_rpm() > 0; }, 1000));
  EXPECT_GT(b.master_heartbeats, 0) << "the guard is armed before the drive turns";
  b.node_ch.cut = true;
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 2000));
  EXPECT_NE(got->error.find("the drive stops as its 0x6007 says"), std::string::npos) << got->error;
  EXPECT_TRUE(b.run_until([&] { return std::abs(b.view().velocity_rpm()) <= 1; }, 30'000))
      << "the drive never saw the loss: " << b.view().velocity_rpm() << " rpm in "
      << (b.view().current() == state::operation_enabled ? "OPERATION ENABLED" : "another state");
}

}  // namespace
}  // namespace cia402::canopen
