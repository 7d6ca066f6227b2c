#include "recorder.hpp"

#include <ostream>
#include <sstream>

#include "page_json.hpp"

namespace cia402::page::detail {
namespace {

using json = nlohmann::ordered_json;

// Everything but the time and the sampled values (velocity, position, torque: they move with a
// ramp or a move).
bool same_but_velocity(const sim::trace_row& a, const sim::trace_row& b) {
  return a.control_word == b.control_word && a.status_word == b.status_word &&
         a.error_code == b.error_code && a.fault_cause == b.fault_cause && a.current == b.current &&
         a.transition == b.transition && a.ramp == b.ramp && a.torque == b.torque &&
         a.brake_released == b.brake_released && a.brake_engaged == b.brake_engaged &&
         a.dc_link == b.dc_link && a.sto == b.sto && a.target_velocity == b.target_velocity &&
         a.mode == b.mode;
}

// The sampled values: kept at most once per velocity_every_us while they move.
bool same_samples(const sim::trace_row& a, const sim::trace_row& b) {
  return a.velocity == b.velocity && a.position == b.position &&
         a.position_demand == b.position_demand && a.torque_permille == b.torque_permille;
}

// micro-rpm to whole rpm, rounded half away from zero.
std::int64_t whole_rpm(std::int64_t micro) {
  return micro >= 0 ? (micro + 500000) / 1000000 : -((-micro + 500000) / 1000000);
}

}  // namespace

void recorder::record(const sim::trace_row& row) {
  bool keep = rows_.empty() || row.transition != no_transition;
  if (!keep) {
    const sim::trace_row& prev = rows_.back();
    keep = !same_but_velocity(prev, row) ||
           (!same_samples(row, prev) && row.time_us >= prev.time_us + limits_.velocity_every_us);
  }
  // Samples that settled after the last kept one: keep the cycle before the first unchanged one,
  // so the file shows where the ramp or the move ended.
  if (!keep && last_ && !same_samples(*last_, rows_.back()) && same_samples(row, *last_)) {
    rows_.push_back(*last_);
  }
  last_ = row;
  if (keep) rows_.push_back(row);
  while (rows_.size() > limits_.rows) {
    rows_.pop_front();
    ++first_row_seq_;
    ++dropped_rows_;
  }
}

void recorder::note_transition(transition t) {
  t.seq = next_transition_seq_++;
  transitions_.push_back(t);
  while (transitions_.size() > limits_.transitions) transitions_.pop_front();
}

void recorder::clear() {
  first_row_seq_ += rows_.size();
  rows_.clear();
  dropped_rows_ = 0;
  transitions_.clear();
  last_.reset();
}

json recorder::since_json(std::uint64_t row_since, std::uint64_t transition_since) const {
  json rows = json::array();
  const std::uint64_t next_row = first_row_seq_ + rows_.size();
  std::uint64_t seq = first_row_seq_;
  for (const sim::trace_row& r : rows_) {
    if (seq++ <= row_since) continue;
    rows.push_back({r.time_us / 1000, r.control_word, r.status_word, state_name(r.current),
                    r.transition == no_transition ? json(nullptr) : json(int{r.transition}),
                    whole_rpm(r.velocity), r.position, r.torque_permille});
  }
  json list = json::array();
  for (const transition& t : transitions_) {
    if (t.seq <= transition_since) continue;
    list.push_back({{"seq", t.seq},
                    {"time_ms", t.time_us / 1000},
                    {"number", t.number ? json(*t.number) : json(nullptr)},
                    {"from", state_name(t.from)},
                    {"to", state_name(t.to)},
                    {"control_word", hex(t.control_word, 4)},
                    {"status_word", hex(t.status_word, 4)},
                    {"inferred", t.inferred}});
  }
  json j;
  j["rows_seen"] = next_row - 1;
  j["transitions_seen"] = next_transition_seq_ - 1;
  j["dropped_rows"] = dropped_rows_;
  j["rows"] = std::move(rows);
  j["transitions"] = std::move(list);
  return j;
}

std::vector<sim::trace_row> recorder::kept_with_last() const {
  std::vector<sim::trace_row> out(rows_.begin(), rows_.end());
  if (last_ && (out.empty() || out.back().time_us != last_->time_us)) out.push_back(*last_);
  return out;
}

void recorder::write_csv(std::ostream& out) const { sim::write_csv(out, kept_with_last()); }

void recorder::write_vcd(std::ostream& out, sim::trace_info info, bool gtkwave) const {
  info.vcd_standard = !gtkwave;
  sim::write_vcd(out, kept_with_last(), info);
}

std::string recorder::file(recording_format format, const sim::trace_info& info) const {
  std::ostringstream out;
  if (format == recording_format::csv) {
    write_csv(out);
  } else {
    write_vcd(out, info, format == recording_format::vcd_gtkwave);
  }
  return out.str();
}

}  // namespace cia402::page::detail
