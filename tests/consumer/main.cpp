// Power up a drive with the standard profile and enable it, as a master would.
#include <cstdio>

#include "cia402/drive.hpp"

int main() {
  cia402::drive drive(cia402::standard_profile());
  cia402::drive_inputs in;  // defaults: an ideal plant (DC link on, no STO, at standstill)

  cia402::drive_outputs out = drive.step(in);  // T0: NOT READY TO SWITCH ON
  out = drive.step(in);                        // T1: SWITCH ON DISABLED
  in.control_word = 0x0006;                    // Shutdown
  out = drive.step(in);                        // T2: READY TO SWITCH ON
  in.control_word = 0x000F;                    // Enable operation
  out = drive.step(in);                        // T3: SWITCHED ON
  out = drive.step(in);                        // T4: OPERATION ENABLED, torque on

  std::printf("%s 0x%04X\n", cia402::state_name(out.current), out.status_word);
  return out.current == cia402::state::operation_enabled && out.status_word == 0x0237 ? 0 : 1;
}
