// The same firmware without the state machine: its registers, read and written, and nothing
// between them. The baseline size.sh subtracts, so the figures are the core's alone.
#include "io.hpp"

volatile firmware::input_registers firmware::inputs;
volatile firmware::output_registers firmware::outputs;

int main() {
  for (;;) {
    const cia402::drive_inputs in = firmware::read_inputs();
    cia402::drive_outputs out;
    out.status_word = in.control_word ^ in.status_bits;
    out.error_code = in.fault_code;
    out.torque = in.dc_link && !in.sto && in.remote && !in.connection_lost && !in.local_disable;
    out.brake_released = in.local_enable && in.standstill && in.brake_engaged;
    out.transition = static_cast<std::uint8_t>(in.fault_class + in.actual_speed_rpm);
    firmware::write_outputs(out);
  }
}
