// CANopen over EtherCAT (ETG.1000.6 §5.6.2..5.6.4): the CoE header, the SDO frames of upload and
// download (expedited, normal and segmented, with complete access), the abort, and the emergency.
// The codec both sides use: the master builds requests and parses responses, the slave parses
// requests and builds responses, and neither reads an SDO byte by byte. Links only the core.
//
// Every parser checks a length before it reads what the length covers, and says "nothing" for a
// frame too short for its command; the data it returns points into the frame given. The command
// specifiers are CiA 301's (§7.2.4.3); bit 4 of an initiate request or response is CoE's complete
// access. An abort is "Abort SDO Transfer", which ETG.1000.6 codes as an SDO *request* (CoE service 2)
// in either direction: SOEM and IgH look for it there.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "cia402/ethercat/coe/mailbox.hpp"

namespace cia402::ethercat {

/// CoE services (the high nibble of the CoE header's second byte).
enum class coe_service : std::uint8_t {
  emergency = 1,
  sdo_request = 2,
  sdo_response = 3,
  tx_pdo = 4,
  rx_pdo = 5,
  tx_pdo_remote_request = 6,
  rx_pdo_remote_request = 7,
  sdo_information = 8,
};

inline constexpr std::size_t coe_header_size = 2;
/// Bytes a CoE service's data may take in a mailbox of `mailbox_size` bytes, after the mailbox
/// header, the CoE header and the service's own `service_header_size` bytes (0 when it is too small
/// for any): the one sum behind every "room" of an SDO and SDO information frame.
constexpr std::size_t coe_room(std::size_t mailbox_size, std::size_t service_header_size) noexcept {
  const std::size_t headers = mailbox_header_size + coe_header_size + service_header_size;
  return mailbox_size > headers ? mailbox_size - headers : 0;
}
/// An SDO's fixed part: command, index, sub-index, then 4 bytes of data or of size.
inline constexpr std::size_t sdo_header_size = 8;
/// Bytes of value the first mailbox of a normal transfer carries, and a segment carries, in a
/// mailbox of `mailbox_size` bytes (0 when it is too small for any).
/// (A segment's own header is its one command byte.)
constexpr std::size_t sdo_initiate_room(std::size_t mailbox_size) noexcept {
  return coe_room(mailbox_size, sdo_header_size);
}
constexpr std::size_t sdo_segment_room(std::size_t mailbox_size) noexcept { return coe_room(mailbox_size, 1); }

/// A mailbox's CoE data: the service and what follows the CoE header.
struct coe_view {
  coe_service service = coe_service::sdo_request;
  std::uint16_t number = 0;  ///< the header's 9-bit number (PDO number; 0 for SDOs)
  std::span<const std::uint8_t> body;
};
/// Nothing when the data is shorter than a CoE header.
std::optional<coe_view> parse_coe(std::span<const std::uint8_t> data) noexcept;

/// What an SDO frame is. A request's and a response's command specifiers differ; the parser of each
/// direction names them alike. `other`: a request whose command specifier (5..7: block transfers)
/// the segmented SDO does not have, with the index and sub-index it names.
enum class sdo_command : std::uint8_t { initiate_download, download_segment, initiate_upload, upload_segment, abort, other };

/// One SDO frame, decoded.
struct sdo_frame {
  sdo_command command = sdo_command::abort;
  std::uint16_t index = 0;       ///< initiate and abort frames
  std::uint8_t sub = 0;
  bool complete_access = false;  ///< initiate frames
  bool expedited = false;        ///< initiate frames: the value is in the 4 data bytes
  bool size_indicated = false;
  std::uint32_t size = 0;        ///< normal initiate: the value's whole size; expedited: its size when indicated
  bool toggle = false;           ///< segments (and their responses)
  bool last = false;             ///< segments: no more follow
  std::uint32_t abort_code = 0;  ///< abort
  std::span<const std::uint8_t> data;  ///< the value's bytes this frame carries
};

/// An SDO request (service 2, master to slave) from the CoE body; nothing when it is too short for
/// its command.
std::optional<sdo_frame> parse_sdo_request(std::span<const std::uint8_t> body) noexcept;
/// An SDO response (service 3, slave to master) from the CoE body, or an abort the slave sent (under
/// service 2 as ETG.1000.6 says, or 3 as some slaves do); nothing when it is too short.
std::optional<sdo_frame> parse_sdo_response(coe_service service, std::span<const std::uint8_t> body) noexcept;

// ---- the master's requests: CoE header and SDO, the data of one mailbox --------------------------

std::vector<std::uint8_t> sdo_upload_request(std::uint16_t index, std::uint8_t sub, bool complete_access = false);
std::vector<std::uint8_t> sdo_upload_segment_request(bool toggle);
/// 1..4 bytes in the request itself.
std::vector<std::uint8_t> sdo_download_expedited(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> value);
/// The size of the whole value and its first bytes (as many as the mailbox holds; segments carry the rest).
std::vector<std::uint8_t> sdo_download_normal(std::uint16_t index, std::uint8_t sub, bool complete_access,
                                              std::uint32_t size, std::span<const std::uint8_t> first);
std::vector<std::uint8_t> sdo_download_segment(bool toggle, bool last, std::span<const std::uint8_t> data);
/// Abort SDO Transfer, from either side: CoE service 2.
std::vector<std::uint8_t> sdo_abort_request(std::uint16_t index, std::uint8_t sub, std::uint32_t code);

// ---- the slave's responses ------------------------------------------------------------------------

std::vector<std::uint8_t> sdo_upload_expedited_response(std::uint16_t index, std::uint8_t sub,
                                                        std::span<const std::uint8_t> value);
std::vector<std::uint8_t> sdo_upload_normal_response(std::uint16_t index, std::uint8_t sub, bool complete_access,
                                                     std::uint32_t size, std::span<const std::uint8_t> first);
std::vector<std::uint8_t> sdo_upload_segment_response(bool toggle, bool last, std::span<const std::uint8_t> data);
std::vector<std::uint8_t> sdo_download_response(std::uint16_t index, std::uint8_t sub, bool complete_access);
std::vector<std::uint8_t> sdo_download_segment_response(bool toggle);

// ---- emergency (ETG.1000.6 §5.6.4) ----------------------------------------------------------------

struct emergency_message {
  std::uint16_t code = 0;
  std::uint8_t error_register = 0;
  std::array<std::uint8_t, 5> data{};
};
std::vector<std::uint8_t> emergency_request(const emergency_message& e);
/// From the CoE body of an emergency; nothing when it is shorter than the 8 bytes it has.
std::optional<emergency_message> parse_emergency(std::span<const std::uint8_t> body) noexcept;

}  // namespace cia402::ethercat
