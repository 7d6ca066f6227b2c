// The instrument page for a drive on an EtherCAT line (`cia402 serve --ecat IF --position N`): the
// remote backend (remote_drive.hpp) with the project's EtherCAT master (ethercat/master) as its link
// instead of the CANopen one. The master scans the line, brings it to OP and runs the cyclic LRW in
// the page's cycle thread; the status word, the actual velocity, position, torque, following error
// and mode display come from the process data each cycle, the control word goes out in it; the
// page's object writes go into the outputs when the drive maps the object there (0x60FF, 0x6060,
// 0x607A, ...), else by SDO over the mailbox. A line that stops answering, or a slave that leaves OP
// (its watchdog, an error), shows as "no_answer" with the reason, and the master brings the line up
// again after retry_us.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/page/remote_drive.hpp"
#include "cia402/profile.hpp"

namespace cia402::page {

/// The drive at `position` (0 first) on the line `link` reaches; `interface` is shown on the page.
/// The profile and the link must outlive the backend. Nothing is sent before the first step.
std::unique_ptr<remote_drive> make_ecat_drive(const profile& p, ethercat::master_link& link, std::uint16_t position,
                                              const std::string& interface, const remote_config& config = {});

}  // namespace cia402::page
