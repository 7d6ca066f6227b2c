// A line of virtual drives that lies to a master in the ways a faulty or hostile slave can: its SII
// describes mailboxes and sync managers the controller does not have, and any datagram addressed to
// one slave can be lost on its way (that slave never sees it and the master gets it back as sent).
// Shared by the master's unit tests (hostile_slave_test.cpp) and its fuzz target
// (tests/fuzz/ethercat_master_fuzz.cpp); virtual time, no clock.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/esc/frame.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "cia402/profile.hpp"

namespace cia402::ethercat::testing {

using drive_slave = apps::virtual_drive_slave;

class hostile_line final : public master_link {
 public:
  /// Thrown by the link when the master is still at it past `time_limit_us` of link time: a test of
  /// "every wait ends" fails instead of hanging.
  struct master_did_not_end : std::runtime_error {
    master_did_not_end() : std::runtime_error("the master was still waiting on the line past the time limit") {}
  };
  /// Runs `f` (a call of the master on this line): false when it had not ended by the time limit.
  template <typename F>
  static bool ends(F f) {
    try {
      f();
      return true;
    } catch (const master_did_not_end&) {
      return false;
    }
  }

  explicit hostile_line(int drives) {
    for (int i = 0; i < drives; ++i) {
      slaves.push_back(std::make_unique<drive_slave>(standard_profile(), static_cast<std::uint32_t>(i + 1)));
      escs_.push_back(&slaves.back()->controller());
    }
    for (std::size_t i = 0; i + 1 < escs_.size(); ++i) escs_[i]->set_next_port_open(true);
    if (!escs_.empty()) escs_.back()->set_next_port_open(false);
    sii.resize(escs_.size());
  }

  /// What slave `i`'s EEPROM is read as instead of its own image (nothing: its own).
  std::vector<std::optional<std::vector<std::uint8_t>>> sii;
  /// Whether this datagram never reaches slave `i`: it passes that slave untouched.
  std::function<bool(std::size_t i, const datagram& d)> lose;
  /// Changes a datagram just before slave `i` serves it (a slave that does what its SII did not say).
  std::function<void(std::size_t i, datagram& d)> rewrite;
  /// The whole frame is lost (before any slave sees it).
  std::function<bool()> lose_frame;
  /// Changes the frame on its way back, after every slave served it.
  std::function<void(std::vector<std::uint8_t>& frame)> tamper;
  /// The frame's answer is lost on its way back, after every slave served it (a read that emptied
  /// a mailbox whose data never reached the master).
  std::function<bool(const std::vector<std::uint8_t>& frame)> lose_answer;
  std::uint64_t time_limit_us = 3'600'000'000ull;
  std::uint32_t exchange_us = 20;  // a frame takes time on any line: every loop of the master moves on

  bool exchange(std::vector<std::uint8_t>& frame) override {
    advance(exchange_us);
    ++frames;
    if (lose_frame && lose_frame()) return false;
    parsed_frame parsed;
    if (parse_frame(frame, parsed) == frame_error::none) {  // a frame no slave takes comes back as sent
      for (std::size_t k = 0; k < parsed.count; ++k) {
        datagram& d = parsed.datagrams[k];
        for (std::size_t i = 0; i < escs_.size(); ++i) {
          if (lose && lose(i, d)) continue;
          const bool mine = d.position() == escs_[i]->read16(reg::station_address);
          if (mine && rewrite) rewrite(i, d);
          escs_[i]->process(d);
          if (mine && d.cmd == command::fprd) serve_sii(i, d);
        }
      }
    }
    if (tamper) tamper(frame);
    return !(lose_answer && lose_answer(frame));
  }
  std::uint64_t now_us() override { return now; }
  void wait_us(std::uint32_t us) override { advance(us); }

  /// The image of slave `i`'s description as changed by `change`, served from now on.
  template <typename F>
  void describe(std::size_t i, F change) {
    slave_description d = slaves[i]->description();
    change(d);
    sii[i] = sii_image(d);
  }

  std::vector<std::unique_ptr<drive_slave>> slaves;
  std::uint64_t now = 0;
  std::uint64_t frames = 0;

 private:
  void advance(std::uint32_t us) {
    now += us;
    if (now > time_limit_us) throw master_did_not_end();
    for (auto& s : slaves) s->step(us);
  }
  // A read of the EEPROM data registers (0x0508..) answers from the replacement image.
  void serve_sii(std::size_t i, datagram& d) {
    if (!sii[i] || d.offset() > reg::eeprom_data || d.offset() + d.length < reg::eeprom_data + 4) return;
    const std::uint32_t word = escs_[i]->read32(reg::eeprom_address);
    const std::size_t at = reg::eeprom_data - d.offset();
    for (std::size_t b = 0; b < 8 && at + b < d.length; ++b) {
      const std::uint64_t byte = std::uint64_t{word} * 2 + b;
      d.data[at + b] = byte < sii[i]->size() ? (*sii[i])[byte] : 0xFF;
    }
  }

  std::vector<esc*> escs_;
};

/// A datagram that reads slave `station`'s AL status.
inline bool al_status_read(const datagram& d, std::uint16_t station) {
  return d.cmd == command::fprd && d.position() == station && d.offset() == reg::al_status;
}

}  // namespace cia402::ethercat::testing
