// The instrument behind the "PROFIBUS instrument control" page of seed 003_83442f2f4b0b2bb9.txt:
// one virtual drive (cia402::sim, the core's state machine on a plant), the control word the page
// builds, what became of each action, and the snapshots the page is sent. Every state-machine
// decision is the core's: a command's control word comes from cia402::encode_command, the state,
// status word and transitions from the drive's step. Thread-safe: the cycle thread and the HTTP
// threads share one instrument.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/state.hpp"

namespace cia402::page {

/// An action the instrument took on: its id, reported again in the snapshots' `results`.
struct accepted {
  std::uint64_t id = 0;
};

/// An action refused before anything changed: the HTTP status it maps to and the reason.
struct refused {
  int http_status = 400;
  std::string reason;
  sdo_abort abort = sdo_abort::none;  ///< set when the drive's object interface refused a write
};

using reply = std::variant<accepted, refused>;

/// The page's command buttons. `disable_operation` sends the same word as `switch_on` (the state
/// tells them apart); `fault_reset` is an edge of bit 7; `halt` toggles bit 8.
enum class page_command : std::uint8_t {
  shutdown,
  switch_on,
  enable_operation,
  disable_operation,
  disable_voltage,
  quick_stop,
  fault_reset,
  halt,
};

/// "shutdown", "switch_on", ... as the HTTP API spells them.
const char* page_command_key(page_command c) noexcept;
bool parse_page_command(std::string_view key, page_command& out) noexcept;

/// Plant inputs to change in one request. Validated as a whole by the caller's parser; applied
/// only if the drive accepts the target velocity (the one part it can refuse).
struct plant_change {
  std::optional<std::int64_t> target_velocity;  ///< 0x60FF, rpm
  std::optional<bool> fault;                    ///< true: a fault cause appears; false: all go
  std::uint16_t fault_code = 0x1000;            ///< with fault = true, 1..0xFFFF
  std::uint8_t fault_class = 2;                 ///< with fault = true, 0..4 (profiles with classes)
  std::optional<bool> dc_link;                  ///< DC-link voltage present
  std::optional<bool> sto;                      ///< safe torque off asserted
};

/// Timing of the instrument, in cycles of the virtual drive.
struct instrument_config {
  sim::plant_config plant{};
  /// A snapshot is published at most once per this many cycles, and only when it changed
  /// (40 cycles of 1 ms: at most 25 updates a second).
  std::uint32_t publish_every = 40;
  /// An action has settled once this many cycles passed with no transition and no stop running.
  std::uint32_t settle_quiet = 50;
  /// An action still unsettled after this many cycles is reported as it stands.
  std::uint32_t settle_limit = 15000;
  /// Results kept for the page, newest first.
  std::size_t results_kept = 8;
};

/// One published snapshot: its sequence number and JSON text.
struct published {
  std::uint64_t version = 0;
  std::string json;
};

class instrument {
 public:
  /// The profile must outlive the instrument. Throws std::invalid_argument for a plant
  /// configuration the simulator refuses.
  explicit instrument(const profile& p, const instrument_config& config = {});
  ~instrument();
  instrument(const instrument&) = delete;
  instrument& operator=(const instrument&) = delete;

  /// One cycle of the virtual drive (the control word the page built goes in first).
  void step();
  /// Cycles stepped so far.
  std::uint64_t cycle() const;

  /// A command button: its control word from cia402::encode_command, keeping the other bits.
  reply command(page_command c);
  /// Flips one bit (0..15) of the control word.
  reply toggle_control_bit(int bit);
  /// Writes an object through the drive's object interface (option codes, ramps, 0x60FF, ...).
  /// A write the drive refuses gives its SDO abort code and changes nothing.
  reply write_object(std::uint16_t index, std::int64_t value);
  /// Plant inputs: target velocity, fault, DC link, STO.
  reply change_plant(const plant_change& change);

  /// The profile, the bit names, the transition rows: what the page draws once. `control` tells the
  /// page whether its requests will be obeyed.
  std::string info_json(bool control, bool token_required) const;
  /// The present snapshot (state, words, plant, results), built now.
  std::string snapshot_json() const;

  /// Waits until a snapshot newer than `seen` is published, or `timeout` passes, or close() is
  /// called. Returns the newest snapshot if it is newer than `seen`, else nothing.
  std::optional<published> wait_for_update(std::uint64_t seen, std::chrono::milliseconds timeout);
  /// The newest published snapshot (version 0 before the first).
  published latest() const;
  /// Wakes every waiter for good (shutdown).
  void close();
  bool closed() const;

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace cia402::page
