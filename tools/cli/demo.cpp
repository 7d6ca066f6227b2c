#include "cli/demo.hpp"


#include <iomanip>
#include <ostream>
#include <string>

#include "cia402/drive.hpp"
#include "cia402/master.hpp"
#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/words.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

// The simulator's plant, slowed to a pace a person can read: 100 ms cycles, ramps of one to three
// cycles from 300 rpm, the brake one cycle late.
sim::plant_config demo_plant() {
  sim::plant_config c;
  c.cycle_us = 100000;
  c.brake_engage_delay_us = 100000;
  c.brake_release_delay_us = 100000;
  c.coast_deceleration = 1500;
  c.standstill_window_rpm = 1;
  return c;
}

constexpr int max_steps_per_event = 16;

class demo_run {
 public:
  demo_run(const profile& p, std::ostream& out) : p_(p), drive_(p, demo_plant()), out_(out) {
    sim::drive_view v = drive_.view();
    (void)v.write(object_index::profile_acceleration, 0, 3000);
    (void)v.write(object_index::profile_deceleration, 0, 1000);
    (void)v.write(object_index::quick_stop_deceleration, 0, 1500);
    out_ << "cia402 demo, profile " << p.name << ": " << p.title << "\n"
         << "(the simulator's plant, 100 ms a cycle: from 300 rpm the ramps take one to three cycles, "
            "the brake follows one cycle late)\n\n"
         << "step  cw      state                   statusword  T   torque  brake     ramp"
            "           rpm\n";
  }

  void event(const std::string& label) {
    sim::drive_view v = drive_.view();
    out_ << "-- " << label << " (cw " << hex(v.control_word(), 4);
    if (v.fault_cause() != 0) out_ << ", fault cause " << hex(v.fault_cause(), 4);
    out_ << ")\n";
    for (int i = 0; i < max_steps_per_event; ++i) {
      const std::int32_t rpm_before = v.velocity_rpm();
      const bool brake_before = v.brake_engaged();
      const drive_outputs o = drive_.step();
      print(o);
      const bool still = v.velocity_rpm() == rpm_before && v.brake_engaged() == brake_before;
      if (o.transition == no_transition && !stop_running(v.state_of_axis().core) && still) break;
    }
  }

  /// The profile's control word for `c`, then the cycles it brings under `label`.
  void command_word(command c, const std::string& label) {
    std::uint16_t word = 0;
    encode_command(p_, c, 0, word);
    set_word(word);
    event(label);
  }
  /// 0x60FF, then the cycles it brings. Enabling clears the set-points (T4), so a target is given
  /// once the drive runs.
  void set_target_rpm(std::int32_t rpm) {
    (void)drive_.view().write(object_index::target_velocity, 0, rpm);
    event("target velocity " + std::to_string(rpm) + " rpm");
  }
  void set_word(std::uint16_t word) { (void)drive_.view().write(object_index::control_word, 0, word); }
  std::uint16_t word() { return drive_.view().control_word(); }
  sim::drive_view view() { return drive_.view(); }

 private:
  void print(const drive_outputs& o) {
    sim::drive_view v = drive_.view();
    out_ << std::left << std::setw(6) << ++step_ << std::setw(8) << hex(v.control_word(), 4)
         << std::setw(24) << state_name(o.current) << std::setw(12) << hex(o.status_word, 4)
         << std::setw(4)
         << (o.transition == no_transition ? std::string("-") : std::to_string(o.transition))
         << std::setw(8) << (o.torque ? "on" : "off") << std::setw(10)
         << (o.brake_released ? "released" : "engaged") << std::setw(15) << stop_ramp_name(o.ramp)
         << v.velocity_rpm() << "\n";
  }

  const profile& p_;
  sim::virtual_drive drive_;
  std::ostream& out_;
  int step_ = 0;
};

}  // namespace

void run_demo(const profile& p, std::ostream& out) {
  demo_run d(p, out);
  d.event("power-up");
  d.command_word(command::shutdown, "shutdown");
  d.command_word(command::switch_on, "switch on");
  d.command_word(command::enable_operation, "enable operation");
  d.set_target_rpm(300);
  d.command_word(command::quick_stop, "quick stop");
  d.command_word(command::disable_voltage, "disable voltage");
  d.command_word(command::shutdown, "shutdown");
  d.command_word(command::enable_operation, "enable operation (T3, then T4)");
  d.set_target_rpm(300);
  (void)d.view().inject_fault(0x2310);
  d.event("fault: continuous over-current");
  d.set_word(static_cast<std::uint16_t>(d.word() | control_bit::fault_reset));
  d.event("fault reset while the cause is present: used up, no change");
  d.view().clear_faults();
  d.set_word(static_cast<std::uint16_t>(d.word() & ~control_bit::fault_reset));
  d.event("cause removed, bit 7 back to 0");
  d.set_word(static_cast<std::uint16_t>(d.word() | control_bit::fault_reset));
  d.event("fault reset");
}

}  // namespace cia402::cli
