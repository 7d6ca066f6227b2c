// The EtherCAT master's link to a real line: a raw socket (AF_PACKET, EtherType 0x88A4) bound to a
// network interface, and the wall clock. A frame goes out and the one that comes back with the same
// first datagram index is its answer (our own frame, seen going out, and late answers to frames
// given up on are passed over). Linux; needs CAP_NET_RAW (root).
#pragma once

#include <cstdint>
#include <string>
#include <system_error>
#include <vector>

#include "cia402/apps/raw_socket.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"

namespace cia402::apps {

class ethercat_link final : public ethercat::master_link {
 public:
  /// `answer_timeout_us`: how long exchange() waits for a frame to come back.
  explicit ethercat_link(std::uint32_t answer_timeout_us = 100000);
  ~ethercat_link() override;
  ethercat_link(const ethercat_link&) = delete;
  ethercat_link& operator=(const ethercat_link&) = delete;

  /// Opens the raw socket on `interface`: the error (no such interface, no permission) if that fails.
  std::error_code open(const std::string& interface);

  bool exchange(std::vector<std::uint8_t>& frame) override;
  std::uint64_t now_us() override;
  void wait_us(std::uint32_t us) override;

 private:
  detail::raw_socket socket_;
  std::uint32_t answer_timeout_us_;
  std::vector<std::uint8_t> buffer_;
};

}  // namespace cia402::apps
