// Our EtherCAT master (ethercat/master) on a hostile line: a virtual drive answers on the
// in-process wire, and the fuzzer's bytes decide, frame by frame, whether the answer comes back as
// the drive gave it, with bytes changed, replaced by the fuzzer's bytes, or not at all. The input is
// a sequence of chunks: an action byte, a length byte and that many bytes. Promise: no crash, no
// sanitizer report, and the master ends (scan, bring-up, cycles, SDOs all give up by link time or a
// bound of their own): whatever the line says, a master never hangs on it.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "cia402/ethercat/402/drive_slave.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/profile.hpp"

namespace {

using namespace cia402;
using namespace cia402::ethercat;

class hostile_link final : public master_link {
 public:
  hostile_link(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {
    wire_.add(slave_.controller());
  }
  bool exchange(std::vector<std::uint8_t>& frame) override {
    now_ += 20;  // a frame takes time on any line: every loop of the master moves on
    wire_.pass(frame);
    if (at_ + 2 > size_) return true;  // the input is spent: an honest line from here
    const std::uint8_t action = data_[at_];
    const std::size_t length = data_[at_ + 1];
    at_ += 2;
    const std::size_t n = length < size_ - at_ ? length : size_ - at_;
    const std::uint8_t* bytes = data_ + at_;
    at_ += n;
    switch (action % 4) {
      case 0: return true;
      case 1:  // bytes changed: each pair is an offset and an XOR
        for (std::size_t k = 0; k + 1 < n; k += 2) frame[bytes[k] % frame.size()] ^= bytes[k + 1];
        return true;
      case 2: frame.assign(bytes, bytes + n); return true;
      default: return false;
    }
  }
  std::uint64_t now_us() override { return now_; }
  void wait_us(std::uint32_t us) override {
    now_ += us;
    slave_.step(us);
  }

 private:
  drive_slave slave_{standard_profile(), 1};
  chain wire_;
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
  std::uint64_t now_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hostile_link link(data, size);
  ecat_master m(link, standard_profile());
  if (!m.scan()) return 0;
  (void)m.sdo_read(0, 0x1018, 1);
  if (!m.bring_to_operational()) return 0;
  m.set_target(0, state::operation_enabled);
  for (int i = 0; i < 50; ++i) {
    (void)m.cycle();
    link.wait_us(1000);
  }
  (void)m.sdo_write(0, 0x6083, 0, 1000, 4);
  return 0;
}
