// EtherCAT frames, CoE mailboxes, sync manager settings, mapping objects and state requests into a
// virtual drive slave (apps/virtual_drive_slave.hpp: the CoE slave of ethercat/slave around the drive)
// on the in-process wire. The input is a sequence of chunks, each
// a length byte, a kind byte and that many bytes: a raw frame; a mailbox the fuzzer's bytes fill
// (written into SM0 with a sound frame, so the CoE server sees them); a sync manager's 8 bytes; an
// SDO download of any value into a PDO mapping or assignment object; a sound bring-up to INIT,
// PRE-OP, SAFE-OP or OP (so every change is also tried in every AL state); a raw AL control word;
// a process data cycle with the fuzzer's outputs; time passing.
// Promise: no crash, no sanitizer report, bounded memory; a frame the wire refuses comes back
// untouched; the application never writes outside what a PDI may (its registers stay the
// controller's); and after any input, a sound SDO upload of 0x1018 sub 2 through the mailbox still
// answers 0x402: no input silences the slave's mailbox for good.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "../ethercat/register_bytes.hpp"
#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/coe/mailbox.hpp"

namespace {

using namespace cia402::ethercat;
using drive_slave = cia402::apps::virtual_drive_slave;

constexpr std::array<std::uint8_t, 6> broadcast{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
constexpr std::array<std::uint8_t, 6> master_mac{2, 0, 0, 0, 0, 1};
constexpr std::uint32_t outputs_logical = 0x10000;
constexpr std::uint32_t inputs_logical = 0x10100;

std::vector<std::uint8_t> one(command c, std::uint32_t address, const std::vector<std::uint8_t>& data, long& at) {
  frame_builder b(broadcast, master_mac);
  at = b.add(c, 0, address, data, static_cast<std::uint16_t>(data.size()));
  return b.finish();
}
std::uint32_t ap(std::uint16_t offset) { return static_cast<std::uint32_t>(offset) << 16; }

void send(chain& wire, command c, std::uint32_t address, const std::vector<std::uint8_t>& data) {
  long at = 0;
  std::vector<std::uint8_t> f = one(c, address, data, at);
  wire.pass(f);
}

void put_mailbox(chain& wire, drive_slave& s, std::vector<std::uint8_t> m) {
  m.resize(mailbox_size, 0);
  send(wire, command::apwr, ap(mailbox_out_start), m);
  s.step(1000);
}

std::vector<std::uint8_t> take_mailbox(chain& wire, drive_slave& s) {
  s.step(1000);
  long at = 0;
  std::vector<std::uint8_t> f = one(command::aprd, ap(mailbox_in_start), std::vector<std::uint8_t>(mailbox_size, 0), at);
  wire.pass(f);
  const std::size_t wkc = static_cast<std::size_t>(at) + mailbox_size;
  if ((f[wkc] | (f[wkc + 1] << 8)) == 0) return {};
  return std::vector<std::uint8_t>(f.begin() + at, f.begin() + at + mailbox_size);
}

void request(chain& wire, drive_slave& s, std::uint8_t state) {
  send(wire, command::apwr, ap(reg::al_control), {state, 0});
  s.step(1000);
}

// A master doing it right: INIT with the error acknowledged, every FMMU and sync manager cleared (as
// a master starting afresh does: whatever was left there), then the sync managers and FMMUs as the
// slave describes them, each state in turn up to `target`.
void bring_up(chain& wire, drive_slave& s, std::uint8_t target) {
  request(wire, s, 0x11);
  send(wire, command::apwr, ap(reg::fmmu0), std::vector<std::uint8_t>(16 * esc::fmmu_count, 0));
  send(wire, command::apwr, ap(reg::sync_manager0), std::vector<std::uint8_t>(8 * esc::sync_manager_count, 0));
  s.step(1000);
  if (target < 2) return;
  const slave_description& d = s.description();
  for (int n = 0; n < 2; ++n) {
    send(wire, command::apwr, ap(reg::sync_manager0 + 8 * n),
         register_bytes::sync_manager(d.sync_managers[static_cast<std::size_t>(n)]));
  }
  request(wire, s, 0x12);
  if (target < 4) return;
  const auto out = static_cast<std::uint16_t>(s.output_bytes());
  const auto in = static_cast<std::uint16_t>(s.input_bytes());
  const sync_manager_description& sm2 = d.sync_managers[2];
  const sync_manager_description& sm3 = d.sync_managers[3];
  send(wire, command::apwr, ap(reg::sync_manager0 + 16), register_bytes::sync_manager(sm2.start, out, sm2.control));
  send(wire, command::apwr, ap(reg::sync_manager0 + 24), register_bytes::sync_manager(sm3.start, in, sm3.control));
  const auto fmmu = [&](int i, std::uint32_t log, std::uint16_t len, std::uint16_t phys, std::uint8_t type) {
    send(wire, command::apwr, ap(static_cast<std::uint16_t>(reg::fmmu0 + 16 * i)), register_bytes::fmmu(log, len, phys, type));
  };
  fmmu(0, outputs_logical, out, sm2.start, 2);
  fmmu(1, inputs_logical, in, sm3.start, 1);
  request(wire, s, 0x14);
  if (target >= 8) request(wire, s, 0x18);
}

// An SDO download of 4 bytes into a mapping (0x1600.., 0x1A00..) or assignment (0x1C12/0x1C13) object.
std::vector<std::uint8_t> mapping_write(const std::vector<std::uint8_t>& b) {
  static constexpr std::uint16_t objects[] = {0x1600, 0x1601, 0x1602, 0x1603, 0x1A00, 0x1A01, 0x1A02, 0x1A03, 0x1C12, 0x1C13};
  const std::uint16_t index = objects[(b.empty() ? 0 : b[0]) % std::size(objects)];
  const std::uint8_t sub = b.size() > 1 ? b[1] % 10 : 0;
  std::vector<std::uint8_t> m(mailbox_size, 0);
  m[0] = 10;
  m[5] = 0x13;
  m[7] = 0x20;
  m[8] = 0x23;
  m[9] = static_cast<std::uint8_t>(index);
  m[10] = static_cast<std::uint8_t>(index >> 8);
  m[11] = sub;
  for (std::size_t k = 0; k < 4; ++k) m[12 + k] = b.size() > 2 + k ? b[2 + k] : 0;
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  drive_slave slave(cia402::standard_profile(), 1);
  chain wire;
  wire.add(slave.controller());
  bring_up(wire, slave, 2);
  std::size_t at = 0;
  while (at + 2 <= size) {
    const std::size_t n = std::min<std::size_t>(data[at], size - at - 2);
    const std::uint8_t kind = data[at + 1];
    std::vector<std::uint8_t> bytes(data + at + 2, data + at + 2 + n);
    at += 2 + n;
    switch (kind % 8) {
      case 0: {
        const std::vector<std::uint8_t> before = bytes;
        if (wire.pass(bytes) != frame_error::none && bytes != before) std::abort();
        slave.step(kind);  // time passes: up to 255 us
        break;
      }
      case 1:
        put_mailbox(wire, slave, bytes);
        (void)take_mailbox(wire, slave);
        break;
      case 2: {  // one sync manager's settings, sent as a master would (whatever they say)
        const std::uint8_t sm = bytes.empty() ? 0 : bytes[0] % 8;
        if (bytes.size() > 1) bytes.erase(bytes.begin());
        bytes.resize(8, 0);
        send(wire, command::apwr, ap(static_cast<std::uint16_t>(reg::sync_manager0 + 8 * sm)), bytes);
        slave.step(1000);
        break;
      }
      case 3:
        put_mailbox(wire, slave, mapping_write(bytes));
        (void)take_mailbox(wire, slave);
        break;
      case 4: bring_up(wire, slave, bytes.empty() ? 8 : static_cast<std::uint8_t>(1u << (bytes[0] % 4))); break;
      case 5: request(wire, slave, bytes.empty() ? 0 : bytes[0]); break;
      case 6:
        bytes.resize(slave.output_bytes(), 0);
        send(wire, command::lwr, outputs_logical, bytes);
        slave.step(1000);
        send(wire, command::lrd, inputs_logical, std::vector<std::uint8_t>(slave.input_bytes(), 0));
        break;
      default: slave.step(1000u * (bytes.empty() ? 1u : bytes[0])); break;
    }
  }
  if (slave.controller().errors().pdi_refused != 0) std::abort();  // the application wrote a register
  // Whatever came before: back to PRE-OP with sound sync managers, and the mailbox answers.
  bring_up(wire, slave, 2);
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
