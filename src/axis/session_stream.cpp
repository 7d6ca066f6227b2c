// Cyclic synchronous streaming (csp, csv, cst): a set-point source called once a cycle, just before
// the cyclic outputs go, and the following error against the set-point the drive has had a cycle
// to reach; the csp ramp of `cia402 master csp-stream`.
#include <algorithm>
#include <cstdlib>

#include "cia402/words.hpp"
#include "session_internal.hpp"

namespace cia402::axes {
namespace {

struct stream_objects {
  std::uint16_t set_point;
  std::uint16_t actual;
};

std::optional<stream_objects> objects_of(std::int8_t m) {
  switch (m) {
    case mode::cyclic_synchronous_position: return stream_objects{object_index::target_position, object_index::position_actual_value};
    case mode::cyclic_synchronous_velocity: return stream_objects{object_index::target_velocity, object_index::velocity_actual_value};
    case mode::cyclic_synchronous_torque: return stream_objects{object_index::target_torque, object_index::torque_actual_value};
    default: return std::nullopt;
  }
}

bool carries(const std::vector<cyclic_object>& list, std::uint16_t index) {
  return std::any_of(list.begin(), list.end(), [index](const cyclic_object& o) { return o.index == index && o.sub == 0; });
}

}  // namespace

position_ramp::position_ramp(std::int64_t from, std::int64_t to, std::uint32_t rpm, std::uint32_t cycle_us,
                             std::uint64_t increments, std::uint64_t revolutions) noexcept
    : from_(from),
      to_(to),
      // rpm x increments x us per cycle, over 60e6 x revolutions: one cycle's travel as a fraction.
      per_cycle_(std::uint64_t{rpm} * std::min<std::uint64_t>(increments, std::uint64_t{1} << 26) * cycle_us),
      divisor_(60'000'000ull * std::max<std::uint64_t>(revolutions, 1)) {}

std::int64_t position_ramp::at(std::uint64_t k) const noexcept {
  const std::int64_t span = to_ - from_;
  const auto distance = static_cast<std::uint64_t>(span < 0 ? -span : span);
  // Whole cycles' travel and the remainder apart, so k x per_cycle never overflows: the ramp ends
  // within distance / (one cycle's travel) cycles.
  const std::uint64_t whole = per_cycle_ / divisor_ * k;
  if (whole >= distance) return to_;
  const std::uint64_t travel = whole + per_cycle_ % divisor_ * k / divisor_;
  if (travel >= distance) return to_;
  const auto t = static_cast<std::int64_t>(travel);
  return from_ + (span < 0 ? -t : t);
}

void session::stream_tick() {
  if (!source_ || !op_ || !op_->streaming) return;
  // The actual value the last cycle brought, against the set-point the cycle before it sent: the
  // one the drive has had a cycle to reach.
  const auto actual_now = link_->cyclic_input(stream_actual_, 0);
  if (actual_now && set_point_before_) {
    max_following_error_ = std::max<std::int64_t>(max_following_error_, std::abs(*actual_now - *set_point_before_));
  }
  set_point_before_ = last_set_point_;
  if (stream_ended_) return;
  const std::optional<std::int64_t> next = source_();
  if (!next) {
    stream_ended_ = true;
    return;
  }
  last_set_point_ = next;
  ++set_points_;
  (void)put_output(stream_object_, 0, *next);
}

std::vector<session::step> session::stream_steps(std::int8_t m, setpoint_source source, std::vector<step> limits,
                                                 std::vector<step> before_mode, std::function<void(result&)> describe) {
  const stream_objects objects = *objects_of(m);
  std::vector<step> steps{need_prepared(), need_cyclic(), step{nullptr, [this, objects] {
                            if (!carries(link_->cyclic_outputs(), objects.set_point) ||
                                !carries(link_->cyclic_inputs(), objects.actual)) {
                              return fail_step("streaming needs " + object_name(objects.set_point, 0) +
                                               " in the cyclic outputs and " + object_name(objects.actual, 0) +
                                               " in the cyclic inputs of " + link_->what());
                            }
                            return step_state::done;
                          }},
                          check(true), mode_supported(m)};
  for (step& l : limits) steps.push_back(std::move(l));
  steps.push_back(call_step([this] {
    op_->commanded = true;  // from here on a failure stops the drive (S20)
    halt_by_stop_ = false;
    set_mode_bits(0);
  }));
  steps.insert(steps.end(), before_mode.begin(), before_mode.end());
  steps.push_back(mode_step(m));
  steps.push_back(target_step(state::operation_enabled));
  steps.push_back(wait_step([this] { return settled() && (link_->status_word() & status_bit::drive_follows_command) != 0; },
                            config_.transition_timeout_us, [this] {
                              return "the drive does not follow the command value (status bit 12 stays 0; " + state_text() + ")";
                            }));
  steps.push_back(call_step([this, objects, source = std::move(source), describe = std::move(describe)] {
    source_ = source;
    stream_object_ = objects.set_point;
    stream_actual_ = objects.actual;
    last_set_point_.reset();
    set_point_before_.reset();
    stream_ended_ = false;
    set_points_ = 0;
    max_following_error_ = 0;
    op_->streaming = true;
    if (describe) describe(op_->res);
    progress(progress_kind::stream_started);
  }));
  steps.push_back(step{nullptr, [this, objects] {
                         const std::uint16_t sw = link_->status_word();
                         if (objects.set_point == object_index::target_position && (sw & status_bit::following_error) != 0) {
                           return fail_step("following error (status bit 13, statusword " + word_hex(sw) + ")");
                         }
                         op_->res.set_points = set_points_;
                         op_->res.max_following_error = max_following_error_;
                         if (!stream_ended_ || !last_set_point_) return step_state::running;
                         const auto at = link_->cyclic_input(objects.actual, 0);
                         const std::int64_t tolerance = objects.set_point == object_index::target_position
                                                            ? 0
                                                            : std::max<std::int64_t>(1, std::abs(*last_set_point_) / 100);
                         if (!at || std::abs(*at - *last_set_point_) > tolerance) return step_state::running;
                         if (objects.actual == object_index::position_actual_value) op_->res.position = *at;
                         if (objects.actual == object_index::velocity_actual_value) op_->res.velocity = *at;
                         if (objects.actual == object_index::torque_actual_value) op_->res.torque = *at;
                         return step_state::done;
                       }});
  return steps;
}

std::uint64_t session::stream(std::int8_t m, setpoint_source source, completion done) {
  if (!objects_of(m)) {
    return refuse_now(mode_words(m) + " is not a cyclic synchronous mode (csp, csv, cst)", std::move(done), true);
  }
  return begin("stream", stream_steps(m, std::move(source), {}, {}, nullptr), std::move(done), true);
}

std::uint64_t session::csp_stream(std::int32_t to, std::uint32_t rpm, completion done) {
  struct plan {
    std::int64_t start = 0;
    std::uint64_t increments = 10000;  // 0x608F sub 1 over sub 2: increments a revolution
    std::uint64_t revolutions = 1;
    std::uint64_t k = 0;
    bool ended = false;
  };
  auto p = std::make_shared<plan>();
  std::vector<step> before;
  // Where it stands, read first and written to 0x607A before the switch to csp: a drive in csp
  // follows 0x607A from its first cycle, and a stale one (a move's target, from before a homing run
  // moved the zero) would send it there at full speed. By a transfer as well as into the cyclic
  // outputs: a bus may not send those before the first control word.
  before.push_back(read_step(object_index::position_actual_value, 0, [p](std::int64_t v) { p->start = v; }, false));
  auto written = std::make_shared<std::optional<std::string>>();
  before.push_back(step{[this, p, written] {
                          (void)put_output(object_index::target_position, 0, p->start);
                          std::vector<std::uint8_t> bytes;
                          std::string why;
                          (void)encode_value(object_value::of_integer(p->start), value_format::integer(4, true), bytes, why);
                          queue_download(object_index::target_position, 0, std::move(bytes), [written](const transfer_result& r) {
                            *written = r.ok ? std::string() : "the drive refused 0x607A: " + transfer_failure(r);
                          });
                        },
                        [this, written] {
                          if (!*written) return step_state::running;
                          return (*written)->empty() ? step_state::done : fail_step(**written);
                        }});
  before.push_back(read_step(object_index::position_encoder_resolution, 1, [p](std::int64_t v) {
    if (v > 0) p->increments = static_cast<std::uint64_t>(v);
  }, true));
  before.push_back(read_step(object_index::position_encoder_resolution, 2, [p](std::int64_t v) {
    if (v > 0) p->revolutions = static_cast<std::uint64_t>(v);
  }, true));
  setpoint_source ramp = [this, p, to, rpm]() -> std::optional<std::int64_t> {
    if (p->ended) return std::nullopt;
    const position_ramp r(p->start, to, rpm, link_->cycle_us(), p->increments, p->revolutions);
    const std::int64_t sp = r.at(++p->k);
    p->ended = sp == to;
    return sp;
  };
  auto describe = [p, to, rpm](result& r) {
    r.stream_from = p->start;
    r.stream_to = to;
    r.velocity = rpm;
  };
  std::vector<step> limits = position_limits(to, false);
  for (step& l : velocity_limits(rpm, "csp velocity")) limits.push_back(std::move(l));
  return begin("csp stream",
               stream_steps(mode::cyclic_synchronous_position, std::move(ramp), std::move(limits), std::move(before), describe),
               std::move(done), true);
}

}  // namespace cia402::axes
