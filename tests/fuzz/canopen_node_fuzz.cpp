// Frame sequences into a CANopen drive node: no crash, no unbounded memory, and the node cannot be
// silenced for good: after NMT reset communication it answers an SDO upload again.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/301/nmt.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/profile.hpp"

using namespace cia402::canopen;
using namespace cia402::dictionary;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  virtual_bus bus;
  cia402::apps::virtual_drive_node node(cia402::standard_profile(), bus.attach(), cia402::apps::drive_node_config(5));
  auto master = bus.attach();
  node.poll(1000);
  // Each frame: 2 bytes id (11 bits), 1 byte length (0..8), the data, 1 byte of time to pass.
  std::size_t i = 0;
  int frames = 0;
  while (i + 4 <= size && frames < 400) {
    frame f;
    f.id = static_cast<std::uint32_t>((data[i] | (data[i + 1] << 8)) & 0x7FF);
    f.len = static_cast<std::uint8_t>(data[i + 2] % 9);
    i += 3;
    for (std::uint8_t k = 0; k < f.len && i < size; ++k) f.data[k] = data[i++];
    const std::uint32_t us = i < size ? 100u * data[i++] : 0u;
    (void)master->send(f);
    node.poll(us);
    frame drop;
    while (master->receive(drop)) {}
    ++frames;
  }
  // Reset communication (COB-IDs back to their defaults), start, and ask for 0x1000.
  (void)master->send(nmt_frame(nmt_command::reset_communication, 5));
  for (int k = 0; k < 5; ++k) node.poll(1000);
  frame drop;
  while (master->receive(drop)) {}
  frame upload;
  upload.id = 0x605;
  upload.len = 8;
  upload.data = {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0};
  (void)master->send(upload);
  node.poll(1000);
  bool answered = false;
  frame r;
  while (master->receive(r)) answered = answered || r.id == 0x585;
  if (!answered) std::abort();
  return 0;
}
