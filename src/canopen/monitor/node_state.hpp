// What the decoder keeps of one node, and the helpers its parts share (private to the monitor).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cia402/canopen/301/pdo.hpp"
#include "cia402/hex_text.hpp"
#include "cia402/canopen/monitor/decoder.hpp"

namespace cia402::canopen::monitor {

/// CiA 301 allows 0x40 mapping entries (of 1 bit each, in 64 bits).
inline constexpr std::size_t max_mapped_entries = 64;
/// Bytes of a segmented transfer the decoder keeps; the rest is counted only.
inline constexpr std::size_t max_kept_bytes = 65536;

struct pdo_map {
  std::uint32_t cob_id = pdo_cob_invalid;
  std::uint8_t count = 0;
  std::array<std::uint32_t, max_mapped_entries> entries{};
};

/// The node's SDO transfer as seen from the bus.
struct sdo_follow {
  enum class phase : std::uint8_t {
    idle,
    download_expedited,   ///< value sent, the server's answer pending
    download_initiated,   ///< segmented download announced, the server's answer pending
    download_segments,    ///< segments going
    download_last_sent,   ///< last segment sent, the server's answer pending
    upload_requested,
    upload_segments,
    block_download_requested,  ///< block download announced, the server's answer pending
    block_download_segments,   ///< the client's segments going, block by block
    block_download_acknowledged,  ///< the last segment acknowledged, the client's end pending
    block_download_ending,      ///< the client's end sent, the server's answer pending
    block_upload_requested,    ///< block upload asked for, the server's answer pending
    block_upload_answered,     ///< the size announced, the client's start pending
    block_upload_segments,     ///< the server's segments going, block by block
    block_upload_acknowledged,  ///< the last segment acknowledged, the server's end pending
    block_upload_ending,       ///< the server's end sent, the client's answer pending
  };
  phase at = phase::idle;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::vector<std::uint8_t> data;
  std::size_t total = 0;           ///< bytes moved, kept or not
  bool size_indicated = false;
  std::size_t size = 0;
  std::uint8_t toggle = 0;         ///< the toggle bit the next segment should carry
  std::uint8_t sequence = 0;       ///< block transfer: the last segment of this block in order
  std::size_t block_start = 0;     ///< block transfer: bytes moved before this block
  bool last_in_order = false;      ///< block transfer: the last segment came, all before it too
  void restart(phase p, std::uint16_t i, std::uint8_t s) {
    sequence = 0;
    block_start = 0;
    last_in_order = false;
    at = p;
    index = i;
    sub = s;
    data.clear();
    total = 0;
    size_indicated = false;
    size = 0;
    toggle = 0;
  }
  void append(std::span<const std::uint8_t> bytes) {
    for (std::uint8_t b : bytes) {
      if (data.size() < max_kept_bytes) data.push_back(b);
    }
    total += bytes.size();
  }
  /// Block transfer: what the acknowledge of segment `acknowledged` says was moved; the rest of the
  /// block is sent again.
  void keep_acknowledged(std::uint8_t acknowledged) {
    if (acknowledged < sequence) last_in_order = false;  // the last is sent again too
    total = std::min(total, block_start + std::size_t{acknowledged} * 7);
    if (data.size() > total) data.resize(total);
    block_start = total;
    sequence = 0;
  }
  /// Block transfer: the end says the last segment carried `unused` bytes that are no data.
  void drop_unused(std::size_t unused) {
    total -= std::min(total, unused);
    if (data.size() > total) data.resize(total);
  }
};

struct decoder::node_state {
  std::shared_ptr<const std::vector<dictionary::object_entry>> table;  ///< its description, or null
  std::map<std::uint16_t, pdo_map> pdos;  ///< by communication index, 0x1400.. and 0x1800..
  sdo_follow sdo;
};

using object_table = std::vector<dictionary::object_entry>;

/// "0x6041:0".
std::string object_ref(std::uint16_t index, std::uint8_t sub);
/// "0x" and `digits` upper-case hexadecimal digits (more if the value needs them): the core's to_hex
/// (cia402/hex_text.hpp) as a string.
std::string hex(std::uint64_t value, int digits);
/// The value of index:sub carried by `bytes`, named and typed by `table` (may be null), else by
/// the CiA 402 object table.
object_value read_value(const object_table* table, std::uint16_t index, std::uint8_t sub,
                        std::span<const std::uint8_t> bytes);
/// The object's name from `table` or the CiA 402 table, or "".
std::string object_name(const object_table* table, std::uint16_t index, std::uint8_t sub);
/// "0x6041:0 = 0x0237 (Statusword: OPERATION_ENABLED)".
std::string describe(const object_value& v);
/// The bytes in hexadecimal, separated by spaces: "37 06".
std::string hex_bytes(std::span<const std::uint8_t> bytes);

/// The PDO maps of a node as its description gives them at power-up (none without one).
void load_pdos(decoder::node_state& n, std::uint8_t node_id);
/// A value of index:sub the node confirmed or reported: a PDO's COB-ID or mapping entry is kept.
void learn(decoder::node_state& n, std::uint8_t node_id, std::uint16_t index, std::uint8_t sub,
           std::span<const std::uint8_t> bytes);

}  // namespace cia402::canopen::monitor
