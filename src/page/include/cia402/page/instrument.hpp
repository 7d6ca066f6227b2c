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

#include "cia402/page/backend.hpp"
#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/state.hpp"

namespace cia402::page {

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
  /// The sign of life (sign_of_life.hpp): a drive left in OPERATION ENABLED is stopped as its 0x6007
  /// says once no client renewed the lease for this long (drive time); 0: no lease.
  std::uint64_t lease_us = 0;
  /// The profiles the page may switch to (each must outlive the instrument); empty: the built-in
  /// ones and the instrument's own.
  std::vector<const profile*> selectable;
};

class instrument final : public backend {
 public:
  /// The profile must outlive the instrument. Throws std::invalid_argument for a plant
  /// configuration the simulator refuses.
  explicit instrument(const profile& p, const instrument_config& config = {});
  ~instrument() override;
  instrument(const instrument&) = delete;
  instrument& operator=(const instrument&) = delete;

  /// One cycle of the virtual drive (the control word the page built goes in first).
  void step() override;
  /// Cycles stepped so far.
  std::uint64_t cycle() const;

  /// A command button: its control word from cia402::encode_command, keeping the other bits.
  reply command(page_command c) override;
  /// Flips one bit (0..15) of the control word.
  reply toggle_control_bit(int bit) override;
  /// Profile position's set-point handshake: bit 4 up until status bit 12, then down (backend.hpp).
  reply new_setpoint() override;
  /// One-click enable, stop and jog (backend.hpp; the walk and the jog's time-to-live run on the
  /// drive's cycles).
  reply enable() override;
  reply stop() override;
  reply jog(std::int64_t velocity_rpm, std::uint64_t time_to_live_us) override;
  /// Starts again from power-up under another of the selectable profiles; the recording and the
  /// control word start over, the results say so.
  reply select_profile(std::string_view name) override;
  /// Writes an object through the drive's object interface (option codes, ramps, 0x60FF, ...).
  /// A write the drive refuses gives its SDO abort code and changes nothing.
  reply write_object(std::uint16_t index, std::int64_t value) override;
  /// Plant inputs: target velocity, fault, DC link, STO.
  reply change_plant(const plant_change& change) override;
  /// The lease is renewed; the next cycle sees it.
  void renew_lease() override;

  /// The profile, the bit names, the transition rows: what the page draws once. `control` tells the
  /// page whether its requests will be obeyed.
  std::string info_json(bool control, bool token_required) const override;
  /// The present snapshot (state, words, plant, results), built now.
  std::string snapshot_json() const override;
  std::string recording_json(std::uint64_t rows_seen,
                             std::uint64_t transitions_seen) const override;
  std::string recording_file(recording_format format) const override;

  /// Waits until a snapshot newer than `seen` is published, or `timeout` passes, or close() is
  /// called. Returns the newest snapshot if it is newer than `seen`, else nothing.
  std::optional<published> wait_for_update(std::uint64_t seen,
                                           std::chrono::milliseconds timeout) override;
  /// The newest published snapshot (version 0 before the first).
  published latest() const override;
  /// Wakes every waiter for good (shutdown).
  void close() override;
  bool closed() const override;

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace cia402::page
