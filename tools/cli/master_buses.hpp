// The buses `cia402 master` runs its sessions on, each behind one interface: the drives to run (a
// link each), the wait for the next thing to do, and what only one bus has (NMT on CANopen, the
// line's own lines on EtherCAT). CANopen: a socketcand or SocketCAN channel in real time, or the
// virtual bus with one virtual drive in virtual time (no waiting). EtherCAT: a raw socket on an
// interface and our master, brought to OP before the first step.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cia402/axis/drive_link.hpp"
#include "cia402/profile.hpp"
#include "cli/master.hpp"
#include "cli/master_output.hpp"
#include "cli/master_steps.hpp"

namespace cia402::cli {

class master_bus {
 public:
  struct drive {
    axes::drive_link* link = nullptr;
    drive_tag tag;
  };
  virtual ~master_bus() = default;
  virtual std::vector<drive>& drives() = 0;
  /// Waits for the next thing to do (at most `next_us`) and returns the microseconds that passed.
  virtual std::uint32_t wait(std::uint32_t next_us) = 0;
  /// Lets an in-process drive answer at once (no time passes).
  virtual void settle() {}
  /// How a csp stream goes on this bus, for its line ("by RPDO3, SYNC every 1000 us").
  virtual std::string stream_words(std::uint32_t cycle_us) const = 0;
  /// NMT to the drive: CANopen only; otherwise why not.
  virtual std::optional<std::string> nmt(const drive& d, const std::string& command) = 0;
  /// The run is over: the bus's own last line (EtherCAT: cycles and frames lost).
  virtual void finish(master_output&) {}
};

/// The bus the options name, with its links; nothing (with the exit status in `status`: 1 a bus
/// that cannot be reached, 2 a refused option) when it cannot be opened.
std::unique_ptr<master_bus> open_can_bus(const master_args& a, const profile& p, const std::vector<master_step>& steps,
                                         master_output& out, int& status);
std::unique_ptr<master_bus> open_ecat_bus(const master_args& a, const profile& p, master_output& out, int& status);

}  // namespace cia402::cli
