#include "sample_ring.hpp"

#include <algorithm>

namespace cia402::page::detail {
namespace {

// A run-length coded column: value, count, value, count (null for a value the drive did not give).
void append_runs(std::string& out, const std::vector<cycle_sample>& rows, std::size_t k) {
  out += '[';
  std::size_t i = 0;
  while (i < rows.size()) {
    const bool known = (rows[i].known >> k) & 1u;
    const std::int64_t v = rows[i].value[k];
    std::size_t n = 1;
    while (i + n < rows.size() && ((rows[i + n].known >> k) & 1u) == known &&
           (!known || rows[i + n].value[k] == v)) {
      ++n;
    }
    if (i > 0) out += ',';
    out += known ? std::to_string(v) : std::string("null");
    out += ',';
    out += std::to_string(n);
    i += n;
  }
  out += ']';
}

}  // namespace

const std::array<const char*, signal_count>& signal_names() {
  static const std::array<const char*, signal_count> names{
      "status_word", "control_word", "state",           "transition",     "velocity", "position",  "torque",
      "following_error", "set_point", "position_demand", "digital_inputs", "mode",     "error_code"};
  return names;
}

sample_ring::sample_ring(std::size_t capacity) : ring_(std::max<std::size_t>(capacity, 16)) {}

void sample_ring::push(const cycle_sample& s) {
  std::lock_guard lock(mutex_);
  ring_[end_ % ring_.size()] = s;
  ++end_;
  if (end_ - begin_ > ring_.size()) begin_ = end_ - ring_.size();
}

void sample_ring::clear() {
  std::lock_guard lock(mutex_);
  begin_ = end_;
}

std::uint64_t sample_ring::end() const {
  std::lock_guard lock(mutex_);
  return end_;
}

std::uint64_t sample_ring::begin() const {
  std::lock_guard lock(mutex_);
  return begin_;
}

std::vector<cycle_sample> sample_ring::copy(std::uint64_t& from, std::size_t max) const {
  std::vector<cycle_sample> rows;
  std::lock_guard lock(mutex_);
  from = std::clamp(from, begin_, end_);
  const std::uint64_t to = std::min<std::uint64_t>(end_, from + max);
  rows.reserve(static_cast<std::size_t>(to - from));
  for (std::uint64_t q = from; q < to; ++q) rows.push_back(ring_[q % ring_.size()]);
  return rows;
}

std::string sample_ring::batch_json(std::uint64_t from, std::size_t max, std::uint64_t& next,
                                    const std::vector<std::string>& polled) const {
  const std::vector<cycle_sample> rows = copy(from, max);
  next = from + rows.size();
  std::string out = "{\"from\":" + std::to_string(from) + ",\"n\":" + std::to_string(rows.size());
  out += ",\"t0\":" + std::to_string(rows.empty() ? 0 : rows.front().time_us) + ",\"dt\":[";
  // The steps between samples: a steady cycle is one pair.
  for (std::size_t i = 1; i < rows.size();) {
    const std::uint64_t dt = rows[i].time_us - rows[i - 1].time_us;
    std::size_t n = 1;
    while (i + n < rows.size() && rows[i + n].time_us - rows[i + n - 1].time_us == dt) ++n;
    if (i > 1) out += ',';
    out += std::to_string(dt) + "," + std::to_string(n);
    i += n;
  }
  out += "],\"polled\":[";
  for (std::size_t i = 0; i < polled.size(); ++i) out += (i ? ",\"" : "\"") + polled[i] + "\"";
  out += "],\"columns\":{";
  for (std::size_t k = 0; k < signal_count; ++k) {
    if (k) out += ',';
    out += '"';
    out += signal_names()[k];
    out += "\":";
    append_runs(out, rows, k);
  }
  out += "}}";
  return out;
}

}  // namespace cia402::page::detail
