// EtherCAT on the in-process wire: one LRW cycle through 64 chained emulated ESCs, each with an
// output and an input FMMU of 8 bytes (a csp drive: control word and target, status word and
// position): time per frame and frames per second. The controllers only; the drives behind them are the simulator's.
#include <benchmark/benchmark.h>

#include <vector>

#include "cia402/ethercat/esc/esc.hpp"

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
  for (std::size_t i = 0; i < n; ++i) {
    // FMMU 0 writes the outputs at 0x1100, FMMU 1 reads the inputs at 0x1180.
    for (int f = 0; f < 2; ++f) {
      std::vector<std::uint8_t> m(16, 0);
      put(m, 0, static_cast<std::uint32_t>(0x10000 + i * 2 * bytes + static_cast<std::size_t>(f) * bytes), 4);
      put(m, 4, bytes, 2);
      m[7] = 7;
      put(m, 8, f == 0 ? 0x1100 : 0x1180, 2);
      m[11] = f == 0 ? 2 : 1;
      m[12] = 1;
      for (std::size_t k = 0; k < m.size(); ++k) {
        escs[i].write8(static_cast<std::uint16_t>(reg::fmmu0 + 16 * f + static_cast<int>(k)), m[k]);
      }
    }
  }
  frame_builder b({0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}, {2, 0, 0, 0, 0, 1});
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

}  // namespace

BENCHMARK_MAIN();
