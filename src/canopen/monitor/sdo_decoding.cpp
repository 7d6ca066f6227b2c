// SDO (CiA 301 §7.2.4.3): each frame of the default server channel, and the node's transfer
// followed across them, so a segment is named by its object and the value of a segmented or block
// transfer shows once its last segment (a block transfer: its end) went. What a server confirmed (a download) or reported (an
// upload) is handed to the PDO maps.
#include "cia402/sdo_abort.hpp"
#include "cia402/sdo_command.hpp"
#include "node_state.hpp"

namespace cia402::canopen::monitor {
namespace {

using namespace sdo_command_specifier;  // ccs_*, scs_*, cs_abort: bits 5..7 of byte 0

using phase = sdo_follow::phase;

std::string size_text(std::size_t n) { return std::to_string(n) + (n == 1 ? " byte" : " bytes"); }

struct sdo_frame {
  const std::uint8_t* d;
  unsigned cs() const { return d[0] >> 5; }
  std::uint16_t index() const { return static_cast<std::uint16_t>(get_le(d + 1, 2)); }
  std::uint8_t sub() const { return d[3]; }
  bool expedited() const { return (d[0] & 0x02) != 0; }
  bool size_indicated() const { return (d[0] & 0x01) != 0; }
  /// Data bytes of an expedited initiate: 4 - n when the size is indicated, else 4.
  std::size_t expedited_size() const { return size_indicated() ? 4u - ((d[0] >> 2) & 0x03u) : 4u; }
  /// Data bytes of a segment: 7 - n.
  std::size_t segment_size() const { return 7u - ((d[0] >> 1) & 0x07u); }
  bool last() const { return (d[0] & 0x01) != 0; }
  std::uint8_t toggle() const { return static_cast<std::uint8_t>((d[0] >> 4) & 1); }
};

// One SDO frame of a node, with the node's transfer: the record is filled in as the frame says.
class sdo_step {
 public:
  sdo_step(decoded_frame& d, decoder::node_state& n, std::uint8_t node_id)
      : d_(d), n_(n), t_(n.sdo), id_(node_id), table_(n.table.get()), s_{d.raw.data.data()} {}

  void request();
  void response();

 private:
  void object(std::uint16_t index, std::uint8_t sub) {
    d_.has_object = true;
    d_.index = index;
    d_.sub = sub;
  }
  std::string named(std::uint16_t index, std::uint8_t sub) const {
    const std::string name = object_name(table_, index, sub);
    return object_ref(index, sub) + (name.empty() ? "" : " (" + name + ")");
  }
  std::string value(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> bytes) {
    d_.values.push_back(read_value(table_, index, sub, bytes));
    return describe(d_.values.back());
  }
  std::string segment(const char* direction) {
    const std::size_t size = s_.segment_size();
    const bool out_of_step = s_.toggle() != t_.toggle;
    t_.toggle ^= 1;
    t_.append({s_.d + 1, size});
    return std::string("SDO ") + direction + " " + object_ref(t_.index, t_.sub) + " segment, " +
           size_text(size) + (out_of_step ? " (toggle bit not alternated)" : "");
  }
  std::string whole(const char* direction) {
    const std::span<const std::uint8_t> kept(t_.data.data(), t_.data.size());
    std::string text = std::string("SDO ") + direction + " " + value(t_.index, t_.sub, kept) + ", " +
                       size_text(t_.total);
    if (t_.total > t_.data.size()) text += " (the first " + size_text(t_.data.size()) + " shown)";
    if (t_.size_indicated && t_.size != t_.total) text += " (" + size_text(t_.size) + " indicated)";
    return text;
  }
  void abort(const char* by) {
    object(s_.index(), s_.sub());
    d_.event = "abort";
    d_.code = static_cast<std::uint32_t>(get_le(s_.d + 4, 4));
    d_.code_text = sdo_abort_text(static_cast<sdo_abort>(d_.code));
    d_.text = "SDO abort " + object_ref(s_.index(), s_.sub()) + " " + hex(d_.code, 8) + " " + d_.code_text + by;
    t_.restart(phase::idle, 0, 0);
  }
  void learn_transfer() { learn(n_, id_, t_.index, t_.sub, {t_.data.data(), t_.data.size()}); }
  std::string announced_size() const {
    return t_.size_indicated ? size_text(t_.size) : std::string("size not indicated");
  }
  // An initiate that opens a segmented transfer of `what` ("download", "upload"): followed from here.
  void start_segments(phase p, const std::string& what) {
    t_.restart(p, s_.index(), s_.sub());
    t_.size_indicated = s_.size_indicated();
    t_.size = s_.size_indicated() ? static_cast<std::size_t>(get_le(s_.d + 4, 4)) : 0;
    d_.event = what + "-start";
    d_.text = "SDO " + what + " " + named(s_.index(), s_.sub()) + ", " + announced_size() + " in segments";
  }
  // Command specifier 7: CiA 301 gives it no meaning in either direction.
  void unknown_specifier(const char* side) {
    d_.kind = frame_kind::unknown;
    d_.event.clear();
    d_.text = std::string("SDO ") + side + " with command specifier 7, none of CiA 301's";
  }
  // Block transfer, followed like a segmented one: the segments of each block in
  // order, what each acknowledge says arrived, the value once the end says how much was data.
  void block_segment(const char* direction) {
    const std::uint8_t sequence = s_.d[0] & 0x7F;
    const bool last = (s_.d[0] & 0x80) != 0;
    object(t_.index, t_.sub);
    d_.event = std::string("block-") + direction + "-segment";
    const bool in_order = sequence == t_.sequence + 1;
    if (in_order) {
      t_.sequence = sequence;
      t_.append({s_.d + 1, 7});
      t_.last_in_order = last;
    }
    d_.text = std::string("SDO block ") + direction + " " + object_ref(t_.index, t_.sub) + " segment " +
              std::to_string(sequence) + (last ? ", the last" : "") + (in_order ? "" : " (out of sequence: sent again)");
  }
  // `last_acknowledged`: the phase once the block with the last segment is acknowledged whole.
  void block_acknowledge(const char* direction, phase last_acknowledged) {
    object(t_.index, t_.sub);
    d_.event = std::string("block-") + direction + "-acknowledge";
    const std::uint8_t acknowledged = s_.d[1];
    const bool short_block = acknowledged < t_.sequence;
    t_.keep_acknowledged(acknowledged);
    if (t_.last_in_order) {
      t_.at = last_acknowledged;
    }
    d_.text = std::string("SDO block ") + direction + " " + object_ref(t_.index, t_.sub) + " block acknowledged at segment " +
              std::to_string(acknowledged) + (short_block ? " (the rest sent again)" : "") + ", next block " +
              std::to_string(s_.d[2]) + " segments";
  }
  void block_request();
  void block_response();

  decoded_frame& d_;
  decoder::node_state& n_;
  sdo_follow& t_;
  std::uint8_t id_;
  const object_table* table_;
  sdo_frame s_;
};

void sdo_step::block_request() {
  object(s_.index(), s_.sub());
  if (s_.cs() == ccs_block_download && (s_.d[0] & 0x01) == 0) {  // 110 00 cc s 0: initiate
    t_.restart(phase::block_download_requested, s_.index(), s_.sub());
    t_.size_indicated = (s_.d[0] & 0x02) != 0;
    t_.size = t_.size_indicated ? static_cast<std::size_t>(get_le(s_.d + 4, 4)) : 0;
    d_.event = "block-download-start";
    d_.text = "SDO block download " + named(s_.index(), s_.sub()) + ", " + announced_size() +
              ((s_.d[0] & 0x04) ? ", CRC offered" : "");
    return;
  }
  if (s_.cs() == ccs_block_download) {  // 110 n 0 1: end
    d_.event = "block-download-end";
    if (t_.at != phase::block_download_acknowledged) {
      d_.text = "SDO block download end, with no block download acknowledged to its last segment";
      return;
    }
    object(t_.index, t_.sub);
    t_.drop_unused((s_.d[0] >> 2) & 0x07);
    t_.at = phase::block_download_ending;
    d_.text = "SDO block download " + object_ref(t_.index, t_.sub) + " end, CRC " + hex(get_le(s_.d + 1, 2), 4);
    return;
  }
  switch (s_.d[0] & 0x03) {  // block upload: 101 00 cc cs
    case 0:
      t_.restart(phase::block_upload_requested, s_.index(), s_.sub());
      d_.event = "block-upload-request";
      d_.text = "SDO block upload request " + named(s_.index(), s_.sub()) + ", blocks of " + std::to_string(s_.d[4]) +
                " segments" + (s_.d[5] ? ", ordinary up to " + size_text(s_.d[5]) : "") + ((s_.d[0] & 0x04) ? ", CRC offered" : "");
      return;
    case 3:
      d_.event = "block-upload-start";
      if (t_.at != phase::block_upload_answered) {
        d_.text = "SDO block upload start, with no block upload open";
        return;
      }
      object(t_.index, t_.sub);
      t_.at = phase::block_upload_segments;
      d_.text = "SDO block upload " + object_ref(t_.index, t_.sub) + " start";
      return;
    case 2:
      if (t_.at != phase::block_upload_segments) {
        d_.event = "block-upload-acknowledge";
        d_.text = "SDO block upload acknowledge, with no block upload open";
        return;
      }
      return block_acknowledge("upload", phase::block_upload_acknowledged);
    default:  // 1: the client's end response
      d_.event = "block-upload-done";
      if (t_.at != phase::block_upload_ending) {
        d_.text = "SDO block upload end response, with no block upload ending";
        return;
      }
      object(t_.index, t_.sub);
      d_.text = "SDO block upload " + object_ref(t_.index, t_.sub) + " done";
      t_.restart(phase::idle, 0, 0);
      return;
  }
}

void sdo_step::block_response() {
  if (s_.cs() == scs_block_download) {  // 101 00 sc ss
    switch (s_.d[0] & 0x03) {
      case 0:
        d_.event = "block-download-start";
        if (t_.at != phase::block_download_requested) {
          d_.text = "SDO block download accepted, with no block download seen";
          return;
        }
        object(t_.index, t_.sub);
        t_.at = phase::block_download_segments;
        d_.text = "SDO block download " + object_ref(t_.index, t_.sub) + " accepted, blocks of " +
                  std::to_string(s_.d[4]) + " segments" + ((s_.d[0] & 0x04) ? ", CRC offered" : "");
        return;
      case 2:
        if (t_.at != phase::block_download_segments) {
          d_.event = "block-download-acknowledge";
          d_.text = "SDO block download acknowledge, with no block download open";
          return;
        }
        return block_acknowledge("download", phase::block_download_acknowledged);
      default:
        d_.event = "download-done";
        if (t_.at != phase::block_download_ending) {
          d_.text = "SDO block download done, with no block download seen";
          return;
        }
        object(t_.index, t_.sub);
        learn_transfer();
        d_.text = "SDO block download " + whole("download").substr(std::string("SDO download ").size()) + ", done";
        t_.restart(phase::idle, 0, 0);
        return;
    }
  }
  // Block upload: 110 00 sc s 0 (the size) or 110 n 0 1 (the end).
  object(s_.index(), s_.sub());
  if ((s_.d[0] & 0x01) == 0) {
    d_.event = "block-upload-answer";
    if (t_.at != phase::block_upload_requested) {
      d_.text = "SDO block upload answer, with no block upload asked for";
      return;
    }
    t_.size_indicated = (s_.d[0] & 0x02) != 0;
    t_.size = t_.size_indicated ? static_cast<std::size_t>(get_le(s_.d + 4, 4)) : 0;
    t_.at = phase::block_upload_answered;
    d_.text = "SDO block upload " + named(t_.index, t_.sub) + ", " + announced_size() + " in blocks" +
              ((s_.d[0] & 0x04) ? ", CRC offered" : "");
    return;
  }
  d_.event = "upload";
  if (t_.at != phase::block_upload_acknowledged) {
    d_.text = "SDO block upload end, with no block upload acknowledged to its last segment";
    return;
  }
  object(t_.index, t_.sub);
  t_.drop_unused((s_.d[0] >> 2) & 0x07);
  learn_transfer();
  d_.text = "SDO block " + whole("upload").substr(std::string("SDO ").size()) + ", CRC " + hex(get_le(s_.d + 1, 2), 4);
  t_.at = phase::block_upload_ending;
}

void sdo_step::request() {
  // Inside a block download the client's first byte is a sequence number (a last segment's looks
  // like an abort's command specifier); only 0x80 is the abort.
  if (t_.at == phase::block_download_segments && s_.d[0] != 0x80) return block_segment("download");
  switch (s_.cs()) {
    case ccs_initiate_download:
      object(s_.index(), s_.sub());
      if (s_.expedited()) {
        t_.restart(phase::download_expedited, s_.index(), s_.sub());
        t_.append({s_.d + 4, s_.expedited_size()});
        d_.event = "download";
        d_.text = "SDO download " + value(s_.index(), s_.sub(), {s_.d + 4, s_.expedited_size()});
        return;
      }
      start_segments(phase::download_initiated, "download");
      return;
    case ccs_download_segment:
      d_.event = "download-segment";
      if (t_.at != phase::download_initiated && t_.at != phase::download_segments) {
        d_.text = "SDO download segment, " + size_text(s_.segment_size()) + ", with no download open";
        return;
      }
      object(t_.index, t_.sub);
      d_.text = segment("download");
      t_.at = s_.last() ? phase::download_last_sent : phase::download_segments;
      if (s_.last()) d_.text = whole("download") + ", the last segment";
      return;
    case ccs_initiate_upload:
      object(s_.index(), s_.sub());
      t_.restart(phase::upload_requested, s_.index(), s_.sub());
      d_.event = "upload-request";
      d_.text = "SDO upload request " + named(s_.index(), s_.sub());
      return;
    case ccs_upload_segment:
      d_.event = "upload-segment-request";
      if (t_.at != phase::upload_segments) {
        d_.text = "SDO upload segment request with no upload open";
        return;
      }
      object(t_.index, t_.sub);
      d_.text = "SDO upload " + object_ref(t_.index, t_.sub) + " segment request";
      return;
    case cs_abort: return abort(" (by the client)");
    case ccs_block_upload:
    case ccs_block_download: return block_request();
    default: return unknown_specifier("request");
  }
}

void sdo_step::response() {
  if (t_.at == phase::block_upload_segments && s_.d[0] != 0x80) return block_segment("upload");
  switch (s_.cs()) {
    case scs_initiate_download: {
      object(s_.index(), s_.sub());
      const bool ours = t_.index == s_.index() && t_.sub == s_.sub();
      if (t_.at == phase::download_initiated && ours) {
        t_.at = phase::download_segments;
        d_.event = "download-start";
        d_.text = "SDO download " + object_ref(s_.index(), s_.sub()) + " accepted, segments follow";
        return;
      }
      d_.event = "download-done";
      d_.text = "SDO download " + object_ref(s_.index(), s_.sub()) + " done";
      if (t_.at == phase::download_expedited && ours) learn_transfer();
      else d_.text += " (its request was not seen)";
      t_.restart(phase::idle, 0, 0);
      return;
    }
    case scs_download_segment:
      d_.event = "download-done";
      if (t_.at == phase::download_last_sent) {
        object(t_.index, t_.sub);
        learn_transfer();
        d_.text = "SDO download " + object_ref(t_.index, t_.sub) + " done, " + size_text(t_.total);
        t_.restart(phase::idle, 0, 0);
      } else if (t_.at == phase::download_segments) {
        object(t_.index, t_.sub);
        d_.event = "download-segment";
        d_.text = "SDO download " + object_ref(t_.index, t_.sub) + " segment confirmed";
      } else {
        d_.text = "SDO download segment confirmed, with no download seen";
      }
      return;
    case scs_initiate_upload:
      object(s_.index(), s_.sub());
      if (s_.expedited()) {
        const std::span<const std::uint8_t> bytes(s_.d + 4, s_.expedited_size());
        learn(n_, id_, s_.index(), s_.sub(), bytes);
        d_.event = "upload";
        d_.text = "SDO upload " + value(s_.index(), s_.sub(), bytes);
        t_.restart(phase::idle, 0, 0);
        return;
      }
      start_segments(phase::upload_segments, "upload");
      return;
    case scs_upload_segment:
      d_.event = "upload-segment";
      if (t_.at != phase::upload_segments) {
        d_.text = "SDO upload segment, " + size_text(s_.segment_size()) + ", with no upload open";
        return;
      }
      object(t_.index, t_.sub);
      d_.text = segment("upload");
      if (s_.last()) {
        d_.event = "upload";
        learn_transfer();
        d_.text = whole("upload");
        t_.restart(phase::idle, 0, 0);
      }
      return;
    case cs_abort: return abort("");
    case scs_block_download:
    case scs_block_upload: return block_response();
    default: return unknown_specifier("response");
  }
}

}  // namespace

void decoder::decode_sdo(decoded_frame& d, bool from_server) {
  const frame& f = d.raw;
  const auto id = static_cast<std::uint8_t>(f.id & 0x7F);
  d.node = id;
  if (f.rtr || f.len != 8) {
    d.kind = frame_kind::unknown;
    d.text = std::string("SDO ") + (from_server ? "response" : "request") + " of " + size_text(f.len) +
             (f.rtr ? " (a remote request)" : "") + ": CiA 301 sends 8";
    return;
  }
  d.kind = frame_kind::sdo;
  sdo_step step(d, node(id), id);
  if (from_server) step.response(); else step.request();
}

}  // namespace cia402::canopen::monitor
