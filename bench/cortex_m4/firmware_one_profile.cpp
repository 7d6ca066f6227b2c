// The same firmware with the standard profile alone: what a drive that embeds its own profile pays.
#include "io.hpp"

volatile firmware::input_registers firmware::inputs;
volatile firmware::output_registers firmware::outputs;

cia402::axis axis_state = cia402::make_axis(cia402::standard_profile());  // in RAM

int main() {
  for (;;) firmware::write_outputs(cia402::step(cia402::standard_profile(), axis_state, firmware::read_inputs()));
}
