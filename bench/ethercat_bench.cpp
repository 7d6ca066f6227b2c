// EtherCAT on the in-process wire.
// - lrw_through_chain: one LRW cycle through 64 chained emulated ESCs, each with an output and an
//   input FMMU of 8 bytes (a csp drive: control word and target, status word and position): time
//   per frame and frames per second. The controllers only.
// - drive_line_1ms_cycle: a line of virtual drives (CoE slaves with the simulator's drive) brought
//   to OP by our master, which runs its cycle (one LRW of every drive's default process data, 13
//   bytes out and 19 in, and the core's master step per drive) while every slave's application
//   runs 1 ms (process data in and out, the drive's plant): cycles per second of wall time. 32
//   drives: 64 would not fit one frame with these PDOs.
#include <benchmark/benchmark.h>

#include <array>
#include <memory>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/master.hpp"
#include "cia402/profile.hpp"
#include "../tests/ethercat/drive_line.hpp"

namespace {

using namespace cia402::ethercat;

void put(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

void lrw_through_chain(benchmark::State& st) {
  const auto n = static_cast<std::size_t>(st.range(0));
  constexpr std::uint16_t bytes = 8;  // 64 x (8 out + 8 in) fits one frame; 16 + 16 would not
  std::vector<esc> escs;
  escs.reserve(n);
  for (std::size_t i = 0; i < n; ++i) escs.emplace_back(std::vector<std::uint8_t>(2048, 0xFF));
  chain wire;
  for (esc& e : escs) wire.add(e);
  // FMMU 0 writes the outputs at 0x1100, FMMU 1 reads the inputs at 0x1180: configured by the master
  // side (APWR), since an application may not write FMMU registers.
  const std::array<std::uint8_t, 6> broadcast{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  const std::array<std::uint8_t, 6> master_mac{2, 0, 0, 0, 0, 1};
  for (std::size_t i = 0; i < n; ++i) {
    frame_builder setup(broadcast, master_mac);
    for (int f = 0; f < 2; ++f) {
      std::vector<std::uint8_t> m(16, 0);
      put(m, 0, static_cast<std::uint32_t>(0x10000 + i * 2 * bytes + static_cast<std::size_t>(f) * bytes), 4);
      put(m, 4, bytes, 2);
      m[7] = 7;
      put(m, 8, f == 0 ? 0x1100 : 0x1180, 2);
      m[11] = f == 0 ? 2 : 1;
      m[12] = 1;
      const auto position = static_cast<std::uint16_t>(-static_cast<int>(i));
      setup.add(command::apwr, 0, position | (static_cast<std::uint32_t>(reg::fmmu0 + 16 * f) << 16), m,
                static_cast<std::uint16_t>(m.size()));
    }
    std::vector<std::uint8_t> f = setup.finish();
    (void)wire.pass(f);
  }
  frame_builder b(broadcast, master_mac);
  const std::vector<std::uint8_t> out(n * 2 * bytes, 0x5A);
  b.add(command::lrw, 0, 0x10000, out, static_cast<std::uint16_t>(out.size()));
  const std::vector<std::uint8_t> frame = b.finish();
  std::vector<std::uint8_t> f;
  for (auto _ : st) {
    f = frame;
    benchmark::DoNotOptimize(wire.pass(f));
  }
  st.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
  const std::size_t wkc_at = ethernet_header_size + ethercat_header_size + datagram_header_size + out.size();
  st.counters["wkc"] = static_cast<double>(f[wkc_at] | (f[wkc_at + 1] << 8));  // 3 a slave
}
BENCHMARK(lrw_through_chain)->Arg(1)->Arg(64);

using wire_link = cia402::ethercat::testing::drive_line;

void drive_line_1ms_cycle(benchmark::State& st) {
  const auto n = static_cast<std::size_t>(st.range(0));
  wire_link link(n);
  ecat_master master(link, cia402::standard_profile());
  if (!master.scan() || !master.bring_to_operational()) {
    st.SkipWithError(master.error().c_str());
    return;
  }
  // The master carries words: each drive's control word comes from the core's master step, as the
  // axis session's does over the EtherCAT link, given before the cycle that sends it.
  const cia402::profile& p = cia402::standard_profile();
  const cia402::master_policy policy = cia402::master_policy::make(p, cia402::make_axis(p), cia402::state::operation_enabled);
  std::vector<cia402::master> steering(n);
  for (cia402::master& m : steering) m.set_target(policy, link.now_us(), 2'000'000);
  std::uint64_t short_counts = 0;
  for (auto _ : st) {
    for (std::size_t i = 0; i < n; ++i) {
      const ecat_slave& s = master.slaves()[i];
      master.send_control_word(i, steering[i].step(s.last_status, link.now_us(), s.last_error_code));
    }
    short_counts += master.cycle() ? 0 : 1;
    link.wait_us(1000);
  }
  st.counters["cycles_per_s"] = benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
  st.counters["failed_cycles"] = static_cast<double>(short_counts);
  std::size_t enabled = 0;
  for (const ecat_slave& s : master.slaves()) {
    cia402::state shown = cia402::state::start;
    enabled += cia402::decode_status(cia402::standard_profile(), s.last_status, shown) &&
               shown == cia402::state::operation_enabled;
  }
  st.counters["drives_enabled"] = static_cast<double>(enabled);
}
BENCHMARK(drive_line_1ms_cycle)->Arg(32)->UseRealTime()->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
