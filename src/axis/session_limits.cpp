// Limits before motion (S20): what a motion command reads from the drive and judges before the first
// word that could move it: 0x6502 for the mode, 0x607F and 0x6080 for a velocity, 0x6072 for a
// torque, 0x607D for a position, 0x60E3 for a homing method. A drive without such an object is not
// judged by it; a target beyond one is refused (bad_input), naming the object, its value and the target.
#include <cstdlib>

#include "cia402/words.hpp"
#include "session_internal.hpp"

namespace cia402::axes {

session::step session::limit_step(std::uint16_t index, std::uint8_t sub,
                                  std::function<std::optional<std::string>(std::int64_t)> judge) {
  auto value = std::make_shared<std::optional<std::int64_t>>();
  step read = read_step(index, sub, [value](std::int64_t v) { *value = v; }, true);
  return {read.start, [this, poll = read.poll, value, judge = std::move(judge)] {
            const step_state st = poll();
            if (st != step_state::done || !*value) return st;  // absent: the drive has no such limit
            if (const auto why = judge(**value)) {
              op_->res.bad_input = true;
              return fail_step(*why + ": refused, nothing was sent to move the drive");
            }
            return step_state::done;
          }};
}

session::step session::mode_supported(std::int8_t m) {
  return {nullptr, [this, m] {
            if (!supported_modes_ || (*supported_modes_ & mode::supported_bit(m)) != 0) return step_state::done;
            op_->res.bad_input = true;
            return fail_step(mode_words(m) + " is not among the modes 0x6502 (supported drive modes) = " +
                             std::to_string(*supported_modes_) + " announces: refused, nothing was sent");
          }};
}

std::vector<session::step> session::velocity_limits(std::int64_t rpm, const char* what) {
  const auto beyond = [rpm, what](const char* object) {
    return [rpm, what, object](std::int64_t limit) -> std::optional<std::string> {
      if (std::abs(rpm) <= limit) return std::nullopt;
      return std::string(what) + " " + std::to_string(rpm) + " rpm is beyond " + object + " = " + std::to_string(limit) + " rpm";
    };
  };
  return {limit_step(object_index::max_profile_velocity, 0, beyond("0x607F (max profile velocity)")),
          limit_step(object_index::max_motor_speed, 0, beyond("0x6080 (max motor speed)"))};
}

session::step session::torque_limit(std::int64_t permille) {
  return limit_step(object_index::max_torque, 0, [permille](std::int64_t limit) -> std::optional<std::string> {
    if (std::abs(permille) <= limit) return std::nullopt;
    return "torque " + std::to_string(permille) + " permille is beyond 0x6072 (max torque) = " + std::to_string(limit) +
           " permille";
  });
}

std::vector<session::step> session::position_limits(std::int64_t target, bool relative) {
  // A relative target is judged where it ends: from the position the drive shows now.
  const auto end_of = [this, target, relative]() -> std::optional<std::int64_t> {
    if (!relative) return target;
    const auto at = actual(object_index::position_actual_value);
    return at ? std::optional(*at + target) : std::nullopt;
  };
  const auto side = [end_of, target, relative](bool min) {
    return [end_of, target, relative, min](std::int64_t limit) -> std::optional<std::string> {
      const auto end = end_of();
      if (!end || (min ? *end >= limit : *end <= limit)) return std::nullopt;
      return "target position " + std::to_string(*end) + (relative ? " (" + std::to_string(target) + " from here)" : "") +
             " is beyond 0x607D:" + (min ? "01 (min position limit) = " : "02 (max position limit) = ") + std::to_string(limit);
    };
  };
  std::vector<step> steps;
  if (relative) steps.push_back(read_step(object_index::position_actual_value, 0, [this](std::int64_t v) {
    polled& p = polled_[object_index::position_actual_value];
    p.value = v;
    p.read_us = now_us_;
  }, true));
  steps.push_back(limit_step(object_index::software_position_limit, 1, side(true)));
  steps.push_back(limit_step(object_index::software_position_limit, 2, side(false)));
  return steps;
}

session::step session::homing_method_supported(std::int8_t method) {
  struct status {
    std::vector<std::int64_t> methods;
    std::size_t wanted = 0, answered = 0;
    bool listed = true;  // the drive gave its list (a drive without 0x60E3 is not judged)
    bool counted = false;
  };
  auto s = std::make_shared<status>();
  return {[this, s] {
            queue_upload(object_index::supported_homing_methods, 0, [this, s](const transfer_result& r) {
              s->counted = true;
              // At most 254 entries follow; a count beyond that is not a list.
              if (!r.ok || r.data.size() != 1 || r.data[0] == 0 || r.data[0] > 254) {
                s->listed = false;
                return;
              }
              s->wanted = r.data[0];
              for (std::uint8_t k = 1; k <= r.data[0]; ++k) {
                queue_upload(object_index::supported_homing_methods, k, [s](const transfer_result& m) {
                  ++s->answered;
                  if (m.ok && m.data.size() == 1) s->methods.push_back(static_cast<std::int8_t>(m.data[0]));
                  else s->listed = false;
                }, true);
              }
            });
          },
          [this, s, method] {
            if (!s->counted || (s->listed && s->answered < s->wanted)) return step_state::running;
            if (!s->listed) return step_state::done;
            for (const std::int64_t m : s->methods) {
              if (m == method) return step_state::done;
            }
            std::string list;
            for (const std::int64_t m : s->methods) list += (list.empty() ? "" : ", ") + std::to_string(m);
            op_->res.bad_input = true;
            return fail_step("homing method " + std::to_string(method) + " is not among 0x60E3 (supported homing methods): " +
                             list + ": refused, nothing was sent");
          }};
}

}  // namespace cia402::axes
