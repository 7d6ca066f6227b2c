// A CiA 301 slave node around a device (device.hpp) and the device's objects: NMT slave with boot-up, heartbeat producer (0x1017) and consumer (0x1016),
// SDO server, EMCY producer, SYNC consumer and 4 RPDOs / 4 TPDOs whose parameters and mappings are
// changed over SDO with the CiA 301 rules.
//
// The node never reads a clock: process(elapsed) runs its timers and gives the device its time, and
// returns when it next wants to run. Frames come in through on_frame(); frames go out on the channel
// given at construction.
//
// Behaviour, where CiA 301 leaves a choice:
// - PDOs only in OPERATIONAL; SDO and EMCY in PRE-OPERATIONAL and OPERATIONAL; in STOPPED only NMT
//   and heartbeats. Reset node restarts the device (power-on) and every object; reset communication
//   resets 0x1000..0x1FFF. Both send the boot-up message and enter PRE-OPERATIONAL.
// - A heartbeat consumer timeout (0x1016) tells the device the connection is lost, so 0x6007 acts
//   (S10), and sends EMCY 0x8130; the next heartbeat from that node clears it. Entering STOPPED
//   tells it too (CiA 402-2 lists "NMT stopped state entered" among 0x6007's events), leaving it
//   clears it; PRE-OPERATIONAL does not (SDO still works). The device decides what a loss does.
// - EMCY (0x80 + node-ID) on every new device error (device::error_changed, device.hpp): bytes 0..1
//   the error code, byte 2 the error register 0x1001, bytes 3..7 the device's
//   manufacturer_error_field() at that moment (a CiA 402 drive: its status word, then zeros). Node errors (heartbeat lost 0x8130, RPDO too short 0x8210) send their
//   own EMCY. When the last error is gone, EMCY 0x0000 ("error reset").
// - 0x1003 (error_history.hpp) holds the last 8 of those errors, newest first, the code with the
//   first two bytes of the manufacturer field (the drive's status word) above it; it records an
//   error that arises in STOPPED too, where no EMCY goes out. Reset node and reset communication
//   empty it, as every object of 0x1000..0x1FFF goes back to its default.
// - 0x1001 reads as the drive's register, plus bits 0 and 4 (communication) while a node error is
//   active.
// - Mapping changes follow CANopenNode: mapping entries need the PDO invalid (COB-ID bit 31) and
//   sub-index 0 = 0, else 0x06010000; a mapped object must exist (0x06020000 / 0x06090011), be
//   mappable in that direction with its full length (0x06040041), or be a CiA 301 dummy entry
//   (0x0001..0x0007 sub 0, its type's length, 1 bit for BOOLEAN; pdo_maps.hpp), which maps either
//   way and whose bits an RPDO skips and a TPDO sends as zeros (a dummy of another length is
//   0x06040041); entries follow each other at any bit offset; sub-index 0 above 8 is 0x06090031,
//   more than 64 bits 0x06040042. A COB-ID that enables a PDO without mapping, changes the CAN-ID of
//   a valid PDO, sets reserved bits or uses a restricted CAN-ID is 0x06090030; so are transmission
//   types 241..253 (RTR-only 252/253 is not offered) and an inhibit time change while the TPDO is
//   valid.
// - A synchronous RPDO's data acts at the next SYNC; an event RPDO's at once. A synchronous TPDO
//   (1..240) is sampled and sent on every n-th SYNC; type 0 on a SYNC if its data changed; 254/255
//   when its data changes (after the inhibit time) and every event-timer period. An event TPDO is
//   sampled only when the device reported a change of an object it maps, the node wrote one, its
//   event timer ran out or it has not been sent since it was (re)configured: no device reads while
//   nothing changes.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cia402/canopen/can/channel.hpp"
#include "cia402/dictionary/device.hpp"
#include "cia402/dictionary/dictionary_access.hpp"
#include "cia402/canopen/301/nmt.hpp"
#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/canopen/301/pdo.hpp"
#include "cia402/canopen/301/sdo_server.hpp"
#include "cia402/canopen/301/timing.hpp"
#include "cia402/pdo_maps.hpp"

namespace cia402::canopen {

/// The communication objects the node has room for (CiA 301): its PDOs and heartbeat consumers.
inline constexpr int pdo_count = 4;             ///< RPDOs and TPDOs each
inline constexpr int max_mapped_objects = 8;    ///< entries per mapping object
inline constexpr int heartbeat_consumers = 4;   ///< sub-indices 1..4 of 0x1016

struct slave_config {
  std::uint8_t node_id = 1;
  std::uint32_t sdo_timeout_us = 1000000;
  /// Default of 0x1017 (also after a reset); 0 = no heartbeat until a master asks for one.
  std::uint16_t heartbeat_ms = 0;
  /// The device's objects, given by the layer above (a CiA 402 drive's: drive402::drive_objects()):
  /// its identity, its profile's objects, its own. The node adds the communication objects it serves
  /// itself (communication_objects()), so this CiA 301 node knows no device profile.
  std::vector<dictionary::object_entry> objects;
  /// RPDO1..4 / TPDO1..4 as they start and after a reset: mapping, transmission type, inhibit time,
  /// event timer (a CiA 402 drive's: cia402::pdo_maps). A PDO with no entries starts invalid.
  std::array<pdo_map, pdo_count> rpdo{};
  std::array<pdo_map, pdo_count> tpdo{};
  /// 0x1021 store EDS and 0x1022 storage format, which a master reads to build
  /// the node's dictionary from the node itself (python-canopen's import_from_node): `store_eds`
  /// puts both in the table; `eds_text` is what 0x1021 gives, made once, when it is first read (the
  /// layer above writes EDS files; this CiA 301 node does not). 0x1022 reads 0: ASCII.
  bool store_eds = false;
  std::function<std::string()> eds_text;
};

/// The communication objects the node serves itself, beside the services that use them (CiA 301
/// §7.5.2): 0x1003 pre-defined error field, 0x1005 COB-ID SYNC, 0x1014 COB-ID EMCY, 0x1016 consumer heartbeat times, 0x1017
/// producer heartbeat time, 0x1200 SDO server, 0x1400..0x1403 / 0x1600..0x1603 RPDO communication
/// and mapping, 0x1800..0x1803 / 0x1A00..0x1A03 TPDO communication and mapping; defaults from the
/// predefined connection set (CiA 301 §7.3.5) and `c`.
std::vector<dictionary::object_entry> communication_objects(const slave_config& c);
/// The whole table a node of configuration `c` serves (and its EDS lists): the device's objects and
/// the communication objects, by index. Throws std::invalid_argument when the device's objects hold
/// one of the node's own.
std::vector<dictionary::object_entry> node_objects(const slave_config& c);

/// Error codes the node raises itself (not the drive).
namespace node_error {
inline constexpr std::uint16_t heartbeat_lost = 0x8130;   ///< life guard / heartbeat error
inline constexpr std::uint16_t pdo_length = 0x8210;       ///< PDO not processed: length error
}  // namespace node_error

class slave final : private dictionary::dictionary_access, private dictionary::device_events {
 public:
  /// Sends the boot-up message and enters PRE-OPERATIONAL. Device and channel must outlive it; the
  /// node attaches itself to the device's reports until it is destroyed. Throws
  /// std::invalid_argument as node_objects() does.
  slave(dictionary::device& d, channel& out, const slave_config& config);
  ~slave();
  slave(const slave&) = delete;
  slave& operator=(const slave&) = delete;

  /// A frame from the bus (any identifier; the node picks what concerns it).
  void on_frame(const frame& f);
  /// Every frame waiting on `in`, then process(elapsed).
  std::uint32_t poll(channel& in, std::uint32_t elapsed_us);
  std::uint32_t process(std::uint32_t elapsed_us);

  nmt_state state() const noexcept { return state_; }
  std::uint8_t node_id() const noexcept { return config_.node_id; }
  bool connection_lost() const noexcept { return consumer_.any_lost(); }
  const dictionary::object_dictionary& dictionary() const noexcept { return od_; }

  /// Local object access with every rule the SDO server applies (what an application on the node
  /// would use). Values travel as int64; strings through read_text / write_text.
  using dictionary::dictionary_access::read;
  using dictionary::dictionary_access::write;
  /// Any object as its bytes on the bus (strings as text).
  sdo_abort read_bytes(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t>& bytes) {
    return upload(index, sub, bytes);
  }

  /// The resolved configuration of RPDO/TPDO n (0..3).
  const pdo_config& rpdo(int n) const noexcept { return rpdo_[static_cast<std::size_t>(n)].cfg; }
  const pdo_config& tpdo(int n) const noexcept { return tpdo_[static_cast<std::size_t>(n)].cfg; }

 private:
  struct rpdo_state {
    pdo_config cfg;
    std::array<std::uint8_t, 8> buffer{};
    bool pending = false;  // synchronous data waiting for the next SYNC
  };
  struct tpdo_state {
    pdo_config cfg;
    std::array<std::uint8_t, 8> last{};
    bool sent = false;
    std::uint8_t sync_count = 0;
    std::uint32_t inhibit_left_us = 0;
    std::uint32_t event_left_us = 0;
    bool event_pending = false;
    bool requested = false;  // an object it maps changed: sample it
  };

  // device_events (the device's reports)
  void object_changed(std::uint16_t index, std::uint8_t sub) noexcept override;
  void error_changed(std::uint16_t code) noexcept override;

  // dictionary_access: what a value that keeps the dictionary's rules does.
  sdo_abort write_value(dictionary::object_dictionary::slot& s, std::int64_t v) override;
  /// A CAN identifier this node may not take for `writing` (0x1005, 0x1014 or a PDO's communication
  /// object): reserved by CiA 301, or already SYNC, this node's EMCY or another PDO in use.
  bool cob_id_taken(std::uint32_t id, std::uint16_t writing) const;
  sdo_abort write_pdo_parameter(dictionary::object_dictionary::slot& s, std::int64_t v);
  sdo_abort read_value(const dictionary::object_dictionary::slot& s, std::int64_t& v) override;
  // 0x1021 from eds_text, made once; every other object as the dictionary has it.
  sdo_abort upload(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t>& data) noexcept override;
  sdo_abort check_mapping_entry(bool receive, std::uint32_t entry) const;
  void resolve_pdos();
  pdo_config resolve(std::uint16_t comm, std::uint16_t mapping);
  void configure_consumer();
  // The device hears whether the fieldbus is there: no lost heartbeat and not STOPPED.
  void tell_connection();

  void boot();
  void enter(nmt_state s);
  void on_nmt(const frame& f);
  void on_sync();
  void apply_rpdo(rpdo_state& r, const std::uint8_t* data);
  bool sample(const tpdo_state& t, std::array<std::uint8_t, 8>& out);
  void send_tpdo(tpdo_state& t, const std::array<std::uint8_t, 8>& data);
  std::uint32_t process_tpdo_events(std::uint32_t elapsed_us);
  void set_node_error(std::uint16_t code, bool active);
  void note_error(std::uint16_t code) noexcept;
  void send_emcy(std::uint16_t code);

  dictionary::device* device_;
  channel* out_;
  slave_config config_;
  dictionary::object_dictionary od_;
  sdo_server sdo_;
  heartbeat_producer producer_;
  heartbeat_consumer consumer_;
  nmt_state state_ = nmt_state::initialising;
  std::array<rpdo_state, 4> rpdo_{};
  std::array<tpdo_state, 4> tpdo_{};
  std::uint32_t sync_id_ = cob::sync;
  std::uint16_t drive_error_ = 0;      // the device's error as last reported
  bool heartbeat_error_ = false;
  bool pdo_length_error_ = false;
  bool any_error_reported_ = false;    // an EMCY other than 0x0000 went out since the last reset one
  std::string eds_;                    // 0x1021 once read
};

}  // namespace cia402::canopen
