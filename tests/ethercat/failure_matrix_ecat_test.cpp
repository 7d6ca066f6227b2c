// Issue 42 / S20 over the real EtherCAT link: tests/axis/failure_matrix_test.cpp's matrix (every
// motion command against every failure injected at a grid of moments of its way), but through
// ethercat::ecat_link on an ecat_line to the virtual drive as a CoE slave on the in-process wire, as
// `cia402 master --ecat` builds them (tests/ethercat/ecat_runs_chain_test.cpp), in virtual time.
// Whatever happens, the request ends within a bound, its error names the cause, the shaft ends at
// standstill wherever the wire still reaches the drive (read from the virtual drive itself), and a
// drive that did not fault takes the next command without a reset.
//
// The slave is apps::virtual_drive_slave's composition (a drive402::sim_device behind a
// ethercat::coe_slave with apps::drive_slave_config), with two things a test needs between them:
// the wire can be cut (no frame passes any more; the drive's time goes on, its sync manager watchdog
// too), and the device can refuse writes of chosen objects (a drive that answers a CoE SDO download
// with an abort). The failures are injected beside the session, never through it: 0x2001 written
// into the device, STO and the DC link set on the virtual drive.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/axis/session.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/ethercat/axis/ecat_link.hpp"
#include "cia402/ethercat/slave/coe_slave.hpp"
#include "cia402/objects.hpp"
#include "failure_matrix.hpp"
#include "refusing_device.hpp"

namespace cia402::ethercat {
namespace {

// The in-process wire with the one slave; cut, no frame comes back.
class wire final : public master_link {
 public:
  wire() { line.add(slave.controller()); }
  bool exchange(std::vector<std::uint8_t>& frame) override {
    if (cut) return false;
    return line.pass(frame) == frame_error::none;
  }
  std::uint64_t now_us() override { return now; }
  void wait_us(std::uint32_t us) override {
    now += us;
    slave.step(us);
  }
  drive402::sim_device drive_device{standard_profile()};
  failure_matrix::refusing_device dev{drive_device};
  coe_slave slave{dev, apps::drive_slave_config(1, 1000)};
  chain line;
  std::uint64_t now = 0;
  bool cut = false;
};

// The drive on the wire, a line brought to OP, a link and a session on slave 0, run in steps of 1 ms.
struct bench : failure_matrix::ms_clock<bench> {
  wire w;
  ecat_line line{w, standard_profile(), 1000, "test-line"};
  std::unique_ptr<ecat_link> link;
  std::optional<axes::session> s;

  bench() {
    EXPECT_TRUE(line.scan()) << line.error();
    EXPECT_TRUE(line.bring_to_operational()) << line.error();
    link = std::make_unique<ecat_link>(line, 0);
    axes::session_config sc;
    sc.drive_profile = &standard_profile();
    s.emplace(*link, sc);
  }

  sim::drive_view view() { return w.drive_device.drive().view(); }
  void tick() {
    (void)s->poll(1000);
    w.wait_us(1000);
  }
  void clear_refusals() { w.dev.refused.clear(); }
};

using namespace failure_matrix;

void inject(bench& b, failure f) {
  switch (f) {
    case failure::cancel: b.s->cancel("the client gave up"); break;
    case failure::link_lost: b.w.cut = true; break;
    case failure::fault: ASSERT_EQ(b.w.drive_device.write(0x2001, 0, 0x7121), sdo_abort::none); break;
    case failure::sto: b.view().set_sto(true); break;
    case failure::dc_link_lost: b.view().set_dc_link(false); break;
    case failure::refused_sdo:
      // Every object the command writes by CoE SDO from now on is refused, as a drive that changed
      // its mind. The RxPDO carries 0x6040, 0x6060, 0x607A, 0x60FF and 0x6071: those are no SDO
      // and stay taken, so velocity, jog, csp and torque have nothing left to refuse.
      b.w.dev.refused = {object_index::profile_velocity, object_index::homing_method, object_index::home_offset};
      break;
  }
}

// The drive's sync manager watchdog sees the frames gone and it stops as 0x6007 says.
const bus_traits ecat_bus{"the line does not answer", 2000, 200, true};

void run_one(kind k, failure f, int at_ms) {
  SCOPED_TRACE(where(k, f, at_ms));
  bench b;
  check_run(b, k, f, at_ms, ecat_bus, inject);
}

// The moments: every 10 ms of the first 60 ms, where the session reads the option codes and limits
// by CoE and enables the drive (the line is in OP before the session starts); then every 50 ms to
// 400 ms, where the command runs.
TEST(failure_matrix_ecat, every_motion_command_every_failure_at_every_moment_of_its_first_400_ms) {
  for_every_case(moments(60, 100), run_one);
}

// A gap the matrix found (issue 42): a wire cut while a CoE SDO waits to hand its request to the
// slave's mailbox was said as the drive refusing the object ("the drive refused 0x6098:0 = 17: ...:
// its receive mailbox stays full"). ecat_master::mailbox_send now tells a full mailbox (working
// counter 0) from a line that brings no frame back, and the session says "refused" only for an abort.
TEST(failure_matrix_ecat, a_wire_cut_during_a_coe_sdo_names_the_line_not_a_refusal) {
  bench b;
  std::optional<axes::result> got;
  b.s->home({std::int8_t{17}, 0}, [&](const axes::result& r) { got = r; });
  b.run_ms(20);
  ASSERT_FALSE(got.has_value());
  b.w.cut = true;
  ASSERT_TRUE(b.run_until([&] { return got.has_value(); }, 10'000));
  EXPECT_EQ(got->error.find("the drive refused"), std::string::npos) << got->error;
  EXPECT_NE(got->error.find("does not answer"), std::string::npos) << got->error;
}

}  // namespace
}  // namespace cia402::ethercat
