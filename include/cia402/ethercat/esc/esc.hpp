// An EtherCAT slave controller (ESC) in software: the register space and process RAM a master
// reads and writes with datagrams, as an ET1100-class controller has them, and the side a slave's
// application (its "PDI") sees. What the controller does by itself lives here: addressing and
// working counters, the configured station address, FMMUs mapping logical to physical memory at
// bit granularity, sync managers (mailbox hand-over; three-buffer process data), the SII EEPROM
// interface, DL status, the process data watchdog. What a slave decides (the AL state machine, what
// a mailbox means, process data contents) is the application's: it reads the events this
// controller raises and answers through the PDI calls.
//
// Memory: registers 0x0000..0x0FFF, process RAM 0x1000..0x1FFF (4 KiB).
//
// Distributed clocks (ET1100 datasheet section II 0x0900..0x09FF, ETG.1000.4 §9.1), 64 bits wide
// (features 0x0008 bits 2 and 3): a local clock that runs on the time advance() passes (the host
// clock's, through the application, on a network interface); a write to 0x0900 latches the receive
// times (0x0900 port 0, 0x0904 port 1 when a slave follows, 0x0918 the processing unit's 64 bits);
// the system time 0x0910 reads the local time plus the offset 0x0920; a write to it (the master's
// drift distribution, ARMW/FRMW) sets the difference 0x092C to the value written plus the delay
// 0x0928 minus the local copy. The clocks of this emulation do not drift (they share one time
// base), so nothing is slewed: the difference shows how well the master set offsets and delays.
// The SYNC0 unit: activation 0x0981 (bit 0 cyclic unit, bit 1 SYNC0), start time 0x0990 (it reads
// as the next pulse), cycle time 0x09A0 (0: one pulse); a pulse sets 0x098E bit 0 and raises
// take_sync0_event(). On the in-process wire a frame reaches the controller at position i after
// i x chain::hop_delay_ns, and comes back to its port 1 after twice the hops behind it, so a master
// measures real propagation delays.
//
// Buffered (three-buffer) sync managers, as on a real ESC: the writer (the master for outputs, the
// application for inputs) fills a buffer of its own, which is published whole when its last byte
// is written; the reader keeps the buffer it opened until it opens the next (the master by reading
// the first byte, the application by taking the sync manager's event or read_buffer()). So a master
// reading or writing a buffer in several datagrams, and an application stepping between frames,
// always see a whole buffer. Unlike a real ESC, the three buffers do not take 3 x length bytes of
// process RAM: the second and third live beside it, so a master that places the next sync manager
// right after the first length works too. And, because the application of this project writes
// bytes in any order, what it wrote is also published when the master opens the buffer; a writer
// goes on from the buffer it published (the bytes it does not write keep their values).
//
// Nothing on the per-frame path allocates or throws: bad input is refused, counted (errors()) and
// leaves memory as it was.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
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
inline constexpr std::uint16_t al_event_mask = 0x0204;
inline constexpr std::uint16_t event_request = 0x0210;
inline constexpr std::uint16_t al_event_request = 0x0220;  ///< PDI side: bit 0 AL control, bit 8+n SM n
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
/// Within a sync manager's 8 bytes: start (2), length (2), control, status, activate, PDI control.
inline constexpr std::uint16_t sm_control = 4;
inline constexpr std::uint16_t sm_status = 5;
inline constexpr std::uint16_t sm_activate = 6;
inline constexpr std::uint16_t sm_pdi_control = 7;
inline constexpr std::uint16_t dc_receive_time = 0x0900;        ///< port 0; a write latches every port
inline constexpr std::uint16_t dc_receive_time_port1 = 0x0904;
inline constexpr std::uint16_t dc_system_time = 0x0910;         ///< 64 bits
inline constexpr std::uint16_t dc_receive_time_unit = 0x0918;   ///< 64 bits, the processing unit's
inline constexpr std::uint16_t dc_system_time_offset = 0x0920;  ///< 64 bits
inline constexpr std::uint16_t dc_system_time_delay = 0x0928;
inline constexpr std::uint16_t dc_system_time_difference = 0x092C;  ///< bit 31: the local copy is smaller
inline constexpr std::uint16_t dc_activation = 0x0981;          ///< bit 0 cyclic unit, bit 1 SYNC0
inline constexpr std::uint16_t dc_sync0_status = 0x098E;
inline constexpr std::uint16_t dc_start_time = 0x0990;          ///< 64 bits; reads as the next SYNC0 pulse
inline constexpr std::uint16_t dc_sync0_cycle_time = 0x09A0;    ///< ns
inline constexpr std::uint16_t process_ram = 0x1000;
}  // namespace reg

/// AL states as register 0x0130 holds them (bit 4: error indication).
enum class al_state : std::uint8_t { init = 1, pre_operational = 2, bootstrap = 3, safe_operational = 4, operational = 8 };

class esc {
 public:
  static constexpr std::size_t memory_size = 0x2000;
  static constexpr std::size_t process_ram_size = memory_size - reg::process_ram;
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
  /// `arrival_ns`: how long after the frame left the master it reaches this controller (receive
  /// times and the system time a datagram reads are taken then).
  void process(parsed_frame& f, std::uint32_t arrival_ns = 0) noexcept {
    arrival_ns_ = arrival_ns;
    latched_ = false;
    for (std::size_t i = 0; i < f.count; ++i) process(f.datagrams[i]);
  }
  /// The frame came back to port 1 `downstream_ns` after it passed port 0: the port 1 receive time,
  /// when this frame latched receive times.
  void frame_returned(std::uint32_t downstream_ns) noexcept;
  /// Time passes (virtual): the local clock runs, SYNC0 pulses, the process data watchdog runs down.
  void advance(std::uint64_t ns) noexcept;

  // ---- the application (PDI) side ------------------------------------------------------------

  std::uint8_t read8(std::uint16_t address) const noexcept;
  std::uint16_t read16(std::uint16_t address) const noexcept;
  std::uint32_t read32(std::uint16_t address) const noexcept;
  /// PDI writes, to what an application owns: process RAM, the AL status (0x0130) and its code
  /// (0x0134), the AL event mask (0x0204) and a sync manager's PDI control (0x0807 + 8 n). Any other
  /// address is refused and counted (errors().pdi_refused): an application cannot write over the
  /// identity, the station address or a sync manager's configuration.
  /// Inside a buffered sync manager both go to the application's buffer: reads see the outputs it
  /// took last, writes fill the inputs the master reads next (see the top of this file).
  void write8(std::uint16_t address, std::uint8_t v) noexcept;
  void write16(std::uint16_t address, std::uint16_t v) noexcept;
  /// The present AL status and code, as the application sets them.
  void set_al_status(std::uint8_t status, std::uint16_t code) noexcept;

  /// What changed since the application last asked (each call clears it).
  bool take_al_control_event() noexcept;
  /// The master wrote the whole of this (ECAT-written) sync manager's buffer: a mailbox became full,
  /// or new outputs arrived (then the application's reads in it see that newest buffer from now),
  /// or it read the whole of the slave's mailbox.
  bool take_sync_manager_event(int n) noexcept;
  /// The process data watchdog expired (the master stopped writing outputs).
  bool take_watchdog_event() noexcept;
  /// A SYNC0 pulse came since the application last asked (0x098E bit 0, cleared by this).
  bool take_sync0_event() noexcept;
  /// The local clock (ns since power-on) and the system time (local + offset 0x0920).
  std::uint64_t local_time() const noexcept { return local_time_ns_; }
  std::uint64_t system_time() const noexcept;
  /// SYNC0 runs: the cyclic unit and SYNC0 activated (0x0981 bits 0 and 1).
  bool sync0_active() const noexcept;

  /// Sync manager n as the master configured it. Enabled only when activated (and not deactivated
  /// by the application) with an area inside process RAM (0x1000..0x1FFF), as on an ESC.
  struct sync_manager {
    std::uint16_t start = 0;
    std::uint16_t length = 0;
    std::uint8_t control = 0;
    bool enabled = false;
    bool mailbox() const noexcept { return (control & 0x03) == 0x02; }
    bool buffered() const noexcept { return (control & 0x03) == 0x00; }  ///< three buffers
    bool ecat_writes() const noexcept { return (control & 0x0C) == 0x04; }
    bool watchdog_trigger() const noexcept { return (control & 0x40) != 0; }
  };
  sync_manager sm(int n) const noexcept;
  /// A mailbox the master wrote: read it (marks it empty). False when it is not full.
  bool read_mailbox(int n, std::vector<std::uint8_t>& out) noexcept;
  /// Fills a mailbox the master reads (marks it full). False when it is still full or too short.
  bool write_mailbox(int n, const std::vector<std::uint8_t>& data) noexcept;
  bool mailbox_full(int n) const noexcept;
  /// Mailbox repeat (ETG.1000.4 sync manager, ET1100 datasheet 0x0806 / 0x0807): the master asks
  /// for the last reply again by toggling the repeat request (activate register bit 1), which leaves
  /// the mailbox as it is and sets 0x0220 bit 4. True while that bit differs from the application's
  /// repeat acknowledge (PDI control bit 1).
  bool repeat_requested(int n) const noexcept;
  /// The application put the reply back: the acknowledge takes the request's value, 0x0220 bit 4 clears.
  void acknowledge_repeat(int n) noexcept;
  /// The newest whole buffer of outputs (a buffered sync manager the master writes) into `out`, of
  /// the sync manager's length. False, and nothing copied, when n is not such a sync manager or the
  /// size differs. Later reads (read8) see the same buffer.
  bool read_buffer(int n, std::span<std::uint8_t> out) noexcept;
  /// A whole buffer of inputs (a buffered sync manager the master reads), published at once.
  bool write_buffer(int n, std::span<const std::uint8_t> in) noexcept;

  /// Datagrams this controller refused, by reason; each left memory and the working counter as they
  /// were, and the frame went on.
  struct error_counters {
    std::uint32_t past_memory = 0;      ///< a physical access (or an FMMU's target) beyond 0x1FFF
    std::uint32_t sync_manager = 0;     ///< a full mailbox written, an empty one read, a read-only buffer written
    std::uint32_t unknown_command = 0;  ///< a command byte no command has
    std::uint32_t pdi_refused = 0;      ///< an application write outside what the PDI may write
  };
  const error_counters& errors() const noexcept { return errors_; }
  std::uint32_t refused_accesses() const noexcept {
    return errors_.past_memory + errors_.sync_manager + errors_.unknown_command;  // the master's, not the PDI's
  }
  /// Tells the controller whether a slave follows it (the DL status shows port 1 open or closed).
  void set_next_port_open(bool open) noexcept;

 private:
  struct sm_state {
    sync_manager config;      // decoded from 0x0800 + 8 n whenever those registers change
    bool triple = false;      // buffered and inside process RAM: three buffers
    bool full = false;        // mailbox: written by one side, not yet read by the other
    bool event = false;
    // Three buffers: 0 is process RAM at config.start, 1 and 2 lie beside it (shadow_). The writer
    // fills `writer`, `ready` is the newest it published, the reader holds `reader`.
    std::uint8_t writer = 0, ready = 1, reader = 2;
    bool fresh = false;       // `ready` is newer than `reader`
    bool written = false;     // the application wrote into its (input) buffer since publishing
    bool published = false;   // any buffer was published since the configuration
  };

  static bool pdi_writable(std::uint16_t address) noexcept;
  // The controller's own register updates (status it shows, its constructor's values).
  void set_register16(std::uint16_t address, std::uint16_t v) noexcept;
  std::uint8_t* buffer(const sm_state& s, std::uint8_t which) noexcept;
  const std::uint8_t* buffer(const sm_state& s, std::uint8_t which) const noexcept;
  // The sync manager (three-buffer) whose area holds this byte, or nullptr.
  const sm_state* triple_at(std::uint16_t address) const noexcept;
  bool any_triple_in(std::uint16_t address, std::uint16_t length) const noexcept;
  // The one three-buffer sync manager that holds all of [address, address + length) and that no
  // other overlaps; nullptr otherwise.
  const sm_state* only_triple_holding(std::uint16_t address, std::uint16_t length) const noexcept;
  // Where the master's access of this byte lands (its own buffer inside a buffered sync manager).
  std::uint8_t* ecat_byte(std::uint16_t address) noexcept;
  void publish(int n) noexcept;        // the writer's buffer becomes the newest
  void take_newest(int n) noexcept;    // the reader moves to the newest buffer
  void show_buffer_state(int n) noexcept;
  void configure_sync_manager(int n, bool reset) noexcept;
  void raise_sync_manager_event(int n) noexcept;

  // An access of the master to physical memory: false when refused (no change, counted).
  bool ecat_access(std::uint16_t address, std::uint8_t* data, std::uint16_t length, bool read, bool write,
                   bool or_read) noexcept;
  bool sync_managers_allow(std::uint16_t address, std::uint16_t length, bool read, bool write) const noexcept;
  void before_ecat_access(std::uint16_t address, std::uint16_t length, bool read) noexcept;
  void after_ecat_access(std::uint16_t address, std::uint16_t length, bool read, bool write) noexcept;
  void register_written(std::uint16_t address, std::uint16_t length) noexcept;
  // Distributed clocks (esc_dc.cpp).
  void dc_before_read(std::uint16_t address, std::uint16_t length) noexcept;
  void dc_written(std::uint16_t address, std::uint16_t length) noexcept;
  void dc_advance() noexcept;
  std::uint64_t read64(std::uint16_t address) const noexcept;
  void set_register64(std::uint16_t address, std::uint64_t v) noexcept;
  // Logical addressing through the FMMUs: how many FMMUs of each kind the datagram reached.
  void logical(datagram& d, bool read, bool write) noexcept;

  std::array<std::uint8_t, memory_size> memory_{};
  std::array<std::array<std::uint8_t, process_ram_size>, 2> shadow_{};  // buffers 1 and 2
  std::vector<std::uint8_t> eeprom_;
  std::array<sm_state, sync_manager_count> sms_{};
  bool al_control_event_ = false;
  bool watchdog_event_ = false;
  std::uint64_t since_trigger_ns_ = 0;
  bool watchdog_armed_ = false;        // a sync manager enabled with its watchdog trigger bit
  std::uint64_t local_time_ns_ = 0;
  std::uint32_t arrival_ns_ = 0;       // of the frame being processed
  bool latched_ = false;               // the frame being processed latched the receive times
  bool sync0_event_ = false;
  std::uint64_t next_sync0_ = 0;       // system time of the next SYNC0 pulse, while active
  error_counters errors_{};
};

/// The in-process wire: a chain of controllers a frame passes in order, and comes back from.
class chain {
 public:
  void add(esc& e);
  std::size_t size() const noexcept { return escs_.size(); }
  /// Passes a frame through every controller; an error (and the frame untouched) when it is not a
  /// sound EtherCAT frame.
  frame_error pass(std::vector<std::uint8_t>& frame) noexcept;
  /// Propagation delay from one controller to the next (forwarding and cable), each way.
  std::uint32_t hop_delay_ns = 500;
  std::uint64_t frames() const noexcept { return frames_; }
  std::uint64_t refused_frames() const noexcept { return refused_frames_; }
  /// Refused frames of one kind.
  std::uint64_t refused_frames(frame_error why) const noexcept {
    const auto i = static_cast<std::size_t>(why);
    return i < frame_error_count ? refused_by_[i] : 0;
  }

 private:
  std::vector<esc*> escs_;
  parsed_frame parsed_;
  std::uint64_t frames_ = 0;
  std::uint64_t refused_frames_ = 0;
  std::array<std::uint64_t, frame_error_count> refused_by_{};
};

}  // namespace cia402::ethercat
