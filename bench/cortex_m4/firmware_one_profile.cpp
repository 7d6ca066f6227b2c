// The same firmware with the standard profile alone: what a drive that embeds its own profile pays.
#include "cia402/drive.hpp"

volatile unsigned short control_word_in;
volatile unsigned short status_word_out;

cia402::axis axis_state = cia402::make_axis(cia402::standard_profile());  // in RAM

int main() {
  for (;;) {
    cia402::drive_inputs in;
    in.control_word = control_word_in;
    status_word_out = cia402::step(cia402::standard_profile(), axis_state, in).status_word;
  }
}
