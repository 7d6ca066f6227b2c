// The virtual CiA 402 drive as an EtherCAT slave: an emulated controller (esc), the application
// behind it (the AL state machine, CoE mailboxes, process data) and the simulator's drive. A master
// reaches it only through frames on a wire (the in-process `chain`, or a network interface).
//
// AL state machine (ETG.1000.6 §6.4): INIT -> PRE-OP needs SM0/SM1 as the SII describes them
// (else 0x0016 invalid mailbox configuration); PRE-OP -> SAFE-OP needs SM2/SM3 as long as the
// assigned PDOs and configured as outputs / inputs (0x001D / 0x001E); SAFE-OP -> OP; any state back
// down; BOOT is refused (0x0013); an unknown or skipped state is refused (0x0011 / 0x0012). A refusal
// keeps the state, sets the error flag (0x0130 bit 4) and the code, until the master acknowledges
// it (0x0120 bit 4). In OP the process data watchdog guards the outputs: when it expires the drive
// falls to SAFE-OP with 0x001B and its fieldbus connection counts as lost, so 0x6007 acts (S10).
//
// Process data: in SAFE-OP and OP the inputs (SM3) carry the assigned TxPDOs' objects every cycle;
// in OP the outputs (SM2) are written to the drive when a whole buffer arrived. PDO mappings and
// assignments are written in PRE-OP only (0x08000022 otherwise), and only with objects that are PDO
// mappable the right way and fit the process data room; an entry of 0 bits, or a count that takes
// in an entry left empty, is refused (0x06040041).
//
// Sync managers changed under a state that checked them take the slave back (with the error flag):
// SM0/SM1 in PRE-OP or above to INIT (0x0016), SM2/SM3 in SAFE-OP or OP to PRE-OP (0x001D / 0x001E).
// The application moves process data through the controller's buffers only, never into registers.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "cia402/canopen/301/device.hpp"
#include "cia402/canopen/301/dictionary_access.hpp"
#include "cia402/canopen/301/object_dictionary.hpp"
#include "cia402/drive402/sim_device.hpp"
#include "cia402/ethercat/coe/mailbox.hpp"
#include "cia402/ethercat/esc/esc.hpp"
#include "cia402/ethercat/sii/slave_information.hpp"
#include "cia402/profile.hpp"

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
}  // namespace al_code

class drive_slave final : private canopen::dictionary_access, private canopen::device_events {
 public:
  /// `serial` goes into 0x1018 sub 4 and the SII (the slave's position, say, so drives differ).
  explicit drive_slave(const profile& p, std::uint32_t serial = 0, const sim::plant_config& plant = {});
  ~drive_slave();
  drive_slave(const drive_slave&) = delete;
  drive_slave& operator=(const drive_slave&) = delete;

  esc& controller() noexcept { return esc_; }
  /// The application's cycle: AL requests, mailboxes, process data, then `elapsed_us` of the drive
  /// and of the watchdog.
  void step(std::uint32_t elapsed_us);
  al_state state() const noexcept { return state_; }
  drive402::sim_device& device() noexcept { return device_; }
  const slave_description& description() const noexcept { return description_; }
  /// Bytes of the assigned RxPDOs (outputs) and TxPDOs (inputs) as the dictionary has them now.
  std::uint16_t output_bytes() const noexcept;
  std::uint16_t input_bytes() const noexcept;

 private:
  struct mapped {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint8_t bits;
  };
  std::vector<mapped> mapping(std::uint16_t assignment) const;
  void handle_al_control();
  void refuse(std::uint16_t code);
  void enter(al_state s);
  bool mailbox_sync_managers_sound() const;
  bool process_data_sync_manager_sound(int n, std::uint16_t bytes, bool outputs) const;
  bool entry_mappable(std::uint16_t mapping, std::uint32_t entry) const;
  static bool same(const esc::sync_manager& a, const esc::sync_manager& b) noexcept;
  void watch_sync_managers();
  void exchange_process_data();
  void serve_mailbox();

  // dictionary_access
  sdo_abort read_value(const canopen::object_dictionary::slot& s, std::int64_t& v) override;
  sdo_abort write_value(canopen::object_dictionary::slot& s, std::int64_t v) override;
  // device_events
  void object_changed(std::uint16_t, std::uint8_t) noexcept override {}
  void error_changed(std::uint16_t code) noexcept override;

  canopen::object_dictionary od_;
  drive402::sim_device device_;
  slave_description description_;
  esc esc_;
  coe_server coe_;
  al_state state_ = al_state::init;
  bool error_ = false;
  std::uint16_t code_ = al_code::none;
  // SM2 and SM3 as the way to SAFE-OP found them sound: the only layout process data moves through.
  esc::sync_manager outputs_checked_{};
  esc::sync_manager inputs_checked_{};
};

}  // namespace cia402::ethercat
