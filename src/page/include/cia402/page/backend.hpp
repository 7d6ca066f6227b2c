// What the instrument page's server talks to: one drive behind the page. One implementation exists,
// axis_page.hpp: an axis session over the link `cia402 serve` builds (a virtual drive in this
// process, a node on a CAN bus, a slave on an EtherCAT line). The server (server.hpp) and the cycle
// thread (runner.hpp) see only this interface, so tests may give them a drive of their own; the page
// learns from /api/info and the snapshots which kind it shows and what it can do.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

#include "cia402/sdo_abort.hpp"

namespace cia402::page {

/// An action the backend took on: its id, reported again in the snapshots' `results`.
struct accepted {
  accepted() = default;
  accepted(std::uint64_t action_id, std::string what = {}) : id(action_id), text(std::move(what)) {}  // NOLINT: implicit from an id
  std::uint64_t id = 0;
  std::string text;  ///< what was done, where the request answers with it (POST /api/homing)
};

/// An action refused before anything changed: the HTTP status it maps to and the reason.
struct refused {
  int http_status = 400;
  std::string reason;
  sdo_abort abort = sdo_abort::none;  ///< set when the drive's object interface refused a write
};

using reply = std::variant<accepted, refused>;

/// An answer with a body of its own: the HTTP status and the body (JSON; a parameter file's text
/// with status 200 where the request asked for the file).
struct document {
  int http_status = 200;
  std::string body;
};

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

/// A homing run's parameters and its start (POST /api/homing); each one optional. Written in this
/// order before the run starts: 0x6098, 0x6099 sub 1, 0x6099 sub 2, 0x609A, 0x607C.
struct homing_request {
  std::optional<std::int64_t> method;        ///< 0x6098
  std::optional<std::int64_t> switch_speed;  ///< 0x6099 sub 1, rpm: searching the switch
  std::optional<std::int64_t> zero_speed;    ///< 0x6099 sub 2, rpm: the edge and the index pulse
  std::optional<std::int64_t> acceleration;  ///< 0x609A, rpm/s
  std::optional<std::int64_t> offset;        ///< 0x607C, increments
  std::optional<bool> start;  ///< true: run it (homing mode, enabled, bit 4 up); false: stop a run
};

/// The recorder's export formats: CSV, IEEE 1364 VCD (state as integer codes), GTKWave's VCD.
enum class recording_format : std::uint8_t { csv, vcd, vcd_gtkwave };

/// One published snapshot: its sequence number and JSON text.
struct published {
  std::uint64_t version = 0;
  std::string json;
};

/// The drive behind the page. Thread-safe: the cycle thread calls step(), the HTTP threads the rest.
class backend {
 public:
  virtual ~backend() = default;

  /// One cycle (the cycle thread calls it once per cycle of real time; tests call it directly).
  virtual void step() = 0;

  /// A command button: its control word from cia402::encode_command, keeping the other bits.
  virtual reply command(page_command c) = 0;
  /// Flips one bit (0..15) of the control word.
  virtual reply toggle_control_bit(int bit) = 0;
  /// Profile position's set-point handshake (CiA 402-2): control bit 4 (new set-point) rises and
  /// stays set until the drive acknowledges with status bit 12, then falls; bits 5, 6 and 9 are
  /// sent as they stand. Refused (409) where the profile gives bit 4 a meaning of its own or the
  /// drive runs another mode.
  virtual reply new_setpoint() {
    return refused{409, "this drive offers no new set-point handshake"};
  }
  /// One-click enable (docs/instrument-page.md, "Enable, Stop and jog"): walks the state machine
  /// to OPERATION ENABLED one planned step at a time (cia402::plan_path_from_status, S17), each
  /// step confirmed by the status word before the next. Never resets a fault: in FAULT, under STO
  /// or without DC link it is refused (409) with what blocks it.
  virtual reply enable() { return refused{409, "one-click enable is not offered on this drive"}; }
  /// One-click stop: Quick stop (CiA 402 T11, the ramp 0x605A says), then Disable voltage (T12)
  /// once the drive left OPERATION ENABLED; ends any jog and enable walk.
  virtual reply stop() { return refused{409, "one-click stop is not offered on this drive"}; }
  /// Jog with a dead-man: profile velocity (0x6060 = 3) at `velocity_rpm` (0x60FF) until
  /// `time_to_live_us` passes without another jog call; then, on a release (velocity 0) or when
  /// the drive leaves OPERATION ENABLED, 0x60FF = 0. Refused (409) outside OPERATION ENABLED.
  virtual reply jog(std::int64_t velocity_rpm, std::uint64_t time_to_live_us) {
    (void)velocity_rpm;
    (void)time_to_live_us;
    return refused{409, "jog is not offered on this drive"};
  }
  /// Writes an object (option codes, ramps, 0x60FF, ...). A write the drive refuses gives its SDO
  /// abort code and changes nothing.
  virtual reply write_object(std::uint16_t index, std::int64_t value) = 0;
  /// Homing (CiA 402-2 mode 6): writes the parameters the request gives, then starts a run (the
  /// axis session's home: 0x6060 = 6, OPERATION ENABLED, control bit 4 up until status bits 12 and
  /// 10) or stops one. A value outside the object table's range is refused (422) before anything is
  /// sent; a write the drive refuses answers with its SDO abort (422).
  virtual reply home(const homing_request& r) {
    (void)r;
    return refused{409, "homing is not offered on this drive"};
  }
  /// The drive's own pre-defined error field 0x1003 (CiA 301 §7.5.2.5): read it again now (the
  /// snapshots' `drive_errors`), or empty it (0x1003 sub 0 = 0).
  virtual reply read_error_field() { return refused{409, "this drive has no 0x1003 the page reads"}; }
  virtual reply clear_error_field() { return refused{409, "this drive has no 0x1003 the page reads"}; }
  /// Writes one entry (index and sub-index) from text: a number (decimal or 0x-hexadecimal) or,
  /// for a string entry, the string. A refusal gives the SDO abort code (CiA 301 §7.2.4.3.17).
  virtual reply write_entry(std::uint16_t index, std::uint8_t sub, std::string_view value) {
    (void)index;
    (void)sub;
    (void)value;
    return refused{409, "this drive offers no parameter list"};
  }
  /// The parameter list (docs/instrument-page.md, "Parameter list and parameter files"): every
  /// entry with its description and present value, read in one pass, as JSON.
  virtual document parameters() { return {409, R"({"error":"this drive offers no parameter list"})"}; }
  /// The parameter set as a file (200 and the file's text, or an error as JSON).
  virtual document parameter_file() { return parameters(); }
  /// Writes every writable value a parameter file gives, in file order: JSON with what was written,
  /// refused (with its abort code and text) and skipped. A file that does not parse changes nothing
  /// (400, with its line and reason).
  virtual document load_parameter_file(std::string_view text) {
    (void)text;
    return parameters();
  }
  /// Plant inputs: target velocity, fault, DC link, STO. A backend that cannot change one refuses
  /// the request (and says so in the `capabilities` of its info).
  virtual reply change_plant(const plant_change& change) = 0;

  /// Runs the drive under another profile (by name): a virtual drive starts again from power-up
  /// with it. A drive on a bus has the profile it was started with, and refuses.
  virtual reply select_profile(std::string_view name) {
    return refused{409, "profile " + std::string(name) +
                            ": a drive on a bus keeps the profile `cia402 serve --profile` gave it"};
  }

  /// The page's sign of life: a client is there (its event stream is open, or it sent a request it
  /// may control with). A backend with a lease (`lease_us`) stops a drive left in OPERATION ENABLED
  /// as its 0x6007 says when nothing renewed it for that long (docs/page.md, "Sign of life").
  virtual void renew_lease() = 0;

  /// The profile, the bit names, the transition rows, the capabilities: what the page draws once.
  /// `control` tells the page whether its requests will be obeyed.
  virtual std::string info_json(bool control, bool token_required) const = 0;
  /// The present snapshot, built now.
  virtual std::string snapshot_json() const = 0;

  /// The recorder: the rows and transitions after the counts a previous answer gave (0, 0: all
  /// that is kept), as JSON text (see src/page/recorder.hpp).
  virtual std::string recording_json(std::uint64_t rows_seen,
                                     std::uint64_t transitions_seen) const = 0;
  /// The whole recording as a file.
  virtual std::string recording_file(recording_format format) const = 0;

  /// The drive's cycles for the scope: the number the next sample gets (0: none kept).
  virtual std::uint64_t samples_end() const { return 0; }
  /// The samples from number `from` (the oldest kept when it is older) on, at most `max`, as a
  /// batch (src/page/sample_ring.hpp); `next` is the number after the last one in it.
  virtual std::string samples_json(std::uint64_t from, std::size_t max, std::uint64_t& next) const {
    next = from;
    (void)max;
    return {};
  }

  /// Waits until a snapshot newer than `seen` is published, or `timeout` passes, or close() is
  /// called. Returns the newest snapshot if it is newer than `seen`, else nothing.
  virtual std::optional<published> wait_for_update(std::uint64_t seen,
                                                   std::chrono::milliseconds timeout) = 0;
  /// The newest published snapshot (version 0 before the first).
  virtual published latest() const = 0;
  /// Wakes every waiter for good (shutdown).
  virtual void close() = 0;
  virtual bool closed() const = 0;
};

}  // namespace cia402::page
