// An EtherCAT slave controller (ESC) in software: the register space and process RAM a master
// reads and writes with datagrams, as an ET1100-class controller has them, and the side a slave's
// application (its "PDI") sees. What the controller does by itself lives here: addressing and
// working counters, the configured station address, FMMUs mapping logical to physical memory at
// bit granularity, sync managers (mailbox hand-over; buffered process data), the SII EEPROM
// interface, DL status, the process data watchdog. What a slave decides (the AL state machine, what
// a mailbox means, process data contents) is the application's: it reads the events this
// controller raises and answers through the PDI calls.
//
// Memory: registers 0x0000..0x0FFF, process RAM 0x1000..0x1FFF (4 KiB). No distributed clocks: the
// ESC features register (0x0008) and the SII say so, so masters skip them. Buffered (three-buffer)
// sync managers: frames and the application's cycle alternate in one thread here, so the master
// always sees a whole buffer the application wrote, and the application a whole buffer a frame
// wrote; the status register reports buffer changes as a real ESC does.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cia402/ethercat/esc/frame.hpp"

namespace cia402::ethercat {

/// Register addresses (ET1100 datasheet section II).
namespace reg {
inline constexpr std::uint16_t type = 0x0000;
inline constexpr std::uint16_t revision = 0x0001;
inline constexpr std::uint16_t build = 0x0002;
inline constexpr std::uint16_t fmmus_supported = 0x0004;
inline constexpr std::uint16_t sync_managers_supported = 0x0005;
inline constexpr std::uint16_t ram_size = 0x0006;  ///< KiB
inline constexpr std::uint16_t port_descriptor = 0x0007;
inline constexpr std::uint16_t features = 0x0008;
inline constexpr std::uint16_t station_address = 0x0010;
inline constexpr std::uint16_t station_alias = 0x0012;
inline constexpr std::uint16_t dl_control = 0x0100;
inline constexpr std::uint16_t dl_status = 0x0110;
inline constexpr std::uint16_t al_control = 0x0120;
inline constexpr std::uint16_t al_status = 0x0130;
inline constexpr std::uint16_t al_status_code = 0x0134;
inline constexpr std::uint16_t pdi_control = 0x0140;
inline constexpr std::uint16_t event_mask = 0x0200;
inline constexpr std::uint16_t event_request = 0x0210;
inline constexpr std::uint16_t rx_errors = 0x0300;
inline constexpr std::uint16_t watchdog_divider = 0x0400;
inline constexpr std::uint16_t watchdog_time_pdi = 0x0410;
inline constexpr std::uint16_t watchdog_time_process_data = 0x0420;
inline constexpr std::uint16_t watchdog_status_process_data = 0x0440;
inline constexpr std::uint16_t watchdog_counter_process_data = 0x0442;
inline constexpr std::uint16_t eeprom_config = 0x0500;
inline constexpr std::uint16_t eeprom_control = 0x0502;
inline constexpr std::uint16_t eeprom_address = 0x0504;
inline constexpr std::uint16_t eeprom_data = 0x0508;
inline constexpr std::uint16_t fmmu0 = 0x0600;   ///< 16 bytes each
inline constexpr std::uint16_t sync_manager0 = 0x0800;  ///< 8 bytes each
inline constexpr std::uint16_t dc_receive_time = 0x0900;
inline constexpr std::uint16_t process_ram = 0x1000;
}  // namespace reg

/// AL states as register 0x0130 holds them (bit 4: error indication).
enum class al_state : std::uint8_t { init = 1, pre_operational = 2, bootstrap = 3, safe_operational = 4, operational = 8 };

class esc {
 public:
  static constexpr std::size_t memory_size = 0x2000;
  static constexpr int fmmu_count = 8;
  static constexpr int sync_manager_count = 8;

  /// `eeprom` is the SII image the EEPROM interface serves (sii_image()); the configured station
  /// alias is loaded from its word 4, as a real ESC does at power-on.
  explicit esc(std::vector<std::uint8_t> eeprom);

  // ---- the EtherCAT side ---------------------------------------------------------------------

  /// One datagram passing this controller: data read or written, the working counter raised for
  /// what it did, ADP incremented for auto-increment and broadcast commands.
  void process(datagram& d) noexcept;
  /// Every datagram of a parsed frame, in order.
  void process(parsed_frame& f) noexcept {
    for (std::size_t i = 0; i < f.count; ++i) process(f.datagrams[i]);
  }
  /// Time passes (virtual): the process data watchdog runs down.
  void advance(std::uint64_t ns) noexcept;

  // ---- the application (PDI) side ------------------------------------------------------------

  std::uint8_t read8(std::uint16_t address) const noexcept;
  std::uint16_t read16(std::uint16_t address) const noexcept;
  std::uint32_t read32(std::uint16_t address) const noexcept;
  /// PDI writes: any register the application owns (AL status and code, process RAM, ...).
  void write8(std::uint16_t address, std::uint8_t v) noexcept;
  void write16(std::uint16_t address, std::uint16_t v) noexcept;
  /// The present AL status and code, as the application sets them.
  void set_al_status(std::uint8_t status, std::uint16_t code) noexcept;

  /// What changed since the application last asked (each call clears it).
  bool take_al_control_event() noexcept;
  /// The master wrote the whole of this (ECAT-written) sync manager's buffer: a mailbox became full,
  /// or new outputs arrived.
  bool take_sync_manager_event(int n) noexcept;
  /// The process data watchdog expired (the master stopped writing outputs).
  bool take_watchdog_event() noexcept;

  /// Sync manager n as the master configured it.
  struct sync_manager {
    std::uint16_t start = 0;
    std::uint16_t length = 0;
    std::uint8_t control = 0;
    bool enabled = false;
    bool mailbox() const noexcept { return (control & 0x03) == 0x02; }
    bool ecat_writes() const noexcept { return (control & 0x0C) == 0x04; }
    bool watchdog_trigger() const noexcept { return (control & 0x40) != 0; }
  };
  sync_manager sm(int n) const noexcept;
  /// A mailbox the master wrote: read it (marks it empty). False when it is not full.
  bool read_mailbox(int n, std::vector<std::uint8_t>& out) noexcept;
  /// Fills a mailbox the master reads (marks it full). False when it is still full or too short.
  bool write_mailbox(int n, const std::vector<std::uint8_t>& data) noexcept;
  bool mailbox_full(int n) const noexcept;

  /// Datagrams refused for a reason a master should hear about (past the memory, a mailbox the
  /// master may not access now); the frame went on.
  std::uint32_t refused_accesses() const noexcept { return refused_; }
  /// Tells the controller whether a slave follows it (the DL status shows port 1 open or closed).
  void set_next_port_open(bool open) noexcept;

 private:
  struct sm_state {
    bool full = false;        // mailbox: written by one side, not yet read by the other
    bool event = false;
  };

  // An access of the master to physical memory: false when a sync manager refuses it (no change).
  bool ecat_access(std::uint16_t address, std::uint8_t* data, std::uint16_t length, bool read, bool write,
                   bool or_read) noexcept;
  bool sync_managers_allow(std::uint16_t address, std::uint16_t length, bool read, bool write) const noexcept;
  void after_ecat_access(std::uint16_t address, std::uint16_t length, bool read, bool write) noexcept;
  void register_written(std::uint16_t address, std::uint16_t length) noexcept;
  // Logical addressing through the FMMUs: how many FMMUs of each kind the datagram reached.
  void logical(datagram& d, bool read, bool write) noexcept;

  std::array<std::uint8_t, memory_size> memory_{};
  std::vector<std::uint8_t> eeprom_;
  std::array<sm_state, sync_manager_count> sms_{};
  bool al_control_event_ = false;
  bool watchdog_event_ = false;
  std::uint64_t since_trigger_ns_ = 0;
  std::uint32_t refused_ = 0;
};

/// The in-process wire: a chain of controllers a frame passes in order, and comes back from.
class chain {
 public:
  void add(esc& e);
  std::size_t size() const noexcept { return escs_.size(); }
  /// Passes a frame through every controller; an error (and the frame untouched) when it is not a
  /// sound EtherCAT frame.
  frame_error pass(std::vector<std::uint8_t>& frame) noexcept;
  std::uint64_t frames() const noexcept { return frames_; }
  std::uint64_t refused_frames() const noexcept { return refused_frames_; }

 private:
  std::vector<esc*> escs_;
  parsed_frame parsed_;
  std::uint64_t frames_ = 0;
  std::uint64_t refused_frames_ = 0;
};

}  // namespace cia402::ethercat
