// Our EtherCAT master (ethercat/master) on a hostile line of one or two virtual drives
// (tests/ethercat/hostile_line.hpp). The fuzzer's bytes decide what each slave's SII says about its
// mailboxes and sync managers (and whether the controller takes the master's mailbox layout
// whatever the SII said), then, frame by frame, whether the line passes the answers, changes or
// replaces their bytes, loses the frame, loses one slave's datagrams, delays the answer, or loses a
// slave's AL status reads for a while. The master is asked for everything a tool does with it: a
// cycle before any bring-up, scan, SDOs, OP, cycles, back to PRE-OP, a remap of drive 0's outputs
// (up to 12 entries, the control word anywhere among them), OP again.
// Promise: no crash, no sanitizer report, and every step of the master ends (link time bounds each
// wait; libFuzzer's -timeout catches one that does not): whatever the line says, a master never
// hangs on it or reads or writes outside its buffers.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../ethercat/enable_words.hpp"
#include "../ethercat/hostile_line.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/profile.hpp"

namespace {

using namespace cia402;
using namespace cia402::ethercat;
using cia402::ethercat::testing::hostile_line;

class input {
 public:
  input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return at_ >= size_; }
  std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  std::uint16_t word() { return static_cast<std::uint16_t>(byte() | (byte() << 8)); }
  std::size_t take(std::size_t n, const std::uint8_t*& p) {
    p = data_ + at_;
    n = n < size_ - at_ ? n : size_ - at_;
    at_ += n;
    return n;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

// What the SII of one slave says instead of the truth: mailbox sizes and places, the process data
// sync managers, CoE or not. Small sizes are as likely as large ones.
void lie_about(slave_description& d, input& in) {
  const std::uint8_t what = in.byte();
  const auto size = [&](std::uint16_t v) { return (v & 0x8000) ? static_cast<std::uint16_t>(v & 0x1F) : v; };
  if (what & 0x01) d.mailbox_out_size = size(in.word());
  if (what & 0x02) d.mailbox_in_size = size(in.word());
  if (what & 0x04) d.mailbox_out_start = in.word();
  if (what & 0x08) d.mailbox_in_start = in.word();
  if (what & 0x10) d.coe = !d.coe;
  if ((what & 0x20) && !d.sync_managers.empty()) {
    sync_manager_description& sm = d.sync_managers[in.byte() % d.sync_managers.size()];
    sm.start = in.word();
    sm.length = size(in.word());
    sm.control = in.byte();
    sm.type = static_cast<sm_type>(in.byte() % 6);
  }
  if (what & 0x40) d.sync_managers.resize(in.byte() % 6);
  if (what & 0x80) {
    for (fmmu_use& f : d.fmmus) f = static_cast<fmmu_use>(in.byte() % 5);
  }
}

// The mailbox sync managers of the slave's real description, whatever the master wrote: a slave
// that runs a mailbox its SII did not describe.
void own_mailbox_layout(const slave_description& real, datagram& d) {
  if (d.cmd != ethercat::command::fpwr || d.offset() != reg::sync_manager0 || d.length < 16) return;
  for (int n = 0; n < 2 && n < static_cast<int>(real.sync_managers.size()); ++n) {
    const sync_manager_description& sm = real.sync_managers[static_cast<std::size_t>(n)];
    std::uint8_t* p = d.data + 8 * n;
    p[0] = static_cast<std::uint8_t>(sm.start);
    p[1] = static_cast<std::uint8_t>(sm.start >> 8);
    p[2] = static_cast<std::uint8_t>(sm.length);
    p[3] = static_cast<std::uint8_t>(sm.length >> 8);
    p[4] = sm.control;
  }
}

struct hostility {
  input& in;
  hostile_line& line;
  std::size_t lost_status_of = 0;  // whose AL status reads are lost
  int lost_status_frames = 0;      // for how many more frames
  int frames_lost_for = -1;        // this frame: lose slave k's datagrams (-1: none)

  void next_frame() {
    frames_lost_for = -1;
    if (lost_status_frames > 0) --lost_status_frames;
    if (in.empty()) return;
    const std::uint8_t action = in.byte();
    const std::uint8_t length = in.byte();
    const std::uint8_t* bytes = nullptr;
    const std::size_t n = in.take(length, bytes);
    switch (action % 8) {
      case 1:  // bytes changed: each pair is an offset and an XOR
        line.tamper = [bytes, n](std::vector<std::uint8_t>& frame) {
          for (std::size_t k = 0; k + 1 < n; k += 2) frame[bytes[k] % frame.size()] ^= bytes[k + 1];
        };
        return;
      case 2:
        line.tamper = [bytes, n](std::vector<std::uint8_t>& frame) { frame.assign(bytes, bytes + n); };
        return;
      case 3: line.tamper = nullptr; lose_whole = true; return;
      case 4: frames_lost_for = n > 0 ? bytes[0] % 2 : 0; break;
      case 5: line.wait_us(static_cast<std::uint32_t>(n > 0 ? bytes[0] : 1) * 1000u); break;  // a late answer
      case 6:
        lost_status_of = n > 0 ? bytes[0] % 2 : 0;
        lost_status_frames = n > 1 ? bytes[1] : 50;
        break;
      default: break;
    }
    line.tamper = nullptr;
  }
  bool lose_whole = false;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  input in(data, size);
  const std::uint8_t shape = in.byte();
  hostile_line line((shape & 0x01) ? 2 : 1);
  line.time_limit_us = 36'000'000'000ull;  // 10 h of link time: far past any wait's limit; the wall-clock -timeout comes first
  const std::size_t drives = line.slaves.size();
  const bool lying_mailbox = (shape & 0x08) != 0;
  // The remap after the first OP: how many entries 0x1601 gets (the control word among 32-bit
  // set-points), and how many 0x1600 gets ahead of it in 0x1C12 (none: 0x1601 alone).
  const std::uint8_t remap = in.byte();
  const std::uint8_t entries = static_cast<std::uint8_t>(1 + remap % 12);
  const std::uint8_t control_at = static_cast<std::uint8_t>(1 + (remap >> 4) % entries);
  const std::uint8_t ahead = static_cast<std::uint8_t>(in.byte() % 13);
  for (std::size_t i = 0; i < drives; ++i) {
    if (shape & (0x02u << i)) line.describe(i, [&](slave_description& d) { lie_about(d, in); });
  }
  hostility h{in, line};
  line.lose_frame = [&] {
    h.lose_whole = false;
    h.next_frame();
    return h.lose_whole;
  };
  line.lose = [&](std::size_t i, const datagram& d) {
    if (h.frames_lost_for == static_cast<int>(i)) return true;
    return h.lost_status_frames > 0 && i == h.lost_status_of &&
           testing::al_status_read(d, static_cast<std::uint16_t>(0x1001 + i));
  };
  if (lying_mailbox) {
    line.rewrite = [&](std::size_t i, datagram& d) { own_mailbox_layout(line.slaves[i]->description(), d); };
  }

  ecat_master m(line, standard_profile());
  (void)m.cycle();  // before any bring-up: refused
  if (!m.scan()) return 0;
  (void)m.sdo_read(0, 0x1018, 1);
  if (!m.bring_to_operational()) return 0;
  for (int i = 0; i < 30; ++i) {
    cia402::ethercat::testing::send_enable_word(m, 0);  // drive 0's words towards OPERATION ENABLED
    (void)m.cycle();
    line.wait_us(1000);
  }
  // Back to PRE-OP, drive 0's outputs remapped larger, OP again: the image must follow.
  if (!m.bring_to_pre_operational()) return 0;
  (void)m.sdo_write(0, 0x1C12, 0, 0, 1);
  (void)m.sdo_write(0, 0x1601, 0, 0, 1);
  for (std::uint8_t k = 1; k <= entries; ++k) {
    (void)m.sdo_write(0, 0x1601, k, k == control_at ? 0x60400010 : 0x607A0020, 4);
  }
  (void)m.sdo_write(0, 0x1601, 0, entries, 1);
  std::uint8_t assigned = 0;
  if (ahead > 0) {
    (void)m.sdo_write(0, 0x1600, 0, 0, 1);
    for (std::uint8_t k = 1; k <= ahead; ++k) (void)m.sdo_write(0, 0x1600, k, 0x607A0020, 4);
    (void)m.sdo_write(0, 0x1600, 0, ahead, 1);
    (void)m.sdo_write(0, 0x1C12, ++assigned, 0x1600, 2);
  }
  (void)m.sdo_write(0, 0x1C12, ++assigned, 0x1601, 2);
  (void)m.sdo_write(0, 0x1C12, 0, assigned, 1);
  if (!m.bring_to_operational()) return 0;
  (void)m.set_output(0, 0x607A, 1000);
  for (int i = 0; i < 20; ++i) {
    (void)m.cycle();
    line.wait_us(1000);
  }
  (void)m.sdo_write(drives - 1, 0x6083, 0, 1000, 4);  // a slave the scan may not have found: an error, not a throw
  return 0;
}
