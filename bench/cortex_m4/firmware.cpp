// A minimal Cortex-M4 firmware that steps one axis of every built-in profile: what the drive-side
// machine with all built-in profiles costs in flash and RAM. size.sh links it next to empty.cpp
// and reports the difference.
#include "io.hpp"

volatile firmware::input_registers firmware::inputs;
volatile firmware::output_registers firmware::outputs;

cia402::axis axes[5];  // in RAM, so size.sh counts it

int main() {
  const std::size_t n = cia402::builtin_profile_count();
  for (std::size_t i = 0; i < n && i < 5; ++i) axes[i] = cia402::make_axis(cia402::builtin_profile(i));
  for (;;) {
    for (std::size_t i = 0; i < n && i < 5; ++i) {
      firmware::write_outputs(cia402::step(cia402::builtin_profile(i), axes[i], firmware::read_inputs()));
    }
  }
}
