// Frames per second through the in-process CAN bus: 64 virtual drives (CiA 301 slaves around the
// simulator's drive) and one master running the core's master step for each, at a 1 ms SYNC. Every
// cycle carries 1 SYNC, 64 TPDO1 (status word, synchronous type 1) and 64 RPDO1 (control word): 129
// frames per millisecond of virtual time. A saturated 1 Mbit/s CAN bus carries about 8,000 frames/s;
// the aim is ten times that. The counter `frames_per_second` is frames through the bus per second
// of wall time.
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "cia402/canopen/301/nmt.hpp"
#include "cia402/apps/virtual_drive_node.hpp"
#include "cia402/canopen/transport/virtual_bus.hpp"
#include "cia402/master.hpp"

namespace {

using namespace cia402;
using namespace cia402::canopen;
using namespace cia402::dictionary;

struct node {
  std::unique_ptr<cia402::apps::virtual_drive_node> drive;
  cia402::master m;
};

void bm_bus_64_drives_1ms_sync(benchmark::State& state) {
  const auto drives = static_cast<std::size_t>(state.range(0));
  const bool filtered = state.range(1) != 0;
  const profile& p = standard_profile();
  const master_policy policy = master_policy::make(p, make_axis(p), state::operation_enabled);
  virtual_bus bus;
  auto master_ch = bus.attach();
  std::vector<node> nodes(drives);
  for (std::size_t i = 0; i < drives; ++i) {
    node& n = nodes[i];
    const slave_config c = cia402::apps::drive_node_config(static_cast<std::uint8_t>(i + 1));
    std::unique_ptr<virtual_channel> ch = bus.attach();
    // With `filtered`, the node's CAN controller takes only what concerns it (NMT, SYNC, its SDO
    // and RPDO1), as hardware acceptance filters do; without, every node sees every frame.
    if (filtered) {
      ch->accept_none();
      for (std::uint32_t id : {cob::nmt, cob::sync, cob::sdo_rx + c.node_id, cob::rpdo1 + c.node_id}) {
        ch->accept(id);
      }
    }
    n.drive = std::make_unique<cia402::apps::virtual_drive_node>(p, std::move(ch), c);
    n.drive->node().write(0x1800, 2, 1);  // TPDO1 on every SYNC
    n.m.set_target(policy, 0, 0);
  }
  master_ch->send(nmt_frame(nmt_command::start, 0));
  const frame sync = make_frame(cob::sync, {});
  std::uint64_t now = 0;
  const std::uint64_t frames_before = bus.frames();
  for (auto _ : state) {
    master_ch->send(sync);
    for (node& n : nodes) n.drive->poll(1000);  // SYNC -> TPDO1, 1 ms of plant
    frame f;
    while (master_ch->receive(f)) {
      const std::size_t i = (f.id & 0x7F) - 1;
      if ((f.id & 0x780) != cob::tpdo1 || i >= drives) continue;
      const auto sw = static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
      frame rpdo;
      rpdo.id = cob::rpdo1 + static_cast<std::uint32_t>(i + 1);
      rpdo.len = 2;
      const std::uint16_t cw = nodes[i].m.step(sw, now);
      rpdo.data[0] = static_cast<std::uint8_t>(cw);
      rpdo.data[1] = static_cast<std::uint8_t>(cw >> 8);
      master_ch->send(rpdo);
    }
    for (node& n : nodes) n.drive->poll(0);  // RPDO1 acts at once (type 255)
    ++now;
  }
  const auto frames = static_cast<double>(bus.frames() - frames_before);
  state.counters["frames_per_second"] = benchmark::Counter(frames, benchmark::Counter::kIsRate);
  state.counters["frames_per_cycle"] = frames / static_cast<double>(state.iterations());
  std::size_t enabled = 0;
  for (node& n : nodes) enabled += n.drive->drive().view().current() == state::operation_enabled;
  state.counters["drives_enabled"] = static_cast<double>(enabled);
}

// Args: drives, acceptance filters on (1) or off (0). Rates are per second of wall time.
BENCHMARK(bm_bus_64_drives_1ms_sync)
    ->ArgNames({"drives", "filtered"})
    ->Args({64, 0})
    ->Args({64, 1})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
