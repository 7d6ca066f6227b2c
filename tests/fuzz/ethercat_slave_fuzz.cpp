// EtherCAT frames and CoE mailboxes into a virtual drive slave (ethercat/402) on the in-process
// wire. The input is a sequence of chunks, each a length byte, a kind byte and that many bytes: a
// raw frame, or a mailbox the fuzzer's bytes fill (written into SM0 with a sound frame, so the CoE
// server sees them). Promise: no crash, no sanitizer report, bounded memory; a frame the wire
// refuses comes back untouched; and after any input, a sound SDO upload of 0x1018 sub 2 through the
// mailbox still answers 0x402: no input silences the slave's mailbox for good.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "cia402/ethercat/402/drive_description.hpp"
#include "cia402/ethercat/402/drive_slave.hpp"

namespace {

using namespace cia402::ethercat;

constexpr std::array<std::uint8_t, 6> broadcast{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
constexpr std::array<std::uint8_t, 6> master_mac{2, 0, 0, 0, 0, 1};

std::vector<std::uint8_t> one(command c, std::uint32_t address, const std::vector<std::uint8_t>& data, long& at) {
  frame_builder b(broadcast, master_mac);
  at = b.add(c, 0, address, data, static_cast<std::uint16_t>(data.size()));
  return b.finish();
}

void put_mailbox(chain& wire, drive_slave& s, std::vector<std::uint8_t> m) {
  m.resize(mailbox_size, 0);
  long at = 0;
  std::vector<std::uint8_t> f = one(command::apwr, static_cast<std::uint32_t>(mailbox_out_start) << 16, m, at);
  wire.pass(f);
  s.step(1000);
}

std::vector<std::uint8_t> take_mailbox(chain& wire, drive_slave& s) {
  s.step(1000);
  long at = 0;
  std::vector<std::uint8_t> f =
      one(command::aprd, static_cast<std::uint32_t>(mailbox_in_start) << 16, std::vector<std::uint8_t>(mailbox_size, 0), at);
  wire.pass(f);
  const std::size_t wkc = static_cast<std::size_t>(at) + mailbox_size;
  if ((f[wkc] | (f[wkc + 1] << 8)) == 0) return {};
  return std::vector<std::uint8_t>(f.begin() + at, f.begin() + at + mailbox_size);
}

void to_pre_op(chain& wire, drive_slave& s) {
  long at = 0;
  for (int n = 0; n < 2; ++n) {
    const sync_manager_description& d = s.description().sync_managers[static_cast<std::size_t>(n)];
    std::vector<std::uint8_t> sm{static_cast<std::uint8_t>(d.start), static_cast<std::uint8_t>(d.start >> 8),
                                 static_cast<std::uint8_t>(d.length), static_cast<std::uint8_t>(d.length >> 8),
                                 d.control, 0, 1, 0};
    std::vector<std::uint8_t> f = one(command::apwr, static_cast<std::uint32_t>(reg::sync_manager0 + 8 * n) << 16, sm, at);
    wire.pass(f);
  }
  std::vector<std::uint8_t> f = one(command::apwr, static_cast<std::uint32_t>(reg::al_control) << 16, {0x12, 0}, at);
  wire.pass(f);
  s.step(1000);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  drive_slave slave(cia402::standard_profile(), 1);
  chain wire;
  wire.add(slave.controller());
  to_pre_op(wire, slave);
  std::size_t at = 0;
  while (at + 2 <= size) {
    const std::size_t n = std::min<std::size_t>(data[at], size - at - 2);
    const std::uint8_t kind = data[at + 1];
    std::vector<std::uint8_t> bytes(data + at + 2, data + at + 2 + n);
    at += 2 + n;
    if (kind & 1u) {
      put_mailbox(wire, slave, bytes);
      (void)take_mailbox(wire, slave);
    } else {
      const std::vector<std::uint8_t> before = bytes;
      if (wire.pass(bytes) != frame_error::none && bytes != before) std::abort();
      slave.step(kind);  // time passes: up to 255 us
    }
  }
  // Whatever came before: back to PRE-OP with sound sync managers, and the mailbox answers.
  to_pre_op(wire, slave);
  while (!take_mailbox(wire, slave).empty()) {
  }
  std::vector<std::uint8_t> m(mailbox_size, 0);
  m[0] = 10;      // length: CoE header + 8 bytes of SDO
  m[5] = 0x13;    // CoE, counter 1
  m[7] = 0x20;    // SDO request
  m[8] = 0x40;    // upload
  m[9] = 0x18;
  m[10] = 0x10;
  m[11] = 2;
  put_mailbox(wire, slave, m);
  for (int tries = 0; tries < 40; ++tries) {
    const std::vector<std::uint8_t> r = take_mailbox(wire, slave);
    if (r.size() > 15 && (r[5] & 0x0F) == 3 && (r[7] >> 4) == 3 && r[8] == 0x43 && r[12] == 0x02 && r[13] == 0x04) {
      return 0;
    }
  }
  std::abort();  // the mailbox was silenced
}
