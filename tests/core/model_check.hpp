// An explicit-state model check of the drive-side machine: every axis state reachable from power-up
// under an input alphabet that covers a real plant, and on every reachable (state, input) pair the
// safety invariants of docs/semantics.md. The step under test is a parameter, so the same search
// proves a faster step (a compiled table, say) equal to detail::full_step byte for byte.
//
// The alphabet: every command the profile's decoder yields (one control word each), bit 7 and bit 8
// set or clear, no fault or a fault of each class (0..4 where the profile has error classes, else one
// class), DC link on/off, STO on/off, standstill or moving, brake engaged or not, remote on/off, the
// fieldbus link lost or not, and where the profile's rows read them, local enable/disable requests
// and the actual speed below or above its limit. The status bits the motion side reports are held
// clear; the compiled step is compared once more with every one of them set.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "cia402/compiled.hpp"
#include "cia402/drive.hpp"
#include "cia402/master.hpp"
#include "cia402/profile.hpp"
#include "test_support.hpp"

namespace cia402::model_check {


/// The fault code every injected fault carries; internal faults bring their own (S13, S14, S10).
inline constexpr std::uint16_t injected_fault = 0x5530;

/// Steps under one constant input within which every reachable state must come to rest.
inline constexpr int settle_bound = 8;

struct report {
  std::size_t states = 0;   ///< distinct axes reachable from power-up
  std::size_t pairs = 0;    ///< (state, input) pairs checked
  int deepest_settle = 0;   ///< the most steps any pair took to come to rest
  std::size_t violations = 0;
  std::map<std::string, std::size_t> kinds;   ///< violations by what was violated
  std::vector<std::string> first_violations;  ///< up to 12, described
};

inline bool reads_fact(const profile& p, fact f) {
  for (std::size_t i = 0; i < p.row_count; ++i) {
    const transition_row r = p.row(i);
    if ((r.any | r.all | r.none).has(f)) return true;
  }
  return false;
}

/// Every input of the alphabet for this profile.
inline std::vector<drive_inputs> alphabet(const profile& p) {
  // One control word per command the decoder yields over bits 0..4 (the first that does).
  std::vector<std::uint16_t> words;
  bool seen[command_count] = {};
  for (std::uint16_t bits = 0; bits < 32; ++bits) {
    const int c = static_cast<int>(p.decode(bits));
    if (!seen[c]) {
      seen[c] = true;
      words.push_back(bits);
    }
  }
  std::vector<int> classes = {-1};  // -1: no fault
  if (p.error_classes) {
    for (int c = 0; c <= 4; ++c) classes.push_back(c);
  } else {
    classes.push_back(2);
  }
  const bool local = reads_fact(p, fact::local_enable) || reads_fact(p, fact::local_disable);
  const bool speed = p.speed_limit_rpm > 0;

  std::vector<drive_inputs> out;
  for (const std::uint16_t w : words) {
    for (int b7 = 0; b7 < 2; ++b7) {
      for (int b8 = 0; b8 < 2; ++b8) {
        for (const int cls : classes) {
          for (unsigned plant = 0; plant < 64; ++plant) {
            for (int loc = 0; loc < (local ? 4 : 1); ++loc) {
              for (int spd = 0; spd < (speed ? 2 : 1); ++spd) {
                drive_inputs in;
                in.control_word = static_cast<std::uint16_t>(w | (b7 << 7) | (b8 << 8));
                in.fault_code = cls < 0 ? 0 : injected_fault;
                in.fault_class = static_cast<std::uint8_t>(cls < 0 ? 2 : cls);
                in.dc_link = (plant & 1u) == 0;
                in.sto = (plant & 2u) != 0;
                in.standstill = (plant & 4u) == 0;
                in.brake_engaged = (plant & 8u) == 0;
                in.remote = (plant & 16u) == 0;
                in.connection_lost = (plant & 32u) != 0;
                in.local_enable = (loc & 1) != 0;
                in.local_disable = (loc & 2) != 0;
                in.actual_speed_rpm = spd == 0 ? 0 : p.speed_limit_rpm + 1;
                out.push_back(in);
              }
            }
          }
        }
      }
    }
  }
  return out;
}

/// The option-code sets to search under: the defaults, then each supported value of each object
/// with the others at their defaults.
inline std::vector<std::array<std::int8_t, option_count>> option_sets(const profile& p) {
  std::array<std::int8_t, option_count> defaults{};
  for (int o = 0; o < option_count; ++o) defaults[o] = p.options[o].default_value;
  std::vector<std::array<std::int8_t, option_count>> sets = {defaults};
  for (int o = 0; o < option_count; ++o) {
    for (int v = 0; v < 16; ++v) {
      if (!p.options[o].allows(v) || v == defaults[o]) continue;
      std::array<std::int8_t, option_count> s = defaults;
      s[o] = static_cast<std::int8_t>(v);
      sets.push_back(s);
    }
  }
  return sets;
}

inline std::string describe(const drive_inputs& in) {
  std::ostringstream os;
  os << "cw=0x" << std::hex << in.control_word << std::dec << " fault=";
  if (in.fault_code) {
    os << "class " << int(in.fault_class);
  } else {
    os << "none";
  }
  os << (in.dc_link ? "" : " no-dc-link") << (in.sto ? " sto" : "")
     << (in.standstill ? "" : " moving") << (in.brake_engaged ? "" : " brake-open")
     << (in.remote ? "" : " local-control") << (in.connection_lost ? " link-lost" : "")
     << (in.local_enable ? " local-enable" : "") << (in.local_disable ? " local-disable" : "")
     << (in.actual_speed_rpm ? " overspeed" : "");
  return os.str();
}

inline std::string describe(const axis& a) {
  std::ostringstream os;
  os << state_name(a.current) << " pending=" << int(a.pending_row) << " flags=0x" << std::hex
     << int(a.flags) << " error=0x" << a.error_code << std::dec << " stop_code=" << int(a.stop_code)
     << " options=";
  for (int o = 0; o < option_count; ++o) os << (o ? "," : "") << int(a.options[o]);
  return os.str();
}

using test::same_outputs;

struct axis_key {
  std::array<std::uint8_t, sizeof(axis)> bytes{};
  explicit axis_key(const axis& a) { std::memcpy(bytes.data(), &a, sizeof(axis)); }
  bool operator==(const axis_key& o) const { return bytes == o.bytes; }
};
struct axis_key_hash {
  std::size_t operator()(const axis_key& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (const std::uint8_t b : k.bytes) h = (h ^ b) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

/// Searches every axis reachable from power-up with the given option codes, checks every pair.
/// The compiled step of `compiled`, unless null, must equal detail::full_step byte for byte (outputs
/// and axis) on every pair, as must the quiet step wherever it takes the cycle.
inline report check(const profile& p, const std::array<std::int8_t, option_count>& options,
                    const compiled_profile* compiled) {
  report r;
  const std::vector<drive_inputs> inputs = alphabet(p);
  auto violation = [&](const std::string& what, const axis& from, const drive_inputs& in) {
    ++r.violations;
    ++r.kinds[what];
    if (r.first_violations.size() < 12) {
      r.first_violations.push_back(what + "\n    from " + describe(from) + "\n    input " +
                                   describe(in));
    }
  };

  // decode_status over bits 0..6, once.
  std::array<int, 128> shown{};
  for (std::uint16_t bits = 0; bits < 128; ++bits) {
    state s;
    shown[bits] = decode_status(p, bits, s) ? static_cast<int>(s) : -1;
  }

  axis start = make_axis(p);
  for (int o = 0; o < option_count; ++o) start.options[o] = options[o];
  std::vector<axis> states = {start};
  std::unordered_map<axis_key, std::uint32_t, axis_key_hash> index;
  index.emplace(axis_key(start), 0u);
  // successor[state * inputs + input]: the state one step leads to, bit 15 if a transition was taken.
  constexpr std::uint16_t took_transition = 0x8000;
  std::vector<std::uint16_t> successor;

  for (std::size_t head = 0; head < states.size(); ++head) {
    const axis from = states[head];
    // S16: a stop code is latched only while its stop runs (the compiled step relies on it).
    const state_activity resting = p.info(from.current).activity;
    if (from.stop_code != 0 && !stop_running(from) && resting != state_activity::quick_stop &&
        resting != state_activity::fault_reaction) {
      violation("a stop code is latched outside a stop", from, drive_inputs{});
    }
    // Writes of every option code, supported or not: a refused one changes nothing; an accepted
    // one changes its value only, never the stop that runs (S16).
    for (int o = 0; o < option_count; ++o) {
      for (const int v : {-1, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 127}) {
        axis written = from;
        const sdo_abort result = write_option(p, written, option_index(static_cast<option>(o)), v);
        axis expected = from;
        if (result == sdo_abort::none) expected.options[o] = static_cast<std::int8_t>(v);
        if (std::memcmp(&written, &expected, sizeof(axis)) != 0) {
          violation("write of 0x" + std::to_string(option_index(static_cast<option>(o))) + " = " +
                        std::to_string(v) + " changed more than its value",
                    from, drive_inputs{});
        }
      }
    }
    successor.resize((head + 1) * inputs.size());
    axis last_next{};
    std::uint32_t last_index = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const drive_inputs& in = inputs[i];
      ++r.pairs;
      axis next = from;
      const drive_outputs out = detail::full_step(p, next, in);
      if (compiled != nullptr) {
        axis other = from;
        const drive_outputs other_out = step(*compiled, other, in);
        if (!same_outputs(out, other_out) || std::memcmp(&next, &other, sizeof(axis)) != 0) {
          violation("the compiled step differs from full_step", from, in);
        }
        // The reported status bits pass differently by state: every one set, the drive's own too.
        drive_inputs reporting = in;
        reporting.status_bits = 0xFFFF;
        axis full_axis = from, compiled_axis = from;
        const drive_outputs full_out = detail::full_step(p, full_axis, reporting);
        const drive_outputs compiled_out = step(*compiled, compiled_axis, reporting);
        if (!same_outputs(full_out, compiled_out) ||
            std::memcmp(&full_axis, &compiled_axis, sizeof(axis)) != 0) {
          violation("the compiled step differs from full_step with every status bit reported", from,
                    reporting);
        }
      }
      axis quiet = from;
      drive_outputs quiet_out;
      if (detail::quiet_step(p, quiet, in, quiet_out) &&
          (!same_outputs(out, quiet_out) || std::memcmp(&next, &quiet, sizeof(axis)) != 0)) {
        violation("the quiet step differs from full_step", from, in);
      }
      // The step every layer runs (the ordinary cycle's table, else the full step), also with
      // every status bit reported: the table's rows decide more than the quiet cycle.
      for (const std::uint16_t reported : {std::uint16_t{0}, std::uint16_t{0xFFFF}}) {
        drive_inputs with = in;
        with.status_bits = reported;
        axis full_axis = from, step_axis = from;
        const drive_outputs full_out = detail::full_step(p, full_axis, with);
        const drive_outputs step_out = step(p, step_axis, with);
        if (!same_outputs(full_out, step_out) ||
            std::memcmp(&full_axis, &step_axis, sizeof(axis)) != 0) {
          violation("step(profile) differs from full_step", from, with);
        }
      }

      // Safety (S12, S13, S14, S4): torque only where the state allows it, never without DC link or
      // under STO, the brake released only with torque, a coast-demanding fault cuts torque now.
      const bool coast_fault = in.sto || !in.dc_link ||
                               (p.error_classes && in.fault_code != 0 && in.fault_class >= 3);
      if (out.torque && !p.torque_allowed(out.current)) violation("torque in a state without it", from, in);
      if (out.torque && (!in.dc_link || in.sto)) violation("torque without DC link or under STO", from, in);
      if (out.brake_released && !out.torque) violation("brake released without torque", from, in);
      if (coast_fault && out.torque) violation("a coast-demanding fault left torque on", from, in);
      // Faults win over any command (S4): a fault that calls for the reaction takes T13 now.
      const bool reaction_fault = in.fault_code != 0 && (!p.error_classes || in.fault_class >= 2);
      const bool t13_source = (p.rows_from[static_cast<int>(from.current)] != 0) &&
                              from.current != state::start &&
                              from.current != state::fault_reaction_active &&
                              from.current != state::fault;
      if (reaction_fault && t13_source && out.current != state::fault_reaction_active) {
        violation("a fault did not take T13 at once", from, in);
      }
      // S14: under STO the drive is never switched on: no restart while it is active.
      if (in.sto && (out.current == state::ready_to_switch_on || out.current == state::switched_on ||
                     out.current == state::operation_enabled) &&
          from.current != out.current) {
        violation("a state that can switch on was entered under STO", from, in);
      }
      if (in.sto && from.current == state::ready_to_switch_on && out.current == state::ready_to_switch_on) {
        violation("STO left the drive in READY TO SWITCH ON (S14: T7)", from, in);
      }
      // S11: the status word shows the state.
      if (next.current != state::start && shown[out.status_word & 0x7Fu] != static_cast<int>(out.current)) {
        violation("the status word does not decode to the state", from, in);
      }

      // Successive inputs often lead to the same axis: look it up only when it differs.
      if (last_index == 0xFFFFFFFFu || std::memcmp(&last_next, &next, sizeof(axis)) != 0) {
        const auto [it, added] =
            index.emplace(axis_key(next), static_cast<std::uint32_t>(states.size()));
        if (added) states.push_back(next);
        last_index = it->second;
        last_next = next;
      }
      successor[head * inputs.size() + i] = static_cast<std::uint16_t>(
          last_index | (out.transition != no_transition ? took_transition : 0u));
    }
  }
  r.states = states.size();
  if (r.states >= took_transition) {
    violation("more states than the search can number", start, drive_inputs{});
    return r;
  }

  // No livelock: under each input held, every reachable state comes to rest (a step that takes no
  // transition and changes nothing) within settle_bound steps. rest[s]: steps from s, -1 unknown.
  const std::size_t n = states.size();
  std::vector<int> rest(n);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    std::fill(rest.begin(), rest.end(), -1);
    for (std::size_t s = 0; s < n; ++s) {
      // Walk forward until a known state or a resting one, then number the walk backwards.
      std::vector<std::size_t> walk;
      std::size_t at = s;
      int base = -1;
      while (rest[at] < 0 && walk.size() <= static_cast<std::size_t>(settle_bound)) {
        const std::uint16_t next = successor[at * inputs.size() + i];
        if ((next & took_transition) == 0 && (next & 0x7FFFu) == at) {
          base = 0;
          rest[at] = 0;
          break;
        }
        walk.push_back(at);
        at = next & 0x7FFFu;
      }
      if (base < 0) base = rest[at];
      if (base < 0) {
        violation("no rest within " + std::to_string(settle_bound) + " steps", states[s], inputs[i]);
        continue;
      }
      for (std::size_t k = walk.size(); k-- > 0;) rest[walk[k]] = ++base;
      if (rest[s] > r.deepest_settle) r.deepest_settle = rest[s];
    }
  }
  return r;
}

}  // namespace cia402::model_check
