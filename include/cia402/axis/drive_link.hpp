// What an axis session needs of a fieldbus to reach one CiA 402 drive: the status word in, the
// control word out, the objects it carries cyclically, acyclic object transfers with raw bytes, what
// it knows of an object's type, emergencies, and a close that puts back what it changed on the node.
// One implementation per fieldbus, each in its own folder: canopen/axis (a node over PDOs and SDO),
// ethercat/axis (a slave on a line over the process data and CoE). Everything CiA 402 that is not
// fieldbus is the session's (session.hpp); a link knows no modes, no handshakes, no state targets.
//
// The namespace is cia402::axes (cia402::axis is the core's drive state).
//
// Poll-driven like the rest of the project: poll(elapsed) does the link's work and returns when it
// next wants to run. A link never blocks beyond one exchange and never reads a clock of its own
// (the EtherCAT link reads its line's, which is the master_link's).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cia402/axis/object_value.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402::axes {

/// 0x1008 (CiA 301, ETG.1000.6): the manufacturer's device name, a text.
inline constexpr std::uint16_t device_name_index = 0x1008;

/// Where a link stands.
enum class link_phase : std::uint8_t {
  connecting,  ///< setting up; phase_text() says what it waits for
  running,     ///< transfers work; status and control go cyclically once cyclic() is true
  failed,      ///< the drive or the bus is gone; phase_text() says why
};

/// How one acyclic transfer (an SDO) ended.
struct transfer_result {
  bool ok = false;
  bool cancelled = false;              ///< the link was lost (or closed) before it ran
  sdo_abort abort = sdo_abort::none;   ///< the drive refused it with this code
  std::string error;                   ///< no answer, or a failure without a code, in words
  std::vector<std::uint8_t> data;      ///< an upload's bytes
};
using transfer_done = std::function<void(const transfer_result&)>;

/// One acyclic transfer a link holds until its turn: what upload() or download() was given.
struct pending_transfer {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  bool download = false;
  std::vector<std::uint8_t> bytes;
  transfer_done done;
};

/// Ends every transfer of `queue` as cancelled with `why` (the link was lost or closed) and leaves
/// it empty before the first `done` runs, so a `done` that queues again finds a clean queue.
void cancel_transfers(std::deque<pending_transfer>& queue, const std::string& why);

/// An object in the cyclic data (CANopen PDOs, EtherCAT process data).
struct cyclic_object {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;
};

/// What a link tells its session besides the values.
enum class link_event : std::uint8_t {
  running,    ///< set-up is done (or done again): transfers work
  cyclic,     ///< the cyclic exchange runs: the status word arrives, the control word goes
  failed,     ///< the drive or the bus went away; every transfer queued was cancelled
  restarted,  ///< the drive started afresh (a boot-up): what was written there is gone
};

/// What close() did to leave the node as it was found.
struct close_report {
  bool done = false;                  ///< nothing more will happen
  std::vector<std::string> restored;  ///< what was written back, in words ("0x1A00: TPDO1 mapping")
  std::vector<std::string> left;      ///< what stays changed, and why ("0x1017: no answer")
};

class drive_link {
 public:
  virtual ~drive_link() = default;

  /// The link's work for `elapsed_us` of time: frames, set-up, the cyclic exchange. Returns the
  /// microseconds until it next wants to run.
  virtual std::uint32_t poll(std::uint32_t elapsed_us) = 0;
  /// Work the next poll(0) does without time passing: a transfer a drive in this process answers
  /// at once. On a bus nothing is answered before time passes (a frame must go and come back), so
  /// a bus's link keeps this false; session::poll_until_idle() asks it whether to poll again.
  virtual bool work_now() const { return false; }
  virtual link_phase phase() const = 0;
  /// Why it is connecting or failed, in words; empty while running.
  virtual std::string phase_text() const = 0;
  /// What it is: "node 1 on socketcand://127.0.0.1:29536/can0", "slave 0 (station 0x1001) on ecm".
  virtual std::string what() const = 0;
  /// "node 1", "slave 0": how a line of output names the drive.
  virtual std::string short_name() const = 0;

  /// The cyclic exchange runs (status word in, control word out). EtherCAT has it once running;
  /// CANopen after start_cyclic() has mapped the PDOs and started the node.
  virtual bool cyclic() const = 0;
  /// Asks for the cyclic exchange; a no-op where it runs already.
  virtual void start_cyclic() = 0;
  /// The period of the cyclic exchange (the SYNC, the LRW), in microseconds.
  virtual std::uint32_t cycle_us() const = 0;

  /// The last status word from the cyclic data; false before the first.
  virtual bool status_known() const = 0;
  virtual std::uint16_t status_word() const = 0;
  /// How many status words the cyclic data has brought so far (the same word again counts): a
  /// session tells a word sent after its last control word from one sent before.
  virtual std::uint64_t status_count() const = 0;
  /// 0x603F when the link carries it (cyclically or with every emergency); nothing otherwise.
  virtual std::optional<std::uint16_t> error_code() const = 0;
  /// The control word from now on: sent at once when it changes, and cyclically where the bus
  /// does (nothing is sent before the first call: watching a drive never commands it).
  virtual void set_control_word(std::uint16_t word) = 0;

  /// The objects the link carries cyclically in each direction (0x6040 and 0x6041 among them).
  virtual const std::vector<cyclic_object>& cyclic_inputs() const = 0;
  virtual const std::vector<cyclic_object>& cyclic_outputs() const = 0;
  /// An input's last value, sign-extended where the CiA 402 object table says it is signed.
  virtual std::optional<std::int64_t> cyclic_input(std::uint16_t index, std::uint8_t sub) const = 0;
  /// Puts a value into an output the link carries; false (nothing changed) when it carries none.
  virtual bool set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) = 0;

  /// One acyclic transfer; `done` is called from a later poll() (never from inside this call).
  /// False, and nothing queued, while not running. The session runs one at a time.
  virtual bool upload(std::uint16_t index, std::uint8_t sub, transfer_done done) = 0;
  virtual bool download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes,
                        transfer_done done) = 0;
  /// What the link knows of an object's type from its bus (CiA 301's communication objects, an EDS,
  /// EtherCAT's CoE objects); nothing when it does not know.
  virtual std::optional<value_format> describe(std::uint16_t index, std::uint8_t sub) const = 0;

  /// Starts putting back what the link changed on the node (PDO mapping and transmission, heartbeat,
  /// guarding; EtherCAT: the line out of OP). poll() goes on until closing().done.
  virtual void close() = 0;
  virtual const close_report& closing() const = 0;

  /// An emergency: error code, error register, the manufacturer's bytes.
  std::function<void(std::uint16_t code, std::uint8_t reg, std::span<const std::uint8_t> bytes)> on_emergency;
  std::function<void(link_event event, const std::string& text)> on_event;
  /// Called just before the cyclic outputs go (before each SYNC, before each LRW): the moment to
  /// put the next cyclic set-point.
  std::function<void()> before_cycle;
};

/// What every bus's link keeps alike, held once: the status words counted, the objects of the cyclic
/// exchange (each link fills them as its bus maps them) and the report of its close.
class link_base : public drive_link {
 public:
  std::uint64_t status_count() const override { return status_count_; }
  const std::vector<cyclic_object>& cyclic_inputs() const override { return inputs_; }
  const std::vector<cyclic_object>& cyclic_outputs() const override { return outputs_; }
  const close_report& closing() const override { return report_; }
  /// Refused while the link is not running (drive_link's rule); else handed to queue_transfer().
  bool upload(std::uint16_t index, std::uint8_t sub, transfer_done done) final;
  bool download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes, transfer_done done) final;

 protected:
  /// Takes a transfer upload() or download() accepted into the link's own queue for its bus; false
  /// (nothing queued) when the link refuses it after all.
  virtual bool queue_transfer(pending_transfer t) = 0;

  std::uint64_t status_count_ = 0;
  std::vector<cyclic_object> inputs_, outputs_;
  close_report report_;
};

}  // namespace cia402::axes
