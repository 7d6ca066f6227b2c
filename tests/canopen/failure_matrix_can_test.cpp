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
#include "refusing_device.hpp"

namespace cia402::canopen {
namespace {

using namespace cia402::dictionary;

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
struct bench : failure_matrix::ms_clock<bench> {
  virtual_bus bus;
  drive402::sim_device drive_device{standard_profile()};
  failure_matrix::refusing_device dev{drive_device};
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
  void clear_refusals() { dev.refused.clear(); }
};

using namespace failure_matrix;

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

// The drive watches the master's heartbeat and stops as 0x6007 says when the node is cut off.
const bus_traits can_bus{"node 1 does not answer", 2000, 200, true};

void run_one(kind k, failure f, int at_ms) {
  SCOPED_TRACE(where(k, f, at_ms));
  bench b(k == kind::csp);
  check_run(b, k, f, at_ms, can_bus, inject);
}

// The moments: every 10 ms of the first 150 ms, where the link reads the drive, sets up its PDOs and
// starts the node, the session reads the option codes and limits and enables the drive (by SDO, at
// one SYNC every 10 ms); then every 50 ms to 400 ms, where the command runs.
TEST(failure_matrix_can, every_motion_command_every_failure_at_every_moment_of_its_first_400_ms) {
  for_every_case(moments(150, 200), run_one);
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
