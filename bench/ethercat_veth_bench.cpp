// Answer times of `cia402 ecat-slave` on a veth pair, beside a baseline that only echoes frames on
// the same pair, in the same run (issue 34, "latency under load"). Run by hand, as root, release
// build: `cia402_ethercat_veth_bench [--cycles N] [--drives 1,16,64] [--realtime PRIO]`. It makes its
// own veth pair (iproute2) and removes it at the end.
//
// For each line length: our master (ecat_master over ethercat_link) maps controlword and target
// position out, statusword and position in (12 bytes a drive, so 64 drives fit one frame), takes the
// line of virtual drives (ethercat_host, what `cia402 ecat-slave` runs, in a thread of this process)
// to OP with DC and cycles it every 1 ms; the time from a cycle frame's send to its answer is recorded. Then the
// same frame, byte for byte, goes every 1 ms to an echo on the same veth end: a thread that answers
// every frame as the host does (ppoll, recvfrom, sendto) but passes it through nothing. The ratio of
// the two is what the drives' line costs over the kernel's own path.
#include <arpa/inet.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <thread>
#include <vector>

#include "cia402/apps/ethercat_host.hpp"
#include "cia402/apps/ethercat_link.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/profile.hpp"

namespace {

using namespace cia402;

std::uint64_t now_ns() {
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::uint64_t>(t.tv_sec) * 1000000000u + static_cast<std::uint64_t>(t.tv_nsec);
}

struct figures {
  double median_us = 0, p99_us = 0, p999_us = 0, max_us = 0;
  std::size_t over_2ms = 0, lost = 0, count = 0;
};

figures summarise(std::vector<std::uint32_t> ns, std::size_t lost) {
  figures f;
  f.lost = lost;
  f.count = ns.size();
  if (ns.empty()) return f;
  std::sort(ns.begin(), ns.end());
  const auto at = [&](double q) { return ns[std::min(ns.size() - 1, static_cast<std::size_t>(q * static_cast<double>(ns.size())))] / 1000.0; };
  f.median_us = at(0.5);
  f.p99_us = at(0.99);
  f.p999_us = at(0.999);
  f.max_us = ns.back() / 1000.0;
  f.over_2ms = static_cast<std::size_t>(std::count_if(ns.begin(), ns.end(), [](std::uint32_t v) { return v > 2000000; }));
  return f;
}

// The master's link with every cycle frame (first datagram an LRW) timed from send to answer.
class timed_link final : public ethercat::master_link {
 public:
  explicit timed_link(apps::ethercat_link& link) : link_(link) {}
  bool exchange(std::vector<std::uint8_t>& frame) override {
    const bool cycle_frame = frame.size() > 16 && frame[16] == 12;
    if (cycle_frame) last_cycle_frame = frame;
    const std::uint64_t t0 = now_ns();
    const bool ok = link_.exchange(frame);
    if (cycle_frame && recording) {
      if (ok) times.push_back(static_cast<std::uint32_t>(now_ns() - t0));
      else ++lost;
    }
    return ok;
  }
  std::uint64_t now_us() override { return link_.now_us(); }
  void wait_us(std::uint32_t us) override { link_.wait_us(us); }

  bool recording = false;
  std::vector<std::uint32_t> times;
  std::size_t lost = 0;
  std::vector<std::uint8_t> last_cycle_frame;

 private:
  apps::ethercat_link& link_;
};

void next_millisecond(timespec& next) {
  next.tv_nsec += 1000000;
  if (next.tv_nsec >= 1000000000) {
    next.tv_nsec -= 1000000000;
    ++next.tv_sec;
  }
  ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
}

void set_fifo(int priority) {
  if (priority <= 0) return;
  sched_param p{};
  p.sched_priority = priority;
  if (::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &p) != 0) std::fprintf(stderr, "SCHED_FIFO refused\n");
}

// The baseline: every frame back at once, source marked as the host marks it, nothing else.
void echo(const std::string& iface, const std::atomic<bool>& stop, int priority) {
  set_fifo(priority);
  const int fd = ::socket(AF_PACKET, SOCK_RAW | SOCK_CLOEXEC, htons(0x88A4));
  sockaddr_ll address{};
  address.sll_family = AF_PACKET;
  address.sll_protocol = htons(0x88A4);
  address.sll_ifindex = static_cast<int>(::if_nametoindex(iface.c_str()));
  if (fd < 0 || ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    std::fprintf(stderr, "echo: cannot open %s\n", iface.c_str());
    return;
  }
  std::vector<std::uint8_t> frame(1600);
  while (!stop) {
    pollfd p{fd, POLLIN, 0};
    const timespec wait{0, 1000000};
    (void)::ppoll(&p, 1, &wait, nullptr);
    for (int burst = 0; burst < 64; ++burst) {
      sockaddr_ll from{};
      socklen_t from_len = sizeof from;
      const ssize_t n = ::recvfrom(fd, frame.data(), frame.size(), MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&from), &from_len);
      if (n <= 0) break;
      if (from.sll_pkttype == PACKET_OUTGOING) continue;
      frame[6] |= 0x02;
      sockaddr_ll to = address;
      to.sll_halen = 6;
      std::memcpy(to.sll_addr, frame.data(), 6);
      (void)::sendto(fd, frame.data(), static_cast<std::size_t>(n), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
    }
  }
  ::close(fd);
}

bool run_line(const std::string& master_end, const std::string& slave_end, int drives, int cycles, int priority,
              figures& line, figures& baseline, std::size_t& frame_bytes) {
  volatile std::sig_atomic_t stop_host = 0;
  apps::ethercat_host host(standard_profile(), drives, 1000);
  if (host.open(slave_end)) return false;
  std::thread slaves([&] {
    set_fifo(priority);
    host.run(stop_host);
  });
  apps::ethercat_link raw(100000);
  if (raw.open(master_end)) return false;
  timed_link link(raw);
  ethercat::ecat_master master(link, standard_profile(), 1000);
  bool ok = master.scan() && master.bring_to_pre_operational();
  // Controlword and target position out, statusword and position in (12 bytes a drive instead of
  // the default 32), so that 64 drives fit the one LRW a cycle this master sends.
  for (std::size_t i = 0; ok && i < master.slaves().size(); ++i) {
    ok = master.sdo_write(i, 0x1600, 0, 2, 1).ok && master.sdo_write(i, 0x1A00, 0, 2, 1).ok;
  }
  ok = ok && master.bring_to_operational();
  if (!ok) std::fprintf(stderr, "%d drives: %s\n", drives, master.error().c_str());
  timespec next{};
  ::clock_gettime(CLOCK_MONOTONIC, &next);
  for (int c = 0; ok && c < 500; ++c) {  // settle: SYNC0 running, drift distributed
    next_millisecond(next);
    (void)master.cycle();
  }
  link.recording = true;
  for (int c = 0; ok && c < cycles; ++c) {
    next_millisecond(next);
    (void)master.cycle();
  }
  link.recording = false;
  stop_host = 1;
  slaves.join();
  if (!ok) return false;
  line = summarise(link.times, link.lost);
  frame_bytes = link.last_cycle_frame.size();

  std::atomic<bool> stop_echo{false};
  std::thread echoer([&] { echo(slave_end, stop_echo, priority); });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::vector<std::uint32_t> times;
  std::size_t lost = 0;
  std::vector<std::uint8_t> frame;
  ::clock_gettime(CLOCK_MONOTONIC, &next);
  for (int c = 0; c < cycles; ++c) {
    next_millisecond(next);
    frame = link.last_cycle_frame;
    frame[17] = static_cast<std::uint8_t>(c);  // the first datagram's index, as the master counts it
    const std::uint64_t t0 = now_ns();
    if (raw.exchange(frame)) times.push_back(static_cast<std::uint32_t>(now_ns() - t0));
    else ++lost;
  }
  stop_echo = true;
  echoer.join();
  baseline = summarise(times, lost);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  int cycles = 20000;
  int priority = 0;
  std::vector<int> lines{1, 16, 64};
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string option = argv[i];
    if (option == "--cycles") cycles = std::atoi(argv[i + 1]);
    else if (option == "--realtime") priority = std::atoi(argv[i + 1]);
    else if (option == "--drives") {
      lines.clear();
      for (const char* p = argv[i + 1]; *p != 0;) {
        char* end = nullptr;
        lines.push_back(static_cast<int>(std::strtol(p, &end, 10)));
        p = *end == ',' ? end + 1 : end;
      }
    } else {
      std::fprintf(stderr, "usage: %s [--cycles N] [--drives 1,16,64] [--realtime PRIO]\n", argv[0]);
      return 2;
    }
  }
  if (::geteuid() != 0) {
    std::fprintf(stderr, "needs root: a veth pair and raw sockets\n");
    return 77;
  }
  const std::string m = "c4bm" + std::to_string(::getpid() % 10000), s = "c4bs" + std::to_string(::getpid() % 10000);
  if (std::system(("ip link add " + m + " type veth peer name " + s + " && ip link set " + m + " up && ip link set " + s + " up").c_str()) != 0) {
    std::fprintf(stderr, "cannot make a veth pair\n");
    return 1;
  }
  set_fifo(priority);
  std::printf("answer times over %d cycles at 1 ms on a veth pair (us); ratio = line / echo of the same frame, same run\n", cycles);
  std::printf("%6s %6s | %-33s | %-33s | %s\n", "drives", "bytes", "echo: median p99 p99.9 max", "ecat-slave: median p99 p99.9 max", "ratios median p99 p99.9 max; >2ms; lost");
  int status = 0;
  for (int drives : lines) {
    figures line, baseline;
    std::size_t bytes = 0;
    if (!run_line(m, s, drives, cycles, priority, line, baseline, bytes)) {
      status = 1;
      continue;
    }
    std::printf("%6d %6zu | %7.1f %7.1f %7.1f %8.1f | %7.1f %7.1f %7.1f %8.1f | %5.2f %5.2f %5.2f %5.2f; %zu/%zu; %zu/%zu\n",
                drives, bytes, baseline.median_us, baseline.p99_us, baseline.p999_us, baseline.max_us, line.median_us,
                line.p99_us, line.p999_us, line.max_us, line.median_us / baseline.median_us, line.p99_us / baseline.p99_us,
                line.p999_us / baseline.p999_us, line.max_us / baseline.max_us, line.over_2ms, baseline.over_2ms, line.lost,
                baseline.lost);
    std::fflush(stdout);
  }
  (void)std::system(("ip link del " + m).c_str());
  return status;
}
