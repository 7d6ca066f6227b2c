// The scope's samples: one per cycle of the link, into the page's sample ring (sample_ring.hpp).
// A drive in this process is sampled at each step of its simulator: the values it read at the
// cycle's start (as the recording's row), the words, state and transition its step gave. A drive on
// a bus is sampled at each cycle of the link (before each SYNC, before each LRW), from its cyclic
// inputs; what the cyclic data does not carry is the session's last polled value, and the batch
// names it as polled.
#include <algorithm>

#include "axis_page_impl.hpp"
#include "cia402/master.hpp"
#include "cia402/objects.hpp"
#include "page_json.hpp"

namespace cia402::page {
namespace {

using detail::hex;
using detail::signal;

// The object each object column shows (the set-point's depends on the mode).
struct object_column {
  signal column;
  std::uint16_t index;
};
constexpr object_column object_columns[] = {
    {signal::velocity, object_index::velocity_actual_value},
    {signal::position, object_index::position_actual_value},
    {signal::torque, object_index::torque_actual_value},
    {signal::following_error, object_index::following_error_actual_value},
    {signal::position_demand, object_index::position_demand_value},
    {signal::digital_inputs, object_index::digital_inputs},
    {signal::mode, object_index::modes_of_operation_display},
    {signal::error_code, object_index::error_code},
};

// The set-point of a mode (0x6061): pp and csp 0x607A, pv and csv 0x60FF, tq and cst 0x6071; 0 for
// a mode without one the scope shows (homing, ip, none).
std::uint16_t set_point_of(std::int64_t mode) {
  switch (mode) {
    case 1: case 8: return object_index::target_position;
    case 3: case 9: return object_index::target_velocity;
    case 4: case 10: return object_index::target_torque;
    default: return 0;
  }
}

bool carried(const std::vector<axes::cyclic_object>& objects, std::uint16_t index) {
  return std::any_of(objects.begin(), objects.end(), [index](const axes::cyclic_object& o) { return o.index == index; });
}

}  // namespace

// The mode panel's set-point: the object of the mode the drive shows and its value now, the local
// drive's own, else what goes out in this cycle (a csp, csv or cst stream's value) or the last read
// or written. `cyclic`: it travels in every cycle (the local link carries every set-point so).
axis_page::impl::json axis_page::impl::set_point_json() const {
  // The simulator's mode itself: its 0x6061 may read as the object's fixed value (one mode only).
  const std::optional<std::int64_t> mode =
      plant ? plant->view().operation_mode() : value_of(object_index::modes_of_operation_display);
  const std::uint16_t index = mode ? set_point_of(*mode) : 0;
  if (index == 0) return nullptr;
  const std::optional<std::int64_t> value = shown_value(index, 0);
  const object_description* d = find_drive_object(index);
  return {{"index", hex(index, 4)},
          {"name", d != nullptr ? d->name : ""},
          {"unit", d != nullptr ? d->unit : ""},
          {"value", value ? json(*value) : json(nullptr)},
          {"cyclic", carried(session->link().cyclic_outputs(), index)}};
}

// The values the drive reads as its cycle begins, as the recording's row has them.
void axis_page::impl::open_plant_sample(const sim::trace_row& row) {
  const sim::drive_view v = plant->view();
  detail::cycle_sample& s = open_sample;
  s = {};
  s.time_us = row.time_us;
  s.set(signal::control_word, row.control_word);
  s.set(signal::velocity, v.velocity_rpm());
  s.set(signal::position, row.position);
  s.set(signal::torque, row.torque_permille);
  s.set(signal::following_error, v.following_error());
  s.set(signal::position_demand, row.position_demand);
  s.set(signal::digital_inputs, row.digital_inputs);
  s.set(signal::mode, row.mode);
  if (const std::uint16_t index = set_point_of(row.mode); index != 0) {
    if (const auto value = plant->read(index, 0)) s.set(signal::set_point, *value);
  }
}

// What its step made of them: the words, the state, the transition (the step's own number).
void axis_page::impl::push_plant_sample(const drive_outputs& out) {
  detail::cycle_sample& s = open_sample;
  s.set(signal::status_word, out.status_word);
  s.set(signal::state, static_cast<std::int64_t>(out.current));
  if (out.transition != no_transition) s.set(signal::transition, out.transition);
  s.set(signal::error_code, out.error_code);
  samples.push(s);
}

// A cycle of a bus: the status word it brought, the control word going, each value the link carries,
// else the last one polled.
void axis_page::impl::push_bus_sample() {
  const axes::drive_link& link = session->link();
  if (!link.cyclic() || !link.status_known()) return;
  detail::cycle_sample s;
  s.time_us = now_us;
  const std::uint16_t sw = link.status_word();
  s.set(signal::status_word, sw);
  if (const auto cw = session->control_word()) s.set(signal::control_word, *cw);
  state shown = state::start;
  if (decode_status(*table, sw, shown)) s.set(signal::state, static_cast<std::int64_t>(shown));
  if (transition_for_sample) s.set(signal::transition, *transition_for_sample);
  transition_for_sample.reset();
  for (const object_column& c : object_columns) {
    if (auto v = link.cyclic_input(c.index, 0)) {
      s.set(c.column, *v);
    } else if (auto p = value_of(c.index)) {
      s.set(c.column, *p);
    }
  }
  if (!s.has(signal::error_code)) s.set(signal::error_code, session->error_code());
  if (s.has(signal::mode)) {
    if (const std::uint16_t index = set_point_of(s.get(signal::mode)); index != 0) {
      // What goes out in this cycle where the link carries it, else the value last read or written.
      if (auto v = session->output(index) ? session->output(index) : value_of(index)) s.set(signal::set_point, *v);
    }
  }
  samples.push(s);
}

// The columns that are not the bus's cycle: the objects the link does not carry (a drive in this
// process has none).
std::vector<std::string> axis_page::impl::polled_signals() const {
  std::vector<std::string> polled;
  if (plant) return polled;
  const axes::drive_link& link = session->link();
  const auto name = [](signal s) { return std::string(detail::signal_names()[static_cast<std::size_t>(s)]); };
  for (const object_column& c : object_columns) {
    if (!carried(link.cyclic_inputs(), c.index)) polled.push_back(name(c.column));
  }
  const std::uint16_t sp = set_point_of(value_of(object_index::modes_of_operation_display).value_or(0));
  if (sp != 0 && !carried(link.cyclic_outputs(), sp)) polled.push_back(name(signal::set_point));
  return polled;
}

std::uint64_t axis_page::samples_end() const { return impl_->samples.end(); }

std::string axis_page::samples_json(std::uint64_t from, std::size_t max, std::uint64_t& next) const {
  std::vector<std::string> polled;
  {
    std::lock_guard lock(impl_->mutex);
    polled = impl_->polled_signals();
  }
  return impl_->samples.batch_json(from, max, next, polled);
}

}  // namespace cia402::page
