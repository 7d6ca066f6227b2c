#include "cia402/ethercat/master/ecat_master.hpp"

#include <algorithm>
#include <cstring>

#include "cia402/ethercat/coe/mailbox.hpp"
#include "cia402/ethercat/coe/sdo.hpp"
#include "cia402/objects.hpp"
#include "master_text.hpp"

namespace cia402::ethercat {
namespace {

using detail::hex;
using detail::max_mapped_entries;
using detail::put_le;
using detail::reg_fmmu0;
using detail::reg_sm0;
using detail::mailbox_us;
using detail::poll_us;
using detail::slave_text;

// Registers (ETG.1000.4 table 29 ff.), written out here rather than taken from the emulated ESC:
// the master is for any slave controller.
constexpr std::uint16_t reg_type = 0x0000;
constexpr std::uint16_t reg_station = 0x0010;
constexpr std::uint16_t reg_al_control = 0x0120;
constexpr std::uint16_t reg_al_status = 0x0130;
constexpr std::uint16_t reg_eeprom_config = 0x0500;
constexpr std::uint16_t reg_eeprom_control = 0x0502;
constexpr std::uint16_t reg_dc_system_time = 0x0910;
constexpr std::uint16_t eeprom_busy = 0x8000;
constexpr std::uint16_t eeprom_read_8 = 0x0040;
constexpr std::uint16_t eeprom_errors = 0x6800;  // command error, checksum error, acknowledge error
constexpr std::uint8_t al_error_bit = 0x10;
constexpr std::uint16_t first_station = 0x1001;
constexpr std::uint32_t logical_base = 0x00010000;

// Limits in link time: a slave that has not done it by then will not.
constexpr std::uint64_t state_change_us = 5'000'000;  // PRE-OP -> SAFE-OP may load a drive's parameters
constexpr std::uint64_t eeprom_us = 100'000;
constexpr std::size_t sii_max_bytes = 8192;
// A mailbox: 6 bytes of header, then CoE's 2 and an SDO's 8 at least, so an expedited SDO fits.
constexpr std::size_t smallest_coe_mailbox = mailbox_header_size + coe_header_size + sdo_header_size;
// A mailbox is read or written in one datagram of one frame.
constexpr std::size_t largest_mailbox = maximum_frame_size - ethernet_header_size - ethercat_header_size -
                                        datagram_header_size - working_counter_size;

const std::array<std::uint8_t, 6> broadcast{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
const std::array<std::uint8_t, 6> master_mac{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};

std::uint16_t le16(const std::uint8_t* p) noexcept { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
std::vector<std::uint8_t> le_bytes(std::uint64_t value, unsigned bytes) {
  std::vector<std::uint8_t> v;
  put_le(v, value, bytes);
  return v;
}

// Bits of the process image, little-endian as EtherCAT carries them. A place outside the image
// reads 0 and takes no write: the layout comes from a slave and is checked where it is learnt, so
// this is the last line of defence, not the check.
bool inside(const std::vector<std::uint8_t>& image, std::size_t bit, unsigned bits) {
  return bits <= 64 && bit + bits <= image.size() * 8;
}
std::uint64_t get_bits(const std::vector<std::uint8_t>& image, std::size_t bit, unsigned bits) {
  std::uint64_t v = 0;
  if (!inside(image, bit, bits)) return v;
  for (unsigned i = 0; i < bits; ++i) {
    const std::size_t b = bit + i;
    if ((image[b / 8] >> (b % 8)) & 1u) v |= std::uint64_t{1} << i;
  }
  return v;
}
void put_bits(std::vector<std::uint8_t>& image, std::size_t bit, unsigned bits, std::uint64_t v) {
  if (!inside(image, bit, bits)) return;
  for (unsigned i = 0; i < bits; ++i) {
    const std::size_t b = bit + i;
    const auto mask = static_cast<std::uint8_t>(1u << (b % 8));
    image[b / 8] = static_cast<std::uint8_t>(((v >> i) & 1u) ? (image[b / 8] | mask) : (image[b / 8] & ~mask));
  }
}

}  // namespace

const char* line_state_name(std::uint8_t al_state) noexcept {
  switch (al_state & 0x0F) {
    case 1: return "INIT";
    case 2: return "PRE-OP";
    case 3: return "BOOT";
    case 4: return "SAFE-OP";
    case 8: return "OP";
    default: return "UNKNOWN";
  }
}

const char* al_status_code_text(std::uint16_t code) noexcept {
  switch (code) {
    case 0x0000: return "no error";
    case 0x0001: return "unspecified error";
    case 0x0011: return "invalid requested state change";
    case 0x0012: return "unknown requested state";
    case 0x0013: return "bootstrap not supported";
    case 0x0014: return "no valid firmware";
    case 0x0015: return "invalid mailbox configuration (bootstrap)";
    case 0x0016: return "invalid mailbox configuration";
    case 0x0017: return "invalid sync manager configuration";
    case 0x001A: return "synchronization error";
    case 0x001B: return "sync manager watchdog";
    case 0x001D: return "invalid output configuration";
    case 0x001E: return "invalid input configuration";
    case 0x0024: return "invalid input mapping";
    case 0x0025: return "invalid output mapping";
    case 0x002D: return "no sync error (no SYNC0 pulse came)";
    case 0x0030: return "invalid DC sync configuration";
    default: return "unknown AL status code";
  }
}

std::int64_t ecat_sdo_result::value(bool is_signed) const noexcept {
  std::uint64_t v = 0;
  const std::size_t n = std::min<std::size_t>(data.size(), 8);
  for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(data[i]) << (8 * i);
  if (is_signed && n > 0 && n < 8 && (data[n - 1] & 0x80)) v |= ~std::uint64_t{0} << (8 * n);
  return static_cast<std::int64_t>(v);
}

ecat_master::ecat_master(master_link& link, const profile& p, std::uint32_t cycle_us)
    : link_(&link), profile_(&p), cycle_us_(cycle_us) {}

bool ecat_master::fail(std::string text) {
  error_ = std::move(text);
  return false;
}

ecat_master::single ecat_master::one(command cmd, std::uint32_t address, std::vector<std::uint8_t> data) {
  frame_builder b(broadcast, master_mac);
  const auto length = static_cast<std::uint16_t>(data.size());
  const long at = b.add(cmd, ++index_, address, data, length);
  single r;
  if (at < 0) return r;
  std::vector<std::uint8_t> f = b.finish();
  std::vector<std::uint8_t> sent;
  if (on_frame) sent = f;  // a copy only for a capture
  if (!link_->exchange(f) || f.size() < static_cast<std::size_t>(at) + length + 2) {
    ++lost_frames_;
    return r;
  }
  if (on_frame) on_frame(sent, f);
  const auto* d = f.data() + at;
  r.ok = true;
  r.data.assign(d, d + length);
  r.wkc = le16(d + length);
  return r;
}

ecat_master::single ecat_master::read_register(const ecat_slave& s, std::uint16_t reg, std::uint16_t length) {
  return one(command::fprd, s.station | (static_cast<std::uint32_t>(reg) << 16), std::vector<std::uint8_t>(length, 0));
}

bool ecat_master::write_register(const ecat_slave& s, std::uint16_t reg, const std::vector<std::uint8_t>& data) {
  const single r = one(command::fpwr, s.station | (static_cast<std::uint32_t>(reg) << 16), data);
  return r.ok && r.wkc == 1;
}

// --- finding the slaves ----------------------------------------------------------------------------

bool ecat_master::scan() {
  slaves_.clear();
  dc_reference_.reset();
  pre_operational_ = false;
  cycling_ = false;
  image_.clear();
  error_.clear();
  const single count = one(command::brd, static_cast<std::uint32_t>(reg_type) << 16, {0, 0});
  if (!count.ok) return fail("no frame came back: is the interface connected to an EtherCAT line?");
  if (count.wkc == 0) return fail("no slave answered (BRD working counter 0)");
  // Every slave to INIT (acknowledging any error), then its FMMUs and sync managers cleared, as a
  // master starting afresh must: an earlier master may have left them set.
  (void)one(command::bwr, static_cast<std::uint32_t>(reg_al_control) << 16, {0x11, 0x00});
  (void)one(command::bwr, static_cast<std::uint32_t>(reg_fmmu0) << 16, std::vector<std::uint8_t>(16 * 8, 0));
  (void)one(command::bwr, static_cast<std::uint32_t>(reg_sm0) << 16, std::vector<std::uint8_t>(8 * 8, 0));
  for (std::uint16_t i = 0; i < count.wkc; ++i) {
    ecat_slave s;
    s.position = i;
    s.station = static_cast<std::uint16_t>(first_station + i);
    // Auto-increment addressing: the slave at position i is the one that sees ADP 0 after i others
    // have counted it up from -i.
    const single r = one(command::apwr, static_cast<std::uint16_t>(-static_cast<int>(i)) |
                                            (static_cast<std::uint32_t>(reg_station) << 16),
                         le_bytes(s.station, 2));
    if (!r.ok || r.wkc != 1) return fail("slave " + std::to_string(i) + " did not take its station address");
    slaves_.push_back(std::move(s));
  }
  for (ecat_slave& s : slaves_) {
    if (!read_sii(s)) return false;
  }
  for (ecat_slave& s : slaves_) (void)read_al_status(s);
  return true;
}

bool ecat_master::read_al_status(ecat_slave& s) {
  const single st = read_register(s, reg_al_status, 6);  // status, reserved, status code
  if (!st.ok || st.wkc != 1) return false;
  s.al_state = st.data[0];
  s.al_code = le16(st.data.data() + 4);
  return true;
}

bool ecat_master::read_sii(ecat_slave& s) {
  (void)write_register(s, reg_eeprom_config, {0x00, 0x00});  // the EEPROM to the EtherCAT side
  std::vector<std::uint8_t> image;
  // Words are read 4 or 8 bytes at a time, as the controller offers (0x0502 bit 6), until the
  // category end marker: the image's fixed part is 64 words, then categories (type, size in words).
  std::size_t category = 0x80;  // byte offset of the next category header
  bool ended = false;
  while (!ended && image.size() < sii_max_bytes) {
    const auto word = static_cast<std::uint32_t>(image.size() / 2);
    std::vector<std::uint8_t> request{0x00, 0x01};  // command: read
    put_le(request, word, 4);
    if (!write_register(s, reg_eeprom_control, request)) {
      return fail(slave_text(s) + ": the SII EEPROM interface refused a read of word " + std::to_string(word));
    }
    std::vector<std::uint8_t> status;
    for (const std::uint64_t start = link_->now_us();;) {
      const single r = read_register(s, reg_eeprom_control, 14);  // control, address, data
      if (r.ok && r.wkc == 1 && !(le16(r.data.data()) & eeprom_busy)) {
        status = r.data;
        break;
      }
      if (link_->now_us() - start > eeprom_us) return fail(slave_text(s) + ": the SII EEPROM stays busy");
      link_->wait_us(poll_us);
    }
    const std::uint16_t control = le16(status.data());
    if (control & eeprom_errors) {
      return fail(slave_text(s) + ": SII read of word " + std::to_string(word) + " failed (EEPROM status " +
                  hex(control, 4) + ")");
    }
    const std::size_t got = (control & eeprom_read_8) ? 8 : 4;
    image.insert(image.end(), status.begin() + 6, status.begin() + 6 + static_cast<long>(got));
    while (!ended && image.size() >= category + 4) {
      const std::uint16_t type = le16(image.data() + category);
      if (type == 0xFFFF) {
        ended = true;
      } else {
        category += 4 + 2u * le16(image.data() + category + 2);
      }
    }
  }
  std::string why;
  auto d = parse_sii(image, why);
  if (!d) return fail(slave_text(s) + ": its SII does not read as one: " + why);
  s.sii = std::move(*d);
  return true;
}

// --- AL states ---------------------------------------------------------------------------------------

bool ecat_master::request_state(line_state target, bool cycling) {
  const auto want = static_cast<std::uint8_t>(target);
  // Slave by slave, a request and a status read are a round trip each: with the line cycling, the
  // LRW goes on between them (pause), so a slave already in OP never waits for the whole line's
  // round trips to see its outputs (a loaded host made that longer than the 100 ms watchdog).
  for (ecat_slave& s : slaves_) {
    if (cycling) pause(0);
    // An error left from before is acknowledged with the request (bit 4).
    const std::uint8_t ack = (s.al_state & al_error_bit) ? al_error_bit : 0;
    if (!write_register(s, reg_al_control, {static_cast<std::uint8_t>(want | ack), 0x00})) {
      return fail(slave_text(s) + " did not take the request for " + line_state_name(want));
    }
  }
  // A slave is there when a status read made after the request shows the state: what was recorded
  // before it (the state already held, say) proves nothing, and neither does a read that was lost.
  std::vector<bool> confirmed(slaves_.size(), false);
  std::vector<bool> answered(slaves_.size(), false);
  const std::uint64_t start = link_->now_us();
  for (;;) {
    bool all = true;
    for (std::size_t i = 0; i < slaves_.size(); ++i) {
      ecat_slave& s = slaves_[i];
      if (cycling) pause(0);
      if (!read_al_status(s)) {
        all = all && confirmed[i];
        continue;
      }
      answered[i] = true;
      if (s.al_state & al_error_bit) {
        return fail(slave_text(s) + " refused " + line_state_name(want) + ": AL status code " + hex(s.al_code, 4) +
                    " (" + al_status_code_text(s.al_code) + "), stays in " + line_state_name(s.al_state));
      }
      confirmed[i] = (s.al_state & 0x0F) == want;
      all = all && confirmed[i];
    }
    if (all) return true;
    if (link_->now_us() - start > state_change_us) {
      for (std::size_t i = 0; i < slaves_.size(); ++i) {
        if (confirmed[i]) continue;
        const ecat_slave& s = slaves_[i];
        if (!answered[i]) {
          return fail(slave_text(s) + " did not answer a read of its AL status while going to " +
                      line_state_name(want) + " (" + std::to_string(state_change_us / 1000) + " ms)");
        }
        return fail(slave_text(s) + " did not reach " + line_state_name(want) + " in time (still " +
                    line_state_name(s.al_state) + ")");
      }
      return fail(std::string("the line did not reach ") + line_state_name(want) + " in time");  // not reached: all was true
    }
    if (cycling) {
      (void)cycle();
      link_->wait_us(cycle_us_);
    } else {
      link_->wait_us(poll_us);
    }
  }
}

bool ecat_master::configure_mailbox(ecat_slave& s) {
  const slave_description& d = s.sii;
  if (!d.coe || d.mailbox_out_size == 0 || d.mailbox_in_size == 0) return true;  // no CoE: SII only
  // Sizes from the slave's SII: a mailbox that cannot hold an SDO, or one datagram cannot carry,
  // is a slave the master cannot talk to, said now rather than found out reading past a reply.
  for (const auto& [what, size] : {std::pair{"receive", d.mailbox_out_size}, std::pair{"send", d.mailbox_in_size}}) {
    if (size < smallest_coe_mailbox || size > largest_mailbox) {
      return fail(slave_text(s) + ": its SII gives a " + what + " mailbox of " + std::to_string(size) +
                  " bytes; CoE needs " + std::to_string(smallest_coe_mailbox) + " to " +
                  std::to_string(largest_mailbox));
    }
  }
  const auto sm_control = [&](int n, std::uint8_t fallback) {
    return n < static_cast<int>(d.sync_managers.size()) && d.sync_managers[static_cast<std::size_t>(n)].control != 0
               ? d.sync_managers[static_cast<std::size_t>(n)].control
               : fallback;
  };
  std::vector<std::uint8_t> sm;
  put_le(sm, d.mailbox_out_start, 2);
  put_le(sm, d.mailbox_out_size, 2);
  sm.insert(sm.end(), {sm_control(0, 0x26), 0x00, 0x01, 0x00});
  put_le(sm, d.mailbox_in_start, 2);
  put_le(sm, d.mailbox_in_size, 2);
  sm.insert(sm.end(), {sm_control(1, 0x22), 0x00, 0x01, 0x00});
  if (!write_register(s, reg_sm0, sm)) return fail(slave_text(s) + " did not take its mailbox sync managers");
  s.mailbox = true;
  return true;
}

bool ecat_master::bring_to_pre_operational() {
  if (slaves_.empty()) return fail("no slaves: scan first");
  // PRE-OP has no process data, and the mapping may change in it: the image is left behind with
  // OP, so no cycle (nor an SDO's pause) writes a layout into an image it was not built for.
  stop_cycling();
  for (ecat_slave& s : slaves_) {
    if (!configure_mailbox(s)) return false;
  }
  pre_operational_ = request_state(line_state::pre_operational, false);
  return pre_operational_;
}

bool ecat_master::bring_to_operational() {
  if (!pre_operational_ && !bring_to_pre_operational()) return false;
  pre_operational_ = false;
  stop_cycling();
  std::uint32_t logical = logical_base;
  expected_wkc_ = 0;
  for (ecat_slave& s : slaves_) {
    if (!learn_mapping(s) || !configure_process_data(s, logical)) return false;
    // ETG.1000.4: an LRW counts 1 for a slave's read FMMU and 2 for its write FMMU.
    expected_wkc_ = static_cast<std::uint16_t>(expected_wkc_ + (s.output_bytes ? 2 : 0) + (s.input_bytes ? 1 : 0));
  }
  image_.assign(logical - logical_base, 0);
  // The image in LRWs of whole slaves (SOEM splits its image the same way): the first frame also
  // carries the AL status BRD (2 bytes), the clock's FRMW (8) and one SM1 status read (1).
  const std::size_t frame_room = maximum_frame_size - ethernet_header_size - ethercat_header_size -
                                 datagram_header_size - working_counter_size;
  const std::size_t first_room = frame_room - 3 * (datagram_header_size + working_counter_size) - 2 - 8 - 1;
  parts_.clear();
  for (const ecat_slave& s : slaves_) {
    const std::size_t bytes = std::size_t{s.output_bytes} + s.input_bytes;
    const std::uint16_t wkc = static_cast<std::uint16_t>((s.output_bytes ? 2 : 0) + (s.input_bytes ? 1 : 0));
    if (bytes > first_room) return fail(slave_text(s) + ": its process data does not fit one frame");
    if (parts_.empty() || parts_.back().length + bytes > (parts_.size() == 1 ? first_room : frame_room)) {
      parts_.push_back({static_cast<std::size_t>(s.logical_outputs - logical_base), 0, 0});
    }
    parts_.back().length += bytes;
    parts_.back().wkc = static_cast<std::uint16_t>(parts_.back().wkc + wkc);
  }
  // The outputs start as the drive has them, so running the line commands nothing by itself: the
  // control word it last got, the set-points and mode it holds (a zero 0x6060 or 0x60FF would).
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    ecat_slave& s = slaves_[i];
    for (const ecat_slave::mapped_object& o : s.outputs) {
      if (o.index == 0 || !s.mailbox || o.bits == 0 || o.bits > 32) continue;
      const ecat_sdo_result v = sdo_read(i, o.index, o.sub);
      if (!v.ok) continue;
      put_bits(image_, (s.logical_outputs - logical_base) * 8u + o.bit_offset, o.bits,
               static_cast<std::uint64_t>(v.value(false)));
    }
    s.last_control = static_cast<std::uint16_t>(
        get_bits(image_, (s.logical_outputs - logical_base) * 8u + s.control_word->bit_offset, 16));
  }
  // Clocks and SYNC0 before SAFE-OP, where a drive chooses its sync mode.
  if (!configure_distributed_clocks()) return false;
  cycling_ = true;
  // Outputs are valid before SAFE-OP -> OP: the drives get them from the first cycle on.
  if (!request_state(line_state::safe_operational, true)) return false;
  return request_state(line_state::operational, true);
}

bool ecat_master::leave_operational() {
  stop_cycling();
  pre_operational_ = request_state(line_state::pre_operational, false);
  return pre_operational_;
}

void ecat_master::pause(std::uint32_t us) {
  if (cycling_ && link_->now_us() - last_cycle_us_ >= cycle_us_) (void)cycle();
  if (us != 0) link_->wait_us(us);
}

void ecat_master::send_control_word(std::size_t i, std::uint16_t word) { slaves_.at(i).last_control = word; }

std::optional<std::int64_t> ecat_master::input(std::size_t i, std::uint16_t index, std::uint8_t sub) const {
  const ecat_slave& s = slaves_.at(i);
  if (image_.empty()) return std::nullopt;
  for (const ecat_slave::mapped_object& o : s.inputs) {
    if (o.index != index || o.sub != sub || o.bits == 0 || o.bits > 32) continue;
    const std::uint64_t raw = get_bits(image_, (s.logical_inputs - logical_base) * 8u + o.bit_offset, o.bits);
    const object_description* d = find_drive_object(index, sub);
    const bool is_signed = d != nullptr && type_is_signed(d->type);
    if (is_signed && o.bits < 64 && ((raw >> (o.bits - 1)) & 1u)) {
      return static_cast<std::int64_t>(raw | (~std::uint64_t{0} << o.bits));
    }
    return static_cast<std::int64_t>(raw);
  }
  return std::nullopt;
}

bool ecat_master::set_output(std::size_t i, std::uint16_t index, std::int64_t value, std::uint8_t sub) {
  ecat_slave& s = slaves_.at(i);
  if (image_.empty()) return false;
  for (const ecat_slave::mapped_object& o : s.outputs) {
    if (o.index != index || o.sub != sub || o.bits == 0 || o.bits > 32) continue;
    put_bits(image_, (s.logical_outputs - logical_base) * 8u + o.bit_offset, o.bits, static_cast<std::uint64_t>(value));
    if (index == 0x6040 && sub == 0) send_control_word(i, static_cast<std::uint16_t>(value));
    return true;
  }
  return false;
}

bool ecat_master::all_operational() const noexcept {
  if (slaves_.empty()) return false;
  for (const ecat_slave& s : slaves_) {
    if (s.al_state != static_cast<std::uint8_t>(line_state::operational)) return false;
  }
  return true;
}

void ecat_master::stop_cycling() {
  cycling_ = false;
  image_.clear();
  line_was_operational_ = false;
}

// One LRW of a part of the image in a frame of its own: its answer into `back`, its working
// counter added to `wkc`; the first part whose counter is wrong is named in `wrong`.
bool ecat_master::exchange_part(const image_part& part, std::vector<std::uint8_t>& back, std::uint16_t& wkc,
                                std::string& wrong) {
  frame_builder b(broadcast, master_mac);
  const long lrw = b.add(command::lrw, ++index_, static_cast<std::uint32_t>(logical_base + part.offset),
                         std::span<const std::uint8_t>(image_.data() + part.offset, part.length),
                         static_cast<std::uint16_t>(part.length));
  std::vector<std::uint8_t> f = b.finish();
  std::vector<std::uint8_t> sent;
  if (on_frame) sent = f;
  if (lrw < 0 || !link_->exchange(f) || f.size() < static_cast<std::size_t>(lrw) + part.length + 2) {
    ++lost_frames_;
    error_ = "a cycle's frame did not come back (the LRW of image bytes " + std::to_string(part.offset) + ".." +
             std::to_string(part.offset + part.length - 1) + ")";
    return false;
  }
  if (on_frame) on_frame(sent, f);
  std::copy(f.begin() + lrw, f.begin() + lrw + static_cast<std::ptrdiff_t>(part.length),
            back.begin() + static_cast<std::ptrdiff_t>(part.offset));
  const std::uint16_t got = le16(f.data() + lrw + part.length);
  if (got != part.wkc && wrong.empty()) {
    wrong = "working counter " + std::to_string(got) + " of the LRW of image bytes " + std::to_string(part.offset) +
             ".." + std::to_string(part.offset + part.length - 1) + ", expected " + std::to_string(part.wkc);
  }
  wkc = static_cast<std::uint16_t>(wkc + got);
  return true;
}

bool ecat_master::cycle() {
  if (!cycling_) {
    error_ = "no process data to exchange: bring the line to OP first";
    return false;
  }
  const std::uint64_t now = link_->now_us();
  last_cycle_us_ = now;
  for (ecat_slave& s : slaves_) {
    if (!s.control_word) continue;
    put_bits(image_, (s.logical_outputs - logical_base) * 8u + s.control_word->bit_offset, 16, s.last_control);
  }
  std::vector<std::uint8_t> back(image_.size(), 0);
  std::uint16_t wkc = 0;
  std::string wrong;
  // The image's later parts first, each in a frame of its own (a line whose image one frame cannot
  // hold); the first travels with the AL status, read once every drive has this cycle's outputs.
  for (std::size_t k = 1; k < parts_.size(); ++k) {
    if (!exchange_part(parts_[k], back, wkc, wrong)) {
      ++cycles_;
      return false;
    }
  }
  const image_part head = parts_.empty() ? image_part{} : parts_.front();
  frame_builder b(broadcast, master_mac);
  const long lrw = b.add(command::lrw, ++index_, static_cast<std::uint32_t>(logical_base + head.offset),
                         std::span<const std::uint8_t>(image_.data() + head.offset, head.length),
                         static_cast<std::uint16_t>(head.length));
  const long al = b.add(command::brd, ++index_, static_cast<std::uint32_t>(reg_al_status) << 16, {}, 2);
  // The drift distribution: the reference clock's system time to every other DC slave.
  if (dc_reference_) {
    (void)b.add(command::frmw, ++index_, slaves_[*dc_reference_].station | (std::uint32_t{reg_dc_system_time} << 16), {}, 8);
  }
  // One slave a cycle, in turn: is its send mailbox full (SM1 status bit 3)? Then an emergency (or
  // anything else it sent unasked) is fetched after the cycle.
  ecat_slave* asked = slaves_.empty() || in_mailbox_ ? nullptr : &slaves_[cycles_ % slaves_.size()];
  if (asked != nullptr && !asked->mailbox) asked = nullptr;
  const long sm1 = asked == nullptr ? -1
                                    : b.add(command::fprd, ++index_,
                                            asked->station | (static_cast<std::uint32_t>(reg_sm0 + 8 + 5) << 16), {}, 1);
  std::vector<std::uint8_t> f = b.finish();
  std::vector<std::uint8_t> sent;
  if (on_frame) sent = f;
  ++cycles_;
  if (lrw < 0 || al < 0 || !link_->exchange(f) || f.size() < static_cast<std::size_t>(al) + 4) {
    ++lost_frames_;
    error_ = "a cycle's frame did not come back";
    return false;
  }
  if (on_frame) on_frame(sent, f);
  const std::uint8_t* data = f.data() + lrw;
  std::copy(data, data + head.length, back.begin() + static_cast<std::ptrdiff_t>(head.offset));
  const std::uint16_t head_wkc = le16(data + head.length);
  if (head_wkc != head.wkc && wrong.empty() && parts_.size() > 1) {
    wrong = "working counter " + std::to_string(head_wkc) + " of the LRW of image bytes 0.." +
             std::to_string(head.length - 1) + ", expected " + std::to_string(head.wkc);
  }
  last_wkc_ = static_cast<std::uint16_t>(wkc + head_wkc);
  const std::uint8_t line = f[static_cast<std::size_t>(al)];  // every slave's AL status, ORed
  if (sm1 >= 0 && static_cast<std::size_t>(sm1) + 3 <= f.size() && le16(f.data() + sm1 + 1) == 1 &&
      (f[static_cast<std::size_t>(sm1)] & 0x08)) {
    const single m = one(command::fprd, asked->station | (static_cast<std::uint32_t>(asked->sii.mailbox_in_start) << 16),
                         std::vector<std::uint8_t>(asked->sii.mailbox_in_size, 0));
    if (m.ok && m.wkc == 1) note_emergency(*asked, m.data);
  }
  if (last_wkc_ != expected_wkc_) {
    error_ = wrong.empty() ? "working counter " + std::to_string(last_wkc_) + ", expected " + std::to_string(expected_wkc_)
                           : wrong;
    return false;
  }
  for (ecat_slave& s : slaves_) {
    const std::size_t base = (s.logical_inputs - logical_base) * 8u;
    s.last_status = static_cast<std::uint16_t>(get_bits(back, base + s.status_word->bit_offset, 16));
    if (s.error_code) s.last_error_code = static_cast<std::uint16_t>(get_bits(back, base + s.error_code->bit_offset, 16));
    // Inputs are read back into the image; outputs stay as the master wrote them.
    std::copy(back.begin() + (s.logical_inputs - logical_base),
              back.begin() + (s.logical_inputs - logical_base) + s.input_bytes,
              image_.begin() + (s.logical_inputs - logical_base));
  }
  const bool operational = line == static_cast<std::uint8_t>(line_state::operational);
  if (operational) {
    for (ecat_slave& s : slaves_) s.al_state = line;
  } else if (line != 0 && (line_was_operational_ || (line & al_error_bit))) {
    // Somebody left OP or shows an error (a watchdog, a refusal): read each one's state and code.
    // Not while the line is on its way to OP: request_state() reads them, and a round trip per
    // slave in every cycle would space the LRWs out past the slaves' watchdog on a long line.
    for (ecat_slave& s : slaves_) (void)read_al_status(s);
  }
  line_was_operational_ = operational;
  return true;
}

}  // namespace cia402::ethercat
