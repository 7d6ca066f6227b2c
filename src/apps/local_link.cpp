#include "cia402/apps/local_link.hpp"

#include <string>

#include "cia402/dictionary/dictionary_access.hpp"
#include "cia402/dictionary/error_history.hpp"
#include "cia402/dictionary/object_builders.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/drive402/drive_objects.hpp"
#include "cia402/objects.hpp"

namespace cia402::apps {
namespace {

using namespace dictionary;

// 0x1003 with the device's depth, its values read from the device (the plant keeps the list).
object_entry error_field(std::uint8_t size) {
  object_entry e = error_history_object(size);
  for (sub_entry& sub : e.subs) sub = on_device(std::move(sub));
  return e;
}

std::vector<object_entry> local_objects(std::uint8_t history) {
  std::vector<object_entry> t = drive402::drive_objects();
  t.push_back(error_field(history));
  return t;
}

}  // namespace

// The drive's dictionary: its values from the device, 0x1003 from the link's list, the rest stored.
class local_link::objects final : public dictionary_access {
 public:
  objects(local_link& link, std::uint8_t history)
      : dictionary_access(od_), od_(local_objects(history), 1), link_(&link) {}
  const object_dictionary& table() const { return od_; }

 protected:
  sdo_abort read_value(const object_dictionary::slot& s, std::int64_t& v) override {
    if (s.object->index == error_history_index) {
      const std::deque<std::uint32_t>& h = link_->history_;
      if (s.entry->sub == 0) {
        v = static_cast<std::int64_t>(h.size());
        return sdo_abort::none;
      }
      if (s.entry->sub > h.size()) return sdo_abort::no_data_available;
      v = h[s.entry->sub - 1u];
      return sdo_abort::none;
    }
    if (s.entry->where == backing::device) return link_->device_->read(s.object->index, s.entry->sub, v);
    v = s.number;
    return sdo_abort::none;
  }
  sdo_abort write_value(object_dictionary::slot& s, std::int64_t v) override {
    if (s.object->index == error_history_index) {
      // Only 0 may be written: it deletes the list (CiA 301 §7.5.2.5).
      if (v != 0) return sdo_abort::invalid_value;
      link_->history_.clear();
      return sdo_abort::none;
    }
    if (s.entry->where == backing::device) return link_->device_->write(s.object->index, s.entry->sub, v);
    s.number = v;
    return sdo_abort::none;
  }

 private:
  object_dictionary od_;
  local_link* link_;
};

local_link::local_link(const profile& p, const sim::plant_config& plant, std::uint8_t error_history)
    : device_(std::make_unique<drive402::sim_device>(p, plant)),
      history_size_(error_history == 0 ? std::uint8_t{1} : error_history) {
  objects_ = std::make_unique<objects>(*this, history_size_);
  // The set-points of EtherCAT's default RxPDO go in each cycle; every mappable object the drive
  // reads comes back each cycle.
  outputs_ = {{object_index::control_word, 0, 16},
              {object_index::modes_of_operation, 0, 8},
              {object_index::target_position, 0, 32},
              {object_index::target_velocity, 0, 32},
              {object_index::target_torque, 0, 16}};
  for (std::size_t i = 0; i < drive_object_count(); ++i) {
    const object_description& d = drive_object(i);
    if (!d.pdo_mappable || d.access == cia402::object_access::write_only) continue;
    inputs_.push_back({d.index, d.sub, static_cast<std::uint8_t>(8 * type_size(d.type))});
  }
}

local_link::~local_link() = default;

axes::link_phase local_link::phase() const { return closed_ ? axes::link_phase::failed : axes::link_phase::running; }

std::uint32_t local_link::cycle_us() const { return device_->drive().constants().cycle_us; }

std::uint16_t local_link::status_word() const { return device_->drive().view().outputs().status_word; }

std::optional<std::uint16_t> local_link::error_code() const { return device_->drive().view().outputs().error_code; }

std::uint32_t local_link::poll(std::uint32_t elapsed_us) {
  if (closed_) return 0xFFFFFFFFu;
  const std::uint32_t cycle = cycle_us();
  // A stalled host goes on from where it was, as the device does (sim_device::max_catch_up_cycles).
  const std::uint64_t pending = std::uint64_t{pending_us_} + elapsed_us;
  const std::uint64_t cap = std::uint64_t{drive402::sim_device::max_catch_up_cycles} * cycle;
  pending_us_ = static_cast<std::uint32_t>(pending < cap ? pending : cap);
  while (pending_us_ >= cycle) {
    pending_us_ -= cycle;
    one_cycle();
  }
  std::deque<transfer> due;
  due.swap(transfers_);
  for (transfer& t : due) {
    axes::transfer_result r;
    if (t.download) {
      r.abort = objects_->download(t.index, t.sub, t.bytes, true);
    } else {
      r.abort = objects_->upload(t.index, t.sub, r.data);
    }
    r.ok = r.abort == sdo_abort::none;
    if (!r.ok) r.data.clear();
    if (t.done) t.done(r);
  }
  return cycle - pending_us_;
}

void local_link::one_cycle() {
  // The word is in the drive already (set_control_word); the session's stream puts its set-point now.
  if (before_cycle) before_cycle();
  sim::virtual_drive& d = device_->drive();
  const drive_outputs out = d.step();
  ++status_count_;
  if (out.error_code != last_error_) {
    last_error_ = out.error_code;
    note_error(out.error_code, out.error_register);
  }
}

void local_link::note_error(std::uint16_t code, std::uint8_t reg) {
  if (code != 0) {
    history_.push_front(code);
    while (history_.size() > history_size_) history_.pop_back();
  }
  if (!on_emergency) return;
  const std::array<std::uint8_t, 5> bytes = device_->manufacturer_error_field();
  on_emergency(code, reg, std::span<const std::uint8_t>(bytes.data(), bytes.size()));
}

void local_link::set_control_word(std::uint16_t word) {
  word_ = word;
  // Any 16-bit word is a control word: the drive reads it in its next step.
  (void)device_->write(object_index::control_word, 0, word);
}

std::optional<std::int64_t> local_link::cyclic_input(std::uint16_t index, std::uint8_t sub) const {
  if (closed_ || status_count_ == 0) return std::nullopt;
  for (const axes::cyclic_object& o : inputs_) {
    if (o.index != index || o.sub != sub) continue;
    std::int64_t v = 0;
    if (device_->read(index, sub, v) != sdo_abort::none) return std::nullopt;
    return v;
  }
  return std::nullopt;
}

bool local_link::set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) {
  if (closed_) return false;
  for (const axes::cyclic_object& o : outputs_) {
    if (o.index != index || o.sub != sub) continue;
    if (index == object_index::control_word) {
      set_control_word(static_cast<std::uint16_t>(value));
      return true;
    }
    // A value the drive refuses is not taken: the caller's transfer then brings the abort code.
    return device_->write(index, sub, value) == sdo_abort::none;
  }
  return false;
}

std::optional<axes::value_format> local_link::describe(std::uint16_t index, std::uint8_t sub) const {
  const object_dictionary::slot* s = objects_->table().find(index, sub);
  if (s == nullptr) return std::nullopt;
  return axes::format_of(s->entry->type);
}

void local_link::close() {
  closed_ = true;
  axes::cancel_transfers(transfers_, "closed");
  report_.done = true;
}

}  // namespace cia402::apps
