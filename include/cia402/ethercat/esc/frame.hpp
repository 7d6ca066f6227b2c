// EtherCAT frames (ETG.1000.4): an Ethernet II frame of EtherType 0x88A4 whose 2-byte EtherCAT header
// (length 11 bits, type 4 bits = 1) is followed by datagrams, each a 10-byte header (command,
// index, 32-bit address, 11-bit length with the circulating and "more follows" bits, IRQ), its
// data and a 16-bit working counter. Parsing points into the frame's own bytes, so a slave edits
// data and working counters in place as the frame passes; no allocation.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace cia402::ethercat {

inline constexpr std::uint16_t ethertype = 0x88A4;
inline constexpr std::size_t ethernet_header_size = 14;
inline constexpr std::size_t ethercat_header_size = 2;
inline constexpr std::size_t datagram_header_size = 10;
inline constexpr std::size_t working_counter_size = 2;
inline constexpr std::size_t minimum_frame_size = 60;  ///< Ethernet minimum without the FCS
inline constexpr std::size_t maximum_frame_size = 1514;
/// The most datagrams one frame may carry here (a full frame of empty datagrams holds ~120).
inline constexpr std::size_t max_datagrams = 128;

/// Datagram commands (ETG.1000.4 table 13).
enum class command : std::uint8_t {
  nop = 0, aprd = 1, apwr = 2, aprw = 3, fprd = 4, fpwr = 5, fprw = 6, brd = 7, bwr = 8, brw = 9,
  lrd = 10, lwr = 11, lrw = 12, armw = 13, frmw = 14,
};
/// "APRD", ...; "?" for a value no command has.
const char* command_name(command c) noexcept;

/// One datagram of a parsed frame: its header fields, and where its data and working counter lie.
struct datagram {
  command cmd = command::nop;
  std::uint8_t index = 0;
  std::uint32_t address = 0;   ///< ADP in the low 16 bits, ADO in the high 16 (or a logical address)
  std::uint16_t length = 0;    ///< data bytes
  bool circulating = false;
  bool more = false;           ///< another datagram follows
  std::uint16_t irq = 0;
  std::uint8_t* header = nullptr;  ///< the 10 header bytes, in the frame
  std::uint8_t* data = nullptr;
  std::uint8_t* wkc = nullptr;     ///< the working counter, little-endian, in the frame

  std::uint16_t position() const noexcept { return static_cast<std::uint16_t>(address); }  ///< ADP
  std::uint16_t offset() const noexcept { return static_cast<std::uint16_t>(address >> 16); }  ///< ADO
  std::uint16_t working_counter() const noexcept;
  void set_working_counter(std::uint16_t v) noexcept;
  /// Writes ADP back into the header (auto-increment addressing changes it on the way).
  void set_position(std::uint16_t adp) noexcept;
};

/// Why a frame was refused. Nothing in it is touched then.
enum class frame_error : std::uint8_t {
  none,
  too_short,              ///< shorter than the Ethernet and EtherCAT headers
  not_ethercat,           ///< another EtherType
  vlan_tagged,            ///< an 802.1Q/802.1ad tag before the EtherType: not supported here
  not_commands,           ///< EtherCAT header type other than 1 (datagrams)
  length_mismatch,        ///< the EtherCAT header's length runs past the frame
  datagram_truncated,     ///< a datagram's data or working counter runs past the EtherCAT length
  more_follows_past_end,  ///< "more follows" set, but the EtherCAT length ends there
  too_many_datagrams,
};
/// How many kinds of frame_error there are (for counters indexed by it).
inline constexpr std::size_t frame_error_count = static_cast<std::size_t>(frame_error::too_many_datagrams) + 1;
const char* frame_error_text(frame_error e) noexcept;

/// The datagrams of a frame, at most max_datagrams, pointing into `frame`.
struct parsed_frame {
  std::array<datagram, max_datagrams> datagrams{};
  std::size_t count = 0;
};

/// Parses a whole Ethernet frame. The chain of datagrams ends at the first without "more follows";
/// bytes after it, inside the EtherCAT length or not, are ignored (padding: a real ESC forwards
/// them untouched too). On an error `out.count` is 0 and nothing was written.
frame_error parse_frame(std::span<std::uint8_t> frame, parsed_frame& out) noexcept;

/// Builds frames: datagrams are appended, then finish() writes the EtherCAT length and pads to the
/// Ethernet minimum.
class frame_builder {
 public:
  frame_builder(const std::array<std::uint8_t, 6>& destination, const std::array<std::uint8_t, 6>& source);
  /// Appends a datagram with `length` data bytes (copied from `data` if given, else zeros);
  /// returns the offset of its data in the frame, or -1 when the frame would grow past 1514 bytes.
  long add(command cmd, std::uint8_t index, std::uint32_t address, std::span<const std::uint8_t> data,
           std::uint16_t length);
  /// The finished frame (the builder may go on adding after a finish: the chain is rewritten).
  std::vector<std::uint8_t> finish() const;

 private:
  std::vector<std::uint8_t> bytes_;
  long last_header_ = -1;
};

}  // namespace cia402::ethercat
