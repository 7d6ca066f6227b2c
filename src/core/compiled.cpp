#include "cia402/compiled.hpp"

namespace cia402 {
namespace {

constexpr std::uint8_t no_word = 0xFF;

// The first control word (bits 0..4) the profile decodes to each command, or no_word.
std::array<std::uint8_t, 8> word_of_command(const profile& p) noexcept {
  std::array<std::uint8_t, 8> words;
  words.fill(no_word);
  for (std::uint8_t bits = 0; bits < 32; ++bits) {
    std::uint8_t& w = words[static_cast<unsigned>(p.decode(bits))];
    if (w == no_word) w = bits;
  }
  return words;
}

// What one probe of the full step did, in the terms an entry can hold.
struct probe_result {
  std::uint8_t transition = no_transition;
  state to = state::start;
  bool pending = false;
  bool clears = false;
  bool resets = false;
  bool ok = true;  // the axis afterwards is what the compiled step would make of it
};

// The facts an ordinary cycle leaves open, one way of each: the entry holds only where the full
// step answers the same for all of them.
struct variant {
  bool halt, standstill, entered_by_fault, latched;
  std::int8_t quick_stop_code, shutdown_code, disable_operation_code;
};

probe_result probe(const profile& p, state s, std::uint8_t word, bool edge, bool torque_was_on,
                   const variant& v) noexcept {
  axis a = make_axis(p);
  a.current = s;
  a.options[static_cast<int>(option::quick_stop)] = v.quick_stop_code;
  a.options[static_cast<int>(option::shutdown)] = v.shutdown_code;
  a.options[static_cast<int>(option::disable_operation)] = v.disable_operation_code;
  a.flags = static_cast<std::uint8_t>((torque_was_on ? axis_flag::torque_on : 0u) |
                                      (v.entered_by_fault ? axis_flag::entered_by_fault : 0u) |
                                      (v.latched ? axis_flag::fault_latched : 0u));
  a.error_code = 0x1234;  // shows whether the step clears it
  drive_inputs in;
  in.control_word = static_cast<std::uint16_t>(word | (edge ? 0x80u : 0u) | (v.halt ? 0x100u : 0u));
  in.standstill = v.standstill;
  const axis before = a;
  const drive_outputs out = detail::full_step(p, a, in);
  probe_result r;
  r.transition = out.transition;
  r.to = a.current;
  r.pending = a.pending_row != no_pending_row;
  r.clears = out.clear_setpoints;
  r.resets = a.error_code == 0;
  // The compiled step keeps these as they were, or clears them on a commit as full_step does.
  const bool committed = out.transition != no_transition;
  const unsigned remembered = axis_flag::entered_by_fault | axis_flag::fault_latched;
  const unsigned kept = committed ? (before.flags & axis_flag::fault_latched) : (before.flags & remembered);
  r.ok = (a.flags & remembered) == kept && a.stop_code == 0 &&
         (r.resets ? committed : a.error_code == 0x1234);
  return r;
}

bool resting(const profile& p, state s) noexcept {
  const state_activity act = p.info(s).activity;
  return act != state_activity::quick_stop && act != state_activity::fault_reaction;
}

}  // namespace

compiled_profile::compiled_profile(const profile& p) noexcept : profile_(&p) {
  has_speed_limit_ = p.speed_limit_rpm > 0;
  speed_span_ = has_speed_limit_ ? static_cast<std::uint64_t>(2 * std::int64_t{p.speed_limit_rpm} - 2) : 0u;
  has_halt_ = p.spec(option::halt).exists();
  const std::array<std::uint8_t, 8> words = word_of_command(p);
  // Every fact an ordinary cycle does not fix, both ways: where the full step does not care, the
  // entry holds; where it does, the full step decides.
  variant variants[192];
  std::size_t n = 0;
  for (unsigned v = 0; v < 64; ++v) {
    for (const std::int8_t qs : {std::int8_t{0}, std::int8_t{1}, std::int8_t{5}}) {  // S5: coast, ends, holds
      variants[n++] = {(v & 1u) != 0, (v & 2u) != 0, (v & 4u) != 0, (v & 8u) != 0, qs,
                       static_cast<std::int8_t>((v >> 4) & 1u), static_cast<std::int8_t>((v >> 5) & 1u)};
    }
  }
  for (unsigned key = 0; key < entry_count; ++key) {
    const auto s = static_cast<state>(key >> 5);
    const unsigned command = (key >> 2) & 7u;
    const bool edge = (key >> 1) & 1u;
    const bool torque_was_on = key & 1u;
    unsigned actions = fallback;
    probe_result first;
    if (command < static_cast<unsigned>(command_count) && words[command] != no_word && resting(p, s)) {
      bool same = true;
      for (std::size_t k = 0; k < n && same; ++k) {
        const probe_result r = probe(p, s, words[command], edge, torque_was_on, variants[k]);
        if (!r.ok || r.pending || !resting(p, r.to)) {
          same = false;
        } else if (k == 0) {
          first = r;
        } else {
          same = r.transition == first.transition && r.to == first.to && r.clears == first.clears &&
                 r.resets == first.resets;
        }
      }
      if (same) {
        actions = first.transition == no_transition ? 0u : commit;
        if (first.clears) actions |= clears;
        if (first.resets) actions |= resets_error;
      }
    }
    // The outputs the entry stands for, as the ordinary cycle's: DC link and remote in the status
    // word, torque and brake as the state's activity says, no ramp (halt adds its own).
    drive_outputs out;
    const state to = (actions & commit) ? first.to : s;
    const state_info info = p.info(to);
    out.current = to;
    out.status_word = static_cast<std::uint16_t>(info.status_pattern | status_bit::voltage_enabled |
                                                 status_bit::remote);
    out.transition = (actions & commit) ? first.transition : no_transition;
    out.ramp = stop_ramp::none;
    out.torque = info.activity != state_activity::idle;
    out.brake_released = out.torque;
    if (info.activity == state_activity::run) actions |= run;
    std::uint64_t lo = 0;
    std::memcpy(&lo, &out, 8);
    namespace at = outputs_layout;
    lo = (lo & ~(std::uint64_t{0xFF} << at::actions)) | (static_cast<std::uint64_t>(actions) << at::actions);
    table_[key] = lo;
  }
}

std::size_t compiled_profile::covered() const noexcept {
  std::size_t n = 0;
  for (const std::uint64_t e : table_) n += ((e >> outputs_layout::actions) & fallback) == 0;
  return n;
}

}  // namespace cia402
