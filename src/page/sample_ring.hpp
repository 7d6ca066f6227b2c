// The drive's cycles for the page's scope (issue 35): one sample per cycle of the link (each step
// of a drive in this process, each SYNC on CAN, each LRW on EtherCAT), numbered without a gap, kept
// in a ring that each event stream reads from where it is. A stream that falls further behind than
// the ring holds skips ahead; the page sees the gap in the numbers and says so.
//
// A batch is JSON, column by column, each column run-length coded ([value, count, value, count,
// ...]; null where the drive gave no value), the times as the first sample's and then the steps
// between them, run-length coded too:
//   {"from": 1200, "n": 40, "t0": 1200000, "dt": [1000, 39], "polled": ["torque"],
//    "columns": {"status_word": [567, 40], "velocity": [...], ...}}
// `polled`: the signals that are not the bus's own cycle but the last value the session polled.
// A standing drive costs a few hundred bytes a batch, a moving one about a number per changing
// column and cycle.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace cia402::page::detail {

/// The signals of a sample, in column order.
enum class signal : std::uint8_t {
  status_word,      ///< 0x6041
  control_word,     ///< 0x6040, the word the drive had in that cycle
  state,            ///< the state the status word shows (cia402::state as a number)
  transition,       ///< the transition taken in that cycle (exact in process, inferred on a bus)
  velocity,         ///< 0x606C, rpm
  position,         ///< 0x6064, increments
  torque,           ///< 0x6077, permille
  following_error,  ///< 0x60F4, increments
  set_point,        ///< the running mode's: 0x607A (pp, csp), 0x60FF (pv, csv), 0x6071 (tq, cst)
  position_demand,  ///< 0x6062
  digital_inputs,   ///< 0x60FD: 0 negative limit, 1 positive limit, 2 home switch, 16 index pulse
  mode,             ///< 0x6061
  error_code,       ///< 0x603F
};
inline constexpr std::size_t signal_count = 13;

/// "status_word", ...: the names the batches' columns have.
const std::array<const char*, signal_count>& signal_names();

struct cycle_sample {
  std::uint64_t time_us = 0;
  std::array<std::int64_t, signal_count> value{};
  std::uint32_t known = 0;  ///< bit k: value[k] is the drive's

  void set(signal s, std::int64_t v) {
    const auto k = static_cast<std::size_t>(s);
    value[k] = v;
    known |= 1u << k;
  }
  bool has(signal s) const { return (known >> static_cast<std::size_t>(s)) & 1u; }
  std::int64_t get(signal s) const { return value[static_cast<std::size_t>(s)]; }
};

class sample_ring {
 public:
  static constexpr std::size_t default_capacity = 8192;  ///< 8 s of a 1 ms cycle

  explicit sample_ring(std::size_t capacity = default_capacity);

  void push(const cycle_sample& s);
  /// Forgets every sample; the numbers go on (a profile switch starts the drive afresh).
  void clear();
  /// The number the next sample gets, and the oldest one kept.
  std::uint64_t end() const;
  std::uint64_t begin() const;
  /// Samples from `from` (or the oldest kept, when `from` is older) on, at most `max`, as a batch;
  /// `next` is the number after the last one in it. `polled`: the signals' names that are the last
  /// value polled rather than the cycle's.
  std::string batch_json(std::uint64_t from, std::size_t max, std::uint64_t& next,
                         const std::vector<std::string>& polled) const;
  /// Samples from `from` on, at most `max`, as they are (for tests and the batch).
  std::vector<cycle_sample> copy(std::uint64_t& from, std::size_t max) const;

 private:
  mutable std::mutex mutex_;
  std::vector<cycle_sample> ring_;
  std::uint64_t end_ = 0;
  std::uint64_t begin_ = 0;
};

}  // namespace cia402::page::detail
