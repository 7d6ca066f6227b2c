// An EtherCAT CoE slave around a device (dictionary/device.hpp): an emulated controller (esc), the
// application behind it (the AL state machine, CoE mailboxes, process data) and the device's part of
// the dictionary, to which it adds the objects of CoE's communication area (ETG.1000.6): 0x1003
// (CiA 301's pre-defined error field: the last 8 emergencies, dictionary/error_history.hpp), 0x1600 /
// 0x1601 RxPDO and 0x1A00 / 0x1A01 TxPDO mappings, 0x1C00 sync manager types, 0x1C12 / 0x1C13 PDO
// assignment, and 0x1017 (producer heartbeat time: stored and acting on nothing, EtherCAT has no
// heartbeat, so a master that writes it on every bus is not refused). It knows no device profile:
// the SII and ESI (description()) say what the device's 0x1000, 0x1008 and 0x1018 say. A master
// reaches it only through frames on a wire (the in-process `chain`, or a network interface).
//
// AL state machine (ETG.1000.6 §6.4): INIT -> PRE-OP needs SM0/SM1 as the SII describes them (else
// 0x0016 invalid mailbox configuration); PRE-OP -> SAFE-OP needs every assigned PDO entry to name an
// object (else 0x0025 invalid output mapping / 0x0024 invalid input mapping) and SM2/SM3 as long as
// the assigned PDOs and configured as outputs / inputs (0x001D / 0x001E), and a sync mode it can run
// (below); SAFE-OP -> OP; any state
// back down; BOOT is refused (0x0013); an unknown or skipped state is refused (0x0011 / 0x0012). A
// refusal keeps the state, sets the error flag (0x0130 bit 4) and the code, until the master
// acknowledges it (0x0120 bit 4); until then every request but INIT (which acknowledges by itself,
// as the ETG's slave code takes it) is ignored: the state, the flag and the code stay. In OP the process data watchdog guards the outputs: when it
// expires the slave falls to SAFE-OP with 0x001B and tells the device its connection is lost, so a
// CiA 402 drive applies 0x6007 (S10).
//
// Process data: each assigned PDO entry is bound once, on the way to SAFE-OP (as SOES fills its sync
// manager maps then), to its dictionary slot, bit offset, length and sign. Each cycle then copies
// bytes between those slots and the sync managers' buffers, with no lookup and no allocation: in
// OP the outputs (SM2) when a whole buffer arrived, before the device's step, and in SAFE-OP and OP
// the inputs (SM3) every cycle after it, so a master reads the state its outputs brought. A
// value the outputs carry goes through the dictionary's rules as an SDO write does
// (dictionary_access). PDO mappings and assignments are written in PRE-OP only (0x08000022
// otherwise), and only with objects that are PDO mappable the right way, of their own length and
// within the process data room; an entry of 0 bits, or a count that takes in an entry left empty, is
// refused (0x06040041). Padding maps either way (pdo_maps.hpp, pdo_padding): an index-0 gap of 1..64
// bits (ETG's convention, KickCAT's default) and a CiA 301 dummy (0x0001..0x0007, sub 0, its type's
// length, 1 bit for BOOLEAN; another length is 0x06040041). It binds nothing: the outputs' padding
// bits are skipped, the inputs' sent as zeros, and it counts in the process data's length.
//
// Sync managers changed under a state that checked them take the slave back (with the error flag):
// SM0/SM1 in PRE-OP or above to INIT (0x0016), SM2/SM3 in SAFE-OP or OP to PRE-OP (0x001D / 0x001E).
// The application moves process data through the controller's buffers only, never into registers.
//
// Synchronisation (ETG.1020 §5.3, as the ETG's slave code takes it): on the way to SAFE-OP, SYNC0
// activated by the master (0x0981) means DC SYNC0 mode, and 0x1C32:01 / 0x1C33:01 say so; a mode of
// DC SYNC0 written without SYNC0 running is refused (0x0030), a SYNC0 cycle below 0x1C32:05 too
// (0x0035). In DC SYNC0 mode the outputs go to the device on each SYNC0 pulse (the newest whole buffer),
// not when they arrive; a pulse that finds no new outputs in OP counts in 0x1C32:0B. Free run and
// SM-synchronous take the outputs when they arrive. In DC SYNC0 mode SAFE-OP to OP waits for the
// first pulse (the AL status stays SAFE-OP, no error), because until then the drive would be in OP
// taking no outputs; the pulse enters OP and applies that pulse's outputs. No pulse within
// first_pulse_wait_us refuses OP with 0x002D (no sync error).
//
// Mailbox repeat (ETG.1000.4, as the ETG's slave code answers it): a master that lost a reply
// toggles SM1's repeat request; the slave puts the reply the master read last back into SM1 (a newer
// one waiting unread there is taken back first, by deactivating SM1 through its PDI control, and
// sent after it) and toggles the repeat acknowledge.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cia402/dictionary/device.hpp"
#include "cia402/dictionary/dictionary_access.hpp"
#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "cia402/ethercat/slave/coe_server.hpp"
#include "cia402/pdo_maps.hpp"

namespace cia402::ethercat {

/// AL status codes (ETG.1000.6 table 11) this slave gives.
namespace al_code {
inline constexpr std::uint16_t none = 0x0000;
inline constexpr std::uint16_t invalid_state_change = 0x0011;
inline constexpr std::uint16_t unknown_state = 0x0012;
inline constexpr std::uint16_t bootstrap_not_supported = 0x0013;
inline constexpr std::uint16_t invalid_mailbox_configuration = 0x0016;
inline constexpr std::uint16_t sync_manager_watchdog = 0x001B;
inline constexpr std::uint16_t invalid_output_configuration = 0x001D;
inline constexpr std::uint16_t invalid_input_configuration = 0x001E;
inline constexpr std::uint16_t invalid_input_mapping = 0x0024;
inline constexpr std::uint16_t invalid_output_mapping = 0x0025;
inline constexpr std::uint16_t invalid_dc_sync_configuration = 0x0030;
inline constexpr std::uint16_t no_sync = 0x002D;  ///< ETG.1000.6: no SYNC0 pulse came
inline constexpr std::uint16_t invalid_dc_sync_cycle_time = 0x0035;
}  // namespace al_code

/// 0x1C32 / 0x1C33 (ETG.1020 §5.3): sub-indices, sync modes, what this slave offers.
namespace sync_parameter {
inline constexpr std::uint16_t outputs = 0x1C32;
inline constexpr std::uint16_t inputs = 0x1C33;
inline constexpr std::uint8_t mode = 1;
inline constexpr std::uint8_t cycle_time = 2;
inline constexpr std::uint8_t supported = 4;
inline constexpr std::uint8_t minimum_cycle_time = 5;
inline constexpr std::uint8_t sync0_cycle_time = 10;
inline constexpr std::uint8_t sync_error_count = 11;  ///< SYNC0 pulses that found no new outputs, in OP
/// Bit 0 free run, bit 1 SM-synchronous, bits 2..3 = 01 DC SYNC0.
inline constexpr std::int64_t supported_modes = 0x0007;
}  // namespace sync_parameter
namespace sync_mode {
inline constexpr std::int64_t free_run = 0x00;
inline constexpr std::int64_t sm_synchronous = 0x01;   ///< outputs: SM2 event; inputs: SM3 event
inline constexpr std::int64_t dc_sync0 = 0x02;
inline constexpr std::int64_t sm2_synchronous = 0x22;  ///< inputs only: with the SM2 event
}  // namespace sync_mode

/// Memory: SM0 (mailbox out) 0x1000, 128 bytes; SM1 (mailbox in) 0x1080, 128 bytes; SM2 (outputs)
/// 0x1100; SM3 (inputs) 0x1180; each process data SM as long as its assigned PDOs.
inline constexpr std::uint16_t mailbox_out_start = 0x1000;
inline constexpr std::uint16_t mailbox_in_start = 0x1080;
inline constexpr std::uint16_t mailbox_size = 128;
inline constexpr std::uint16_t outputs_start = 0x1100;
inline constexpr std::uint16_t inputs_start = 0x1180;
/// Most bytes a process data SM may take (the room between SM2 and SM3, and after SM3).
inline constexpr std::uint16_t max_process_data = 0x80;
/// Entries a PDO mapping object holds.
inline constexpr int max_pdo_entries = 12;
/// How long an OP request in DC SYNC0 mode waits for the first SYNC0 pulse before it is refused
/// with 0x002D: ten times the 100 ms SOEM's ec_dcsync0 puts the first pulse ahead of now.
inline constexpr std::uint32_t first_pulse_wait_us = 1'000'000;

struct coe_slave_config {
  /// The device's objects: its identity (0x1000, 0x1008, 0x1018 ...), its profile's objects, its own.
  /// The slave adds its communication objects (coe_communication_objects()).
  std::vector<dictionary::object_entry> objects;
  /// RxPDO 0x1600 and TxPDO 0x1A00 as they start, assigned by 0x1C12 / 0x1C13; 0x1601 and 0x1A01
  /// start empty and unassigned.
  pdo_map rx_pdo{};
  pdo_map tx_pdo{};
  /// What the SII and ESI name besides the dictionary's identity.
  std::string vendor_name;
  std::string group_name;
  /// The application's cycle (the time each step() is given): the shortest SYNC0 cycle the slave
  /// takes (0x1C32:05 / 0x1C33:05), since a pulse more often would find it still in the last one.
  std::uint32_t application_cycle_us = 1000;
};

/// The objects the slave serves itself: 0x1003, 0x1017, 0x1600, 0x1601, 0x1A00, 0x1A01, 0x1C00, 0x1C12,
/// 0x1C13, 0x1C32, 0x1C33.
std::vector<dictionary::object_entry> coe_communication_objects(const coe_slave_config& c);
/// The whole table of a slave of configuration `c`, by index. Throws std::invalid_argument when the
/// device's objects hold one of the slave's own.
std::vector<dictionary::object_entry> coe_objects(const coe_slave_config& c);
/// The SII / ESI description of a slave of configuration `c`: identity and names from its 0x1018,
/// 0x1008 and 0x1000 (the device profile number), the PDOs 0x1C12 / 0x1C13 assign by default with their
/// entries' names and types, mailbox and sync manager layout.
slave_description coe_slave_description(const coe_slave_config& c);

class coe_slave final : private dictionary::dictionary_access, private dictionary::device_events {
 public:
  /// The device must outlive the slave; the slave attaches itself to its reports until destroyed.
  /// Throws std::invalid_argument as coe_objects() does.
  coe_slave(dictionary::device& d, const coe_slave_config& c);
  ~coe_slave();
  coe_slave(const coe_slave&) = delete;
  coe_slave& operator=(const coe_slave&) = delete;

  esc& controller() noexcept { return esc_; }
  /// The application's cycle: AL requests, mailboxes, the outputs to the device, `elapsed_us` of the
  /// device, the inputs from it (so they answer this cycle's outputs, as SOES runs its application
  /// between the two), then `elapsed_us` of the controller and the watchdog.
  void step(std::uint32_t elapsed_us);
  /// The controller's clock kept by whoever hosts the slave (the host's clock to the nanosecond,
  /// esc::advance before every frame), not by step(), which then runs the application only.
  void keep_clock_outside() noexcept { clock_outside_ = true; }
  al_state state() const noexcept { return state_; }
  const slave_description& description() const noexcept { return description_; }
  const dictionary::object_dictionary& dictionary() const noexcept { return od_; }
  /// Bytes of the assigned RxPDOs (outputs) and TxPDOs (inputs) as the dictionary has them now.
  std::uint16_t output_bytes() const noexcept;
  std::uint16_t input_bytes() const noexcept;

 private:
  /// One PDO entry bound on the way to SAFE-OP.
  struct bound_entry {
    dictionary::object_dictionary::slot* slot = nullptr;
    std::uint16_t bit_offset = 0;
    std::uint8_t bits = 0;
    bool is_signed = false;
  };
  unsigned assigned_bits(std::uint16_t assignment) const noexcept;
  bool bind(std::uint16_t assignment, std::vector<bound_entry>& out, unsigned& bits);
  void handle_al_control();
  bool to_safe_operational();
  bool choose_sync_mode();
  sdo_abort write_sync_mode(dictionary::object_dictionary::slot& s, std::int64_t v);
  void refuse(std::uint16_t code);
  void enter(al_state s);
  bool mailbox_sync_managers_sound() const;
  bool process_data_sync_manager_sound(int n, std::uint16_t bytes, bool outputs) const;
  bool entry_mappable(std::uint16_t mapping, std::uint32_t entry) const;
  sdo_abort write_pdo_configuration(dictionary::object_dictionary::slot& s, std::int64_t v);
  void watch_sync_managers();
  // The cycle's process data, either side of the device's step: the outputs (SM2) to the device in
  // OP, then the inputs (SM3) from it in SAFE-OP and OP.
  void outputs_in();
  void inputs_out();
  void serve_mailbox();
  void send_reply(std::vector<std::uint8_t>& reply);
  void repeat_last_reply();
  void send_next_as_last_read();

  // dictionary_access
  sdo_abort read_value(const dictionary::object_dictionary::slot& s, std::int64_t& v) override;
  sdo_abort write_value(dictionary::object_dictionary::slot& s, std::int64_t v) override;
  // device_events
  void object_changed(std::uint16_t, std::uint8_t) noexcept override {}
  void error_changed(std::uint16_t code) noexcept override;

  dictionary::device* device_;
  dictionary::object_dictionary od_;
  slave_description description_;
  esc esc_;
  coe_server coe_;
  al_state state_ = al_state::init;
  bool error_ = false;
  std::uint16_t code_ = al_code::none;
  // SM2 and SM3 as the way to SAFE-OP found them sound: the only layout process data moves through.
  esc::sync_manager outputs_checked_{};
  esc::sync_manager inputs_checked_{};
  // The assigned PDOs' entries as SAFE-OP bound them, and their lengths in bits.
  std::vector<bound_entry> outputs_;
  std::vector<bound_entry> inputs_;
  unsigned output_bits_ = 0;
  unsigned input_bits_ = 0;
  // DC SYNC0 mode, as chosen on the way to SAFE-OP: outputs go to the device on a SYNC0 pulse.
  bool dc_sync0_ = false;
  bool outputs_waiting_ = false;  // outputs arrived since the last pulse
  bool pulse_seen_ = false;       // a SYNC0 pulse came since DC SYNC0 mode was chosen
  bool clock_outside_ = false;    // step() leaves the controller's clock alone
  // An OP request in DC SYNC0 mode that waits for the first pulse, and for how long it has waited.
  bool op_waits_for_pulse_ = false;
  std::uint32_t op_wait_us_ = 0;
  std::vector<std::uint8_t> mailbox_;  // the last request SM0 brought (its room kept across cycles)
  // Mailbox repeat (ETG.1000.4): the reply SM1 holds unread, the one the master read last (which a
  // repeat request puts back), and one taken back from SM1 for a repeat, which goes out next.
  std::vector<std::uint8_t> in_send_mailbox_;
  std::vector<std::uint8_t> last_read_;
  std::vector<std::uint8_t> withdrawn_;
  // SM1 holds a reply put back by a repeat request; SM1 holds last_read_ itself (a repeat request
  // then only acknowledges).
  bool repeat_in_send_mailbox_ = false;
  bool last_read_in_send_mailbox_ = false;
};

}  // namespace cia402::ethercat
