// The drive master's set-up script: the SDO transfers that make a CiA 402 drive ready for PDOs,
// in the order drive_master.hpp gives, built once from the configuration.
#include <algorithm>

#include "cia402/canopen/master/drive_master.hpp"
#include "cia402/canopen/301/pdo.hpp"
#include "cia402/manufacturer_objects.hpp"
#include "cia402/objects.hpp"
#include "cia402/pdo_maps.hpp"
#include "cia402/support/text.hpp"

namespace cia402::canopen {
namespace {

bool is_signed_object(std::uint16_t index) {
  const object_description* o = find_drive_object(index);
  return o != nullptr && type_is_signed(o->type);
}

template <typename Job>
Job read_job(std::uint16_t index, bool optional) {
  Job j;
  j.index = index;
  j.optional = optional;
  j.is_signed = is_signed_object(index);
  return j;
}

// A write of `v` in `bytes`; one of a group (group != 0) is optional, and its refusal skips the
// rest of the group.
template <typename Job>
Job write_job(std::uint16_t index, std::uint8_t sub, std::int64_t v, unsigned bytes, int group = 0) {
  Job j;
  j.write = true;
  j.index = index;
  j.sub = sub;
  j.value = [v] { return v; };
  j.bytes = bytes;
  j.group = group;
  j.optional = group != 0;
  return j;
}

// CiA 301's order for a new mapping: sub-index 0 to 0, the entries, then their number.
template <typename Job>
void push_mapping(std::vector<Job>& script, std::uint16_t map_index, const pdo_map& m) {
  script.push_back(write_job<Job>(map_index, 0, 0, 1));
  for (std::uint8_t e = 0; e < m.count; ++e) {
    script.push_back(write_job<Job>(map_index, static_cast<std::uint8_t>(e + 1), m.entries[e].word(), 4));
  }
  script.push_back(write_job<Job>(map_index, 0, m.count, 1));
}

// A transfer's `then` that records whether it was done.
auto note_done(bool& worked) {
  return [&worked](const sdo_client& c) { worked = c.state() == sdo_client::status::done; };
}

}  // namespace

void drive_master::build_script() {
  script_identity();
  script_start_values();
  script_error_control();
  script_pdos();
  script_present_values();
  sdo_job start;
  start.nmt_start = true;
  script_.push_back(start);
}

// 0x1000 (a CiA 402 drive or none), 0x1008, and whether it is our virtual drive with 0x2001.
void drive_master::script_identity() {
  sdo_job type = read_job<sdo_job>(0x1000, false);
  type.then = [this](const sdo_client& c) {
    if ((c.value() & 0xFFFF) != 0x0192) {
      fail(master_failure::not_a_drive, sdo_abort::none, 0x1000, 0,
           node_text() + " is not a CiA 402 drive (0x1000 = " +
               support::hex(static_cast<std::uint32_t>(c.value()), 8) + ", low word not 0x0192)");
    }
  };
  script_.push_back(type);

  sdo_job name = read_job<sdo_job>(0x1008, true);
  name.then = [this](const sdo_client& c) {
    if (c.state() != sdo_client::status::done) return;
    device_name_.assign(c.data().begin(), c.data().end());
    while (!device_name_.empty() && device_name_.back() == '\0') device_name_.pop_back();
  };
  script_.push_back(name);

  // 0x2001 exists on a `cia402 bus` node as write-only: reading it says so and changes nothing.
  sdo_job probe = read_job<sdo_job>(fault_injection_index, true);
  probe.wanted = [this] { return device_name_ == virtual_drive_device_name; };
  probe.then = [this](const sdo_client& c) {
    fault_injection_ = c.state() == sdo_client::status::aborted &&
                       c.abort_code() == sdo_abort::write_only_object;
  };
  script_.push_back(probe);
}

// The option codes (the core's list, 0x605A..0x605E and 0x6007) and what the configuration reads at
// start, each kept as the drive had it.
void drive_master::script_start_values() {
  const auto keep_value = [this](std::uint16_t index, bool is_signed) {
    return [this, index, is_signed](const sdo_client& c) {
      if (c.state() == sdo_client::status::done) {
        start_values_[index] = c.value(is_signed);
      } else {
        start_values_.erase(index);
      }
    };
  };
  for (int o = 0; o < option_count; ++o) {
    const std::uint16_t index = option_index(static_cast<option>(o));
    sdo_job s = read_job<sdo_job>(index, true);
    const auto keep = keep_value(index, true);
    s.then = [this, index, keep](const sdo_client& c) {
      keep(c);
      if (c.state() == sdo_client::status::done) {
        (void)write_option(*profile_, options_, index, static_cast<std::int32_t>(c.value(true)));
      }
    };
    script_.push_back(s);
  }
  for (const std::uint16_t index : config_.read_at_start) {
    option already_read;
    if (option_of_index(index, already_read)) continue;  // read above
    sdo_job s = read_job<sdo_job>(index, true);
    s.then = keep_value(index, s.is_signed);
    script_.push_back(s);
  }
}

// The drive's heartbeat (0x1017) and its watch of ours (0x1016).
void drive_master::script_error_control() {
  if (config_.drive_heartbeat_ms != 0) {
    sdo_job hb = write_job<sdo_job>(0x1017, 0, config_.drive_heartbeat_ms, 2, config_.heartbeat_required ? 0 : 1);
    hb.then = note_done(heartbeat_watched_);
    script_.push_back(hb);
  }
  if (config_.master_heartbeat_ms == 0) {
    // A master of ours that asked to be watched and went away leaves the drive watching a silent
    // node (and faulting on it, 0x6007): clear its entry, and only its.
    sdo_job guard = read_job<sdo_job>(0x1016, true);
    guard.sub = 1;
    guard.then = [this](const sdo_client& c) {
      const auto v = static_cast<std::uint32_t>(c.value());
      stale_guard_ = c.state() == sdo_client::status::done && (v & 0xFFFF) != 0 &&
                     ((v >> 16) & 0x7F) == config_.master_node_id;
    };
    script_.push_back(guard);
    sdo_job clear = write_job<sdo_job>(0x1016, 1, 0, 4);
    clear.wanted = [this] { return stale_guard_; };
    script_.push_back(clear);
  }
  if (config_.master_heartbeat_ms != 0) {
    const std::uint32_t watch = std::min<std::uint32_t>(3u * config_.master_heartbeat_ms, 0xFFFF);
    script_.push_back(write_job<sdo_job>(0x1016, 1, (static_cast<std::int64_t>(config_.master_node_id) << 16) | watch,
                                         4, config_.heartbeat_required ? 0 : 4));
  }
}

void drive_master::script_pdos() {
  const std::uint8_t node = config_.node_id;
  const auto write = [](std::uint16_t index, std::uint8_t sub, std::int64_t v, unsigned bytes, int group = 0) {
    return write_job<sdo_job>(index, sub, v, bytes, group);
  };
  // TPDO1: status word (+ error code), at each SYNC or on every change.
  const bool on_change = config_.timing == pdo_timing::on_change;
  const std::int64_t tpdo1 = cob::tpdo1 + node;
  script_.push_back(write(0x1800, 1, pdo_cob_invalid | tpdo1, 4));
  script_.push_back(write(0x1A00, 0, 0, 1));
  script_.push_back(write(0x1A00, 1, 0x60410010, 4));
  sdo_job error_entry = write(0x1A00, 2, 0x603F0010, 4);
  error_entry.optional = true;
  error_entry.then = note_done(error_code_mapped_);
  script_.push_back(error_entry);
  sdo_job count = write(0x1A00, 0, 0, 1);
  count.value = [this] { return std::int64_t{error_code_mapped_ ? 2 : 1}; };
  script_.push_back(count);
  script_.push_back(write(0x1800, 2, on_change ? 255 : 1, 1));
  if (on_change) script_.push_back(write(0x1800, 3, 0, 2, 2));  // no inhibit: every state arrives
  script_.push_back(write(0x1800, 1, tpdo1, 4));

  // TPDO2: actual velocity, on change, at most every velocity_inhibit. Optional as a whole.
  if (config_.map_velocity) {
    const std::int64_t tpdo2 = cob::tpdo1 + 0x100 + node;
    constexpr int velocity_group = 3;
    script_.push_back(write(0x1801, 1, pdo_cob_invalid | tpdo2, 4, velocity_group));
    script_.push_back(write(0x1A01, 0, 0, 1, velocity_group));
    script_.push_back(write(0x1A01, 1, 0x606C0020, 4, velocity_group));
    script_.push_back(write(0x1A01, 0, 1, 1, velocity_group));
    script_.push_back(write(0x1801, 2, 255, 1, velocity_group));
    script_.push_back(write(0x1801, 3, config_.velocity_inhibit_100us, 2, velocity_group));
    sdo_job enable2 = write(0x1801, 1, tpdo2, 4, velocity_group);
    enable2.then = note_done(velocity_mapped_);
    script_.push_back(enable2);
  }

  // RPDO1: the control word, acting on receipt.
  const std::int64_t rpdo1 = cob::rpdo1 + node;
  script_.push_back(write(0x1400, 1, pdo_cob_invalid | rpdo1, 4));
  push_mapping(script_, 0x1600, pdo_maps::can_rpdo[0]);  // the control word alone: CiA 402's RPDO1
  script_.push_back(write(0x1400, 2, 255, 1));
  script_.push_back(write(0x1400, 1, rpdo1, 4));

  // PDO 3 for a cyclic synchronous position master: RPDO3 = 0x6040 + 0x607A taken at the next
  // SYNC, TPDO3 = 0x6041 + 0x6064 sent on every SYNC. The drive's defaults, written all the same: a
  // drive set up otherwise before (or by another master) gets them back. Required: a csp master has
  // nothing without them.
  if (config_.map_position) {
    const std::int64_t rpdo3_id = cob::rpdo1 + 0x200 + node;
    script_.push_back(write(0x1402, 1, pdo_cob_invalid | rpdo3_id, 4));
    const pdo_map& rpdo3 = pdo_maps::can_rpdo[2];
    push_mapping(script_, 0x1602, rpdo3);
    script_.push_back(write(0x1402, 2, rpdo3.transmission_type, 1));
    script_.push_back(write(0x1402, 1, rpdo3_id, 4));
    const std::int64_t tpdo3_id = cob::tpdo1 + 0x200 + node;
    script_.push_back(write(0x1802, 1, pdo_cob_invalid | tpdo3_id, 4));
    const pdo_map& tpdo3 = pdo_maps::can_tpdo[2];
    push_mapping(script_, 0x1A02, tpdo3);
    script_.push_back(write(0x1802, 2, tpdo3.transmission_type, 1));
    sdo_job enable3 = write(0x1802, 1, tpdo3_id, 4);
    enable3.then = note_done(position_mapped_);
    script_.push_back(enable3);
  }
}

// With TPDOs on change, the drive's present values last, just before NMT start, so the master
// starts from them: no TPDO says them until they change.
void drive_master::script_present_values() {
  if (config_.timing != pdo_timing::on_change) return;
  sdo_job cw = read_job<sdo_job>(0x6040, true);
  cw.then = [this](const sdo_client& c) {
    if (c.state() == sdo_client::status::done) last_sent_ = static_cast<std::uint16_t>(c.value());
  };
  script_.push_back(cw);
  sdo_job sw = read_job<sdo_job>(0x6041, false);
  sw.then = [this](const sdo_client& c) { note_status(static_cast<std::uint16_t>(c.value())); };
  script_.push_back(sw);
  sdo_job err = read_job<sdo_job>(0x603F, true);
  err.then = [this](const sdo_client& c) {
    if (c.state() == sdo_client::status::done) error_code_ = static_cast<std::uint16_t>(c.value());
  };
  script_.push_back(err);
  sdo_job vel = read_job<sdo_job>(0x606C, true);
  vel.then = [this](const sdo_client& c) {
    if (c.state() == sdo_client::status::done) note_velocity(static_cast<std::int32_t>(c.value(true)));
  };
  script_.push_back(vel);
}

}  // namespace cia402::canopen
