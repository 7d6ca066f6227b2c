#include "cli/demo.hpp"


#include <iomanip>
#include <ostream>
#include <string>

#include "cia402/drive.hpp"
#include "cia402/master.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

// A small plant, so that ramps take a few cycles: the motor runs at speed 3 under torque, loses 1
// per cycle on the slow-down ramp and 2 on the faster stops, and the brake follows the drive's
// command one cycle late; an engaged brake holds the shaft.
struct demo_plant {
  int speed = 0;
  bool brake_engaged = true;

  void follow(const drive_outputs& o, const profile& p) {
    if (brake_engaged || !o.torque) {
      speed = 0;
    } else if (o.ramp == stop_ramp::none) {
      if (p.info(o.current).activity == state_activity::run) speed = 3;
    } else {
      speed -= o.ramp == stop_ramp::slow_down ? 1 : 2;
      if (speed < 0) speed = 0;
    }
    brake_engaged = !o.brake_released;
  }
  bool operator==(const demo_plant&) const = default;
};

constexpr int max_steps_per_event = 16;

class demo_run {
 public:
  demo_run(const profile& p, std::ostream& out) : p_(p), axis_(make_axis(p)), out_(out) {
    out_ << "cia402 demo, profile " << p.name << ": " << p.title << "\n"
         << "(plant: the motor runs at speed 3, ramps lose 1 or 2 a cycle, the brake follows one "
            "cycle late)\n\n"
         << "step  cw      state                   statusword  T   torque  brake     ramp"
            "           speed\n";
  }

  void event(const std::string& label) {
    out_ << "-- " << label << " (cw " << hex(inputs_.control_word, 4);
    if (inputs_.fault_code != 0) out_ << ", fault cause " << hex(inputs_.fault_code, 4);
    out_ << ")\n";
    for (int i = 0; i < max_steps_per_event; ++i) {
      const demo_plant before = plant_;
      inputs_.standstill = plant_.speed == 0;
      inputs_.brake_engaged = plant_.brake_engaged;
      const drive_outputs o = step(p_, axis_, inputs_);
      plant_.follow(o, p_);
      print(o);
      if (o.transition == no_transition && !stop_running(axis_) && plant_ == before) break;
    }
  }

  void command_word(command c) {
    std::uint16_t word = 0;
    encode_command(p_, c, 0, word);
    inputs_.control_word = word;
  }
  drive_inputs& inputs() { return inputs_; }

 private:
  void print(const drive_outputs& o) {
    out_ << std::left << std::setw(6) << ++step_ << std::setw(8) << hex(inputs_.control_word, 4)
         << std::setw(24) << state_name(o.current) << std::setw(12) << hex(o.status_word, 4)
         << std::setw(4)
         << (o.transition == no_transition ? std::string("-") : std::to_string(o.transition))
         << std::setw(8) << (o.torque ? "on" : "off") << std::setw(10)
         << (o.brake_released ? "released" : "engaged") << std::setw(15) << stop_ramp_name(o.ramp)
         << plant_.speed << "\n";
  }

  const profile& p_;
  axis axis_;
  drive_inputs inputs_;
  demo_plant plant_;
  std::ostream& out_;
  int step_ = 0;
};

}  // namespace

void run_demo(const profile& p, std::ostream& out) {
  demo_run d(p, out);
  d.event("power-up");
  d.command_word(command::shutdown);
  d.event("shutdown");
  d.command_word(command::switch_on);
  d.event("switch on");
  d.command_word(command::enable_operation);
  d.event("enable operation");
  d.command_word(command::quick_stop);
  d.event("quick stop");
  d.command_word(command::disable_voltage);
  d.event("disable voltage");
  d.command_word(command::shutdown);
  d.event("shutdown");
  d.command_word(command::enable_operation);
  d.event("enable operation (T3, then T4)");
  d.inputs().fault_code = 0x2310;
  d.event("fault: continuous over-current");
  d.inputs().control_word = static_cast<std::uint16_t>(d.inputs().control_word | 0x80u);
  d.event("fault reset while the cause is present: used up, no change");
  d.inputs().fault_code = 0;
  d.inputs().control_word = static_cast<std::uint16_t>(d.inputs().control_word & ~0x80u);
  d.event("cause removed, bit 7 back to 0");
  d.inputs().control_word = static_cast<std::uint16_t>(d.inputs().control_word | 0x80u);
  d.event("fault reset");
}

}  // namespace cia402::cli
