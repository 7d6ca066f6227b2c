// The drive's hardware as the firmwares see it: every input of a step read from a register, every
// output written to one. Reading all of them matters: a firmware that fed only the control word
// would let the compiler (with -flto) fold the fault, STO and DC-link paths away, and the figure
// would be of a drive that cannot fault.
#pragma once

#include "cia402/drive.hpp"

namespace firmware {

struct input_registers {
  unsigned short control_word;
  unsigned short fault_code;
  unsigned short status_bits;
  unsigned char dc_link, sto, remote, connection_lost, local_enable, local_disable;
  unsigned char fault_class, standstill, brake_engaged;
  int actual_speed_rpm;
};

struct output_registers {
  unsigned short status_word;
  unsigned short error_code;
  unsigned char state, transition, ramp, torque, brake_released, clear_setpoints;
};

extern volatile input_registers inputs;
extern volatile output_registers outputs;

inline cia402::drive_inputs read_inputs() {
  cia402::drive_inputs in;
  in.control_word = inputs.control_word;
  in.fault_code = inputs.fault_code;
  in.status_bits = inputs.status_bits;
  in.dc_link = inputs.dc_link != 0;
  in.sto = inputs.sto != 0;
  in.remote = inputs.remote != 0;
  in.connection_lost = inputs.connection_lost != 0;
  in.local_enable = inputs.local_enable != 0;
  in.local_disable = inputs.local_disable != 0;
  in.fault_class = inputs.fault_class;
  in.standstill = inputs.standstill != 0;
  in.brake_engaged = inputs.brake_engaged != 0;
  in.actual_speed_rpm = inputs.actual_speed_rpm;
  return in;
}

inline void write_outputs(const cia402::drive_outputs& out) {
  outputs.status_word = out.status_word;
  outputs.error_code = out.error_code;
  outputs.state = static_cast<unsigned char>(out.current);
  outputs.transition = out.transition;
  outputs.ramp = static_cast<unsigned char>(out.ramp);
  outputs.torque = out.torque;
  outputs.brake_released = out.brake_released;
  outputs.clear_setpoints = out.clear_setpoints;
}

}  // namespace firmware
