// An EtherCAT master for CiA 402 drives (ETG.1000.4/.6, ETG.6010): it finds the slaves on a line,
// addresses them, reads their SII, sets up the mailbox, learns the PDO mapping over CoE (falling
// back to the SII's default PDOs), maps the process data with FMMUs, brings the line to OP and then
// runs a cyclic LRW carrying each drive's control word out and its status word back. It carries
// words and steers nothing: the axis session steers a drive through them (ethercat/axis's
// ecat_link). SDO upload and download over the mailbox for everything else.
//
// It is written for real drives, not only ours: every layout comes from what a slave says about
// itself (SII sync managers and mailbox, 0x1C12/0x1C13 and the PDOs they assign), 0x6040 and 0x6041
// are found wherever the mapping puts them, AL status codes are read and reported, and a slave
// that answers late is polled until a time limit rather than assumed ready.
//
// Distributed clocks (ETG.1000.4 §9.1, ETG.1020 §5.3), when the drives offer them (ESC features
// 0x0008 bit 2), on the way to SAFE-OP: receive times latched by a BWR to 0x0900, the propagation
// delay of each from the port time spans of a line (ETG.1000.4's method), offsets making the first
// DC slave's clock the system time, a static drift distribution (FRMW of 0x0910, 16 times), then
// SYNC0 at the master's cycle on every DC slave whose 0x1C32:05 (minimum cycle time) allows that
// cycle (the others run free), starting on a cycle boundary after twice the time the set-up took
// and two cycles, so every slave is activated before the first pulse. Each cycle's frame then
// carries the drift distribution (FRMW of the reference clock's 0x0910).
//
// The master never reads a clock: time comes from the link (`now_us`, `wait_us`), so the same code
// runs on a raw socket (src/apps) and on the in-process wire of the tests on virtual time.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cia402/ethercat/coe/sdo.hpp"
#include "cia402/ethercat/coe/sdo_information.hpp"
#include "cia402/ethercat/esc/frame.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "cia402/master.hpp"
#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402::ethercat {

/// What carries a master's frames to the line and back, and its sense of time.
class master_link {
 public:
  virtual ~master_link() = default;
  /// Sends `frame` and replaces it with the frame the line returned; false when none came back
  /// within the link's time limit (the frame is then unchanged).
  virtual bool exchange(std::vector<std::uint8_t>& frame) = 0;
  /// Microseconds since a fixed start.
  virtual std::uint64_t now_us() = 0;
  /// Lets `us` microseconds pass: a sleep on a real line, the drives' time on an in-process one.
  virtual void wait_us(std::uint32_t us) = 0;
};

/// AL states as register 0x0130 shows them (bits 0..3).
enum class line_state : std::uint8_t { init = 1, pre_operational = 2, bootstrap = 3, safe_operational = 4, operational = 8 };
const char* line_state_name(std::uint8_t al_state) noexcept;
/// The text of an AL status code (0x0134), "unknown AL status code" for others.
const char* al_status_code_text(std::uint16_t code) noexcept;

/// Where an object sits in a slave's process data.
struct pdo_place {
  std::uint16_t bit_offset = 0;
  std::uint8_t bits = 0;
};

/// One slave as the master found and configured it.
struct ecat_slave {
  std::uint16_t position = 0;   ///< 0 for the first slave after the master
  std::uint16_t station = 0;    ///< the configured station address the master gave it
  slave_description sii;        ///< identity, mailbox and sync managers, default PDOs, from its SII
  bool mailbox = false;         ///< it has a CoE mailbox the master set up
  std::uint8_t mailbox_counter = 0;
  std::uint16_t output_bytes = 0;
  std::uint16_t input_bytes = 0;
  std::uint32_t logical_outputs = 0;  ///< its outputs' logical address in the LRW
  std::uint32_t logical_inputs = 0;
  std::optional<pdo_place> control_word, status_word, error_code, position_actual, velocity_actual, mode_display;
  /// Every object of its outputs and inputs, in order (padding has index 0).
  struct mapped_object {
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    std::uint8_t bits = 0;
    std::uint16_t bit_offset = 0;
  };
  std::vector<mapped_object> outputs, inputs;
  std::string mapping_source;   ///< "CoE 0x1C12/0x1C13" or "SII default PDOs"
  std::uint8_t al_state = 0;    ///< the last AL status read (bits 0..3; bit 4 = error)
  std::uint16_t al_code = 0;
  std::uint16_t last_status = 0;   ///< 0x6041 as the last cycle brought it
  std::uint16_t last_control = 0;  ///< 0x6040 as every cycle sends it (send_control_word)
  std::uint16_t last_error_code = 0;
  std::vector<std::uint16_t> emergencies;  ///< error codes of the EMCYs the mailbox brought
  bool dc = false;              ///< its ESC has distributed clocks (0x0008 bit 2)
  bool sync0 = false;           ///< the master started its SYNC0 at the master's cycle
  std::uint32_t dc_delay_ns = 0;  ///< propagation delay from the reference clock (0x0928)
};

/// An SDO transfer's result.
struct ecat_sdo_result {
  bool ok = false;
  bool aborted = false;                  ///< the slave answered with an SDO abort
  sdo_abort abort = sdo_abort::general_error;  ///< when the slave aborted
  std::string error;                     ///< when there was no SDO answer at all (why)
  std::vector<std::uint8_t> data;        ///< an upload's bytes
  std::int64_t value(bool is_signed) const noexcept;
};

/// An entry as a slave's SDO information describes it (ETG.1000.6 §5.6.3): its CiA 301 data type,
/// bit length, object access word (bits 0..2 read, 3..5 write in PRE-OP / SAFE-OP / OP, 6 RxPDO, 7
/// TxPDO mappable) and name.
struct ecat_entry_description {
  std::uint8_t sub = 0;
  std::uint16_t data_type = 0;
  std::uint16_t bit_length = 0;
  std::uint16_t access = 0;
  std::string name;
};
/// An object as the slave's SDO information describes it, with the entries it has.
struct ecat_object_description {
  std::uint16_t index = 0;
  std::uint16_t data_type = 0;
  std::uint8_t max_sub = 0;
  std::uint8_t object_code = 0;  ///< 7 VAR, 8 ARRAY, 9 RECORD
  std::string name;
  std::vector<ecat_entry_description> entries;  ///< sub-indices 0..max_sub the slave has
};
struct ecat_dictionary_result {
  bool ok = false;
  std::string error;  ///< why not (the request, the slave and its SDO information error)
  std::vector<ecat_object_description> objects;
};

class ecat_master {
 public:
  /// `p` (outliving the master) is the drives' profile; the master itself reads no state from a
  /// status word (drive_profile() gives it to whoever does).
  ecat_master(master_link& link, const profile& p, std::uint32_t cycle_us = 1000);

  /// Counts the slaves (BRD), resets them to INIT, gives each the station address 0x1001 + position
  /// and reads its SII. False, with error(), when no slave answers or a SII cannot be read.
  bool scan();
  /// PRE-OP: the mailbox sync managers as the SII says; SDO works from here (a tool may change the
  /// PDO mapping now, before bring_to_operational reads it).
  bool bring_to_pre_operational();
  /// PRE-OP if not yet, the PDO mapping (CoE, else SII), process data
  /// sync managers and FMMUs, SAFE-OP, then OP with the cyclic exchange running. False with error()
  /// (including the slave's AL status code) when a slave refuses or does not get there in time.
  bool bring_to_operational();
  /// Every slave from OP back to PRE-OP (the cycle stops first): how a master leaves the line when
  /// it is done. False with error() when a slave does not get there.
  bool leave_operational();
  /// One cycle: the LRW of every slave's process data (each control word out, each status word
  /// back) and each AL status. False when the frame did not come back or the working counter was
  /// short (the cycle still counts; error() says which), and, sending nothing, when no bring-up to
  /// OP has configured the process data since the last scan or PRE-OP.
  bool cycle();

  /// Sends this control word to drive `i` (index into slaves()) every cycle from now on.
  void send_control_word(std::size_t i, std::uint16_t word);

  /// An input object as the last cycle brought it (signed where the CiA 402 object table says so);
  /// nothing when drive `i` does not map it.
  std::optional<std::int64_t> input(std::size_t i, std::uint16_t index, std::uint8_t sub = 0) const;
  /// Puts a value into an output object the drive maps, sent from the next cycle on; false (and
  /// nothing changed) when it maps no such object.
  bool set_output(std::size_t i, std::uint16_t index, std::int64_t value, std::uint8_t sub = 0);
  /// Whether every slave shows OP (as the last cycle or status read saw it).
  bool all_operational() const noexcept;

  /// SDO transfers with slave `i` (an error result, not an exception, for one the line does not have),
  /// through the CoE codec (ethercat/coe): expedited, normal or segmented as the value's length needs,
  /// so an object longer than a mailbox (a string, a DCF's value) goes in segments. An upload longer
  /// than max_sdo_upload bytes is refused with the size the slave announced.
  static constexpr std::size_t max_sdo_upload = 65536;
  ecat_sdo_result sdo_read(std::size_t i, std::uint16_t index, std::uint8_t sub);
  /// `bytes` (1..4) of `value`, expedited.
  ecat_sdo_result sdo_write(std::size_t i, std::uint16_t index, std::uint8_t sub, std::int64_t value, unsigned bytes);
  /// Any number of bytes: expedited up to 4, else a normal download with segments for what the first
  /// mailbox does not hold.
  ecat_sdo_result sdo_write_bytes(std::size_t i, std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data);
  /// Slave `i`'s object dictionary through CoE SDO information (ETG.1000.6 §5.6.3): the list of all
  /// objects, each object's description and each of its entries' (a sub-index the slave says it
  /// lacks is left out). Each reply's fragments are taken in order, at most max_sdo_upload bytes.
  ecat_dictionary_result read_dictionary(std::size_t i);

  std::vector<ecat_slave>& slaves() noexcept { return slaves_; }
  const std::vector<ecat_slave>& slaves() const noexcept { return slaves_; }
  const std::string& error() const noexcept { return error_; }
  std::uint16_t expected_working_counter() const noexcept { return expected_wkc_; }
  std::uint16_t last_working_counter() const noexcept { return last_wkc_; }
  std::uint64_t cycles() const noexcept { return cycles_; }
  std::uint64_t lost_frames() const noexcept { return lost_frames_; }
  std::uint32_t cycle_us() const noexcept { return cycle_us_; }
  const profile& drive_profile() const noexcept { return *profile_; }
  /// The slave whose clock is the system time, when the line has distributed clocks.
  std::optional<std::size_t> dc_reference() const noexcept { return dc_reference_; }
  /// Called with every frame exchanged (sent, then answered), for captures.
  std::function<void(const std::vector<std::uint8_t>& sent, const std::vector<std::uint8_t>& answered)> on_frame;

 private:
  struct single {
    bool ok = false;
    std::uint16_t wkc = 0;
    std::vector<std::uint8_t> data;
  };
  single one(command cmd, std::uint32_t address, std::vector<std::uint8_t> data);
  single read_register(const ecat_slave& s, std::uint16_t reg, std::uint16_t length);
  bool write_register(const ecat_slave& s, std::uint16_t reg, const std::vector<std::uint8_t>& data);
  bool read_sii(ecat_slave& s);
  bool read_al_status(ecat_slave& s);
  bool request_state(line_state target, bool cycling);
  bool configure_mailbox(ecat_slave& s);
  bool learn_mapping(ecat_slave& s);
  bool configure_process_data(ecat_slave& s, std::uint32_t& logical);
  bool configure_distributed_clocks();
  bool start_sync0();
  /// `answered`, when given, is set once any frame of the attempt came back.
  bool mailbox_send(ecat_slave& s, const std::vector<std::uint8_t>& coe, bool* answered = nullptr);
  std::optional<std::vector<std::uint8_t>> mailbox_receive(ecat_slave& s);
  bool request_mailbox_repeat(ecat_slave& s);
  // The slave `i` names, with its CoE mailbox, or an error in `result`.
  ecat_slave* sdo_slave(std::size_t i, ecat_sdo_result& result);
  // Sends one SDO request (a mailbox's CoE data) and waits for the answer of kind `expected` (for an
  // initiate, of index:sub), noting emergencies on the way. The answer's data points into `reply`.
  std::optional<sdo_frame> sdo_exchange(ecat_slave& s, const std::vector<std::uint8_t>& request, std::uint16_t index,
                                        std::uint8_t sub, sdo_command expected, std::vector<std::uint8_t>& reply,
                                        ecat_sdo_result& result);
  // The upload segments after a normal upload response, until the value is whole.
  bool upload_segments(ecat_slave& s, std::uint16_t index, std::uint8_t sub, const sdo_frame& first,
                       ecat_sdo_result& result);
  // One SDO information request and its whole answer (every fragment, in order) of kind
  // `expected`; nothing, with `error` saying why (and `code` the slave's, on an error reply), on an
  // error reply or a broken answer.
  std::optional<std::vector<std::uint8_t>> sdo_info_exchange(ecat_slave& s, sdo_info_opcode request,
                                                             std::span<const std::uint8_t> data,
                                                             sdo_info_opcode expected, std::string& error,
                                                             std::uint32_t& code);
  // Ends a transfer the slave got wrong: the abort to the slave, the reason in `result`.
  void give_up(ecat_slave& s, std::uint16_t index, std::uint8_t sub, sdo_abort code, std::string why,
               ecat_sdo_result& result);
  // An emergency a mailbox the master read brought, kept with the slave.
  static void note_emergency(ecat_slave& s, std::span<const std::uint8_t> mailbox);
  bool fail(std::string text);
  // Forgets the process image: no cycle runs until bring_to_operational() builds the next.
  void stop_cycling();
  // Waits `us` (0: not at all), running a cycle first when one is due: set-up and SDO transfers
  // keep the process data flowing once it is configured.
  void pause(std::uint32_t us);

  master_link* link_;
  const profile* profile_;
  std::uint32_t cycle_us_;
  std::vector<ecat_slave> slaves_;
  std::vector<std::uint8_t> image_;  // the logical process image, outputs and inputs of every slave
  // The image as the cycle's LRWs carry it: runs of whole slaves, each within one frame (the first
  // beside the cycle's other datagrams), each with the working counter its slaves owe.
  struct image_part {
    std::size_t offset = 0;
    std::size_t length = 0;
    std::uint16_t wkc = 0;
  };
  std::vector<image_part> parts_;
  bool exchange_part(const image_part& part, std::vector<std::uint8_t>& back, std::uint16_t& wkc,
                     std::string& wrong);
  std::uint16_t expected_wkc_ = 0;
  std::uint16_t last_wkc_ = 0;
  std::uint64_t cycles_ = 0;
  std::uint64_t lost_frames_ = 0;
  std::uint8_t index_ = 0;
  bool pre_operational_ = false;
  bool line_was_operational_ = false;  // the last cycle's BRD of the AL status read OP
  bool cycling_ = false;       // the process data is configured: cycles run, also during SDOs
  bool in_mailbox_ = false;    // an SDO transfer owns the send mailboxes
  std::uint64_t last_cycle_us_ = 0;
  std::optional<std::size_t> dc_reference_;
  std::string error_;
};

}  // namespace cia402::ethercat
