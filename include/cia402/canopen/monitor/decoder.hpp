// CANopen frames decoded for a person or a script (`cia402 monitor`): each frame, with the time it
// was seen, becomes a record of what it is (CiA 301's services by their COB-IDs, §7.3.5: NMT, SYNC,
// TIME, EMCY, SDO, PDO, heartbeat), which node it concerns, the objects and values it carries, and
// a line of text.
//
// The decoder keeps what the bus told it, per node:
// - SDO transfers (the default server channel, 0x600/0x580 + node-ID), followed across segments:
//   expedited and segmented, upload and download; an abort with its code's text (sdo_abort.hpp).
// - PDO maps: the COB-ID (0x1400.. / 0x1800.. sub 1) and mapping (0x1600.. / 0x1A00..) of each PDO,
//   from the node's description at power-up (its EDS, or the dictionary it serves), then from every
//   SDO download the node confirmed and every upload it answered, so a master's remapping is
//   followed. A reset (NMT reset node / communication, a boot-up) restores the description's
//   values. A node known by no description gets the predefined connection set's COB-IDs for PDOs
//   1..4 once a mapping of it goes over the bus.
// Values are named and read with their type from the node's description, else from the CiA 402
// object table (objects.hpp); an EMCY code is named from error_codes.hpp.
//
// The bus is not trusted: a frame that is not what its COB-ID says (a wrong length, an RTR, a PDO
// shorter than its mapping, a 29-bit identifier) is decoded as `unknown` with the reason, and
// nothing a frame says makes the decoder hold more than a bounded amount (segments beyond 64 KiB
// are counted, not kept).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/canopen/can/frame.hpp"

namespace cia402::canopen::monitor {

enum class frame_kind : std::uint8_t { nmt, sync, time, emcy, heartbeat, sdo, pdo, unknown };
/// "nmt", "sync", "time", "emcy", "heartbeat", "sdo", "pdo", "unknown".
const char* kind_name(frame_kind k) noexcept;

/// The value of one object as a frame carried it.
struct object_value {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::string name;          ///< "Statusword"; "" when no description names it
  std::string unit;          ///< "rpm", from the CiA 402 table; "" for none
  bool is_number = false;    ///< else `shown` is a string's text or the bytes in hexadecimal
  bool is_signed = false;
  std::int64_t number = 0;   ///< sign-extended for a signed type
  std::string shown;         ///< as a person reads it: "0x0237", "-120", "\"virtual\""
  std::string meaning;       ///< what the value says where the decoder knows: a status word's
                             ///< state, a mode's short name, an error code's text; else ""
};

struct decoded_frame {
  std::uint64_t time_us = 0;
  frame raw;
  frame_kind kind = frame_kind::unknown;
  std::uint8_t node = 0;     ///< the node it comes from or is for; 0: none (SYNC) or every node
  /// One word for scripts: NMT "start", "stop", "pre-operational", "reset-node",
  /// "reset-communication"; heartbeat "boot-up", "operational", "stopped", "pre-operational",
  /// "guarding-request"; SDO "upload-request", "upload-start", "upload-segment-request",
  /// "upload-segment", "upload", "download", "download-start", "download-segment",
  /// "download-done", "abort", "block"; PDO "RPDO1".."TPDO512"; EMCY "error" or "reset";
  /// "" for SYNC, TIME and unknown frames.
  std::string event;
  bool has_object = false;   ///< SDO: the object of the transfer
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint32_t code = 0;    ///< EMCY error code, SDO abort code, NMT command, heartbeat state
  std::string code_text;     ///< that code's text ("continuous over-current"), or ""
  std::vector<object_value> values;  ///< SDO: the value moved, once known; PDO: each mapped object
  /// What a person reads, without time and node: "SDO upload 0x6041:0 = 0x0237 (Statusword:
  /// OPERATION_ENABLED)"; for an unknown frame the reason it is not what its COB-ID says.
  std::string text;
};

class decoder {
 public:
  decoder();
  ~decoder();
  decoder(const decoder&) = delete;
  decoder& operator=(const decoder&) = delete;

  /// Describes node `node_id` (1..127; others are ignored) by its objects: an EDS read with
  /// read_eds (306/eds_reader.hpp), or the dictionary the node serves. Its PDO maps start from the
  /// description's values.
  void describe_node(std::uint8_t node_id, std::vector<dictionary::object_entry> objects);
  /// Describes every node that describe_node did not, e.g. by the whole table of the project's drive
  /// as a node (canopen::node_objects(apps::drive_node_config(0))), so the predefined PDOs of a
  /// `cia402 bus` decode with no EDS.
  void describe_other_nodes(std::vector<dictionary::object_entry> objects);

  decoded_frame decode(const frame& f, std::uint64_t time_us);

  struct node_state;  ///< what the decoder knows of one node (src/canopen/monitor/node_state.hpp)

 private:
  node_state& node(std::uint8_t id);
  void reset_node(node_state& n, std::uint8_t id);
  void decode_nmt(decoded_frame& d);
  void decode_heartbeat(decoded_frame& d);
  void decode_sdo(decoded_frame& d, bool from_server);
  bool decode_pdo(decoded_frame& d);

  using table = std::shared_ptr<const std::vector<dictionary::object_entry>>;
  std::map<std::uint8_t, table> described_;
  table others_;
  std::map<std::uint8_t, std::unique_ptr<node_state>> nodes_;
};

}  // namespace cia402::canopen::monitor
