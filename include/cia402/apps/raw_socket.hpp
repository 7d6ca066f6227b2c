// An AF_PACKET socket bound to one interface, as both ends of an EtherCAT line here hold it (the
// slaves' host and our master's link); opened and used by src/apps/raw_ethercat_socket.hpp.
#pragma once

namespace cia402::apps::detail {

struct raw_socket {
  int fd = -1;
  int ifindex = 0;
};

}  // namespace cia402::apps::detail
