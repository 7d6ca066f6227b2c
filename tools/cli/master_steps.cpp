#include "cli/master_steps.hpp"

#include <algorithm>
#include <array>
#include <string_view>

#include "cia402/axis/object_value.hpp"
#include "cia402/objects.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

constexpr std::array<std::string_view, 12> global_options{"--can",   "--ecat",      "--position", "--node",
                                                          "--profile", "--profile-file", "--cycle", "--timeout",
                                                          "--heartbeat", "--guard",  "--sync-us",  "--eds"};
constexpr std::array<std::string_view, 4> global_flags{"--json", "--hold", "--help", "-h"};
constexpr std::array<std::string_view, 5> nmt_commands{"start", "stop", "preop", "reset", "reset-communication"};
constexpr std::int64_t longest_wait_ms = 3'600'000;

template <std::size_t N>
bool one_of(const std::array<std::string_view, N>& list, std::string_view s) {
  return std::find(list.begin(), list.end(), s) != list.end();
}

// A number for an object of the core's table: within its type.
bool number_for(std::string_view text, std::uint16_t index, std::int64_t& out, std::string& why) {
  const auto v = axes::parse_integer(text);
  const object_description* o = find_drive_object(index);
  if (!v || o == nullptr || *v < type_min(o->type) || *v > type_max(o->type)) {
    why = "'" + std::string(text) + "' is not a value for " + hex(index, 4) +
          (o != nullptr ? std::string(" (") + o->name + "): an integer from " + std::to_string(type_min(o->type)) + " to " +
                              std::to_string(type_max(o->type))
                        : std::string());
    return false;
  }
  out = *v;
  return true;
}

bool number_within(std::string_view text, std::int64_t low, std::int64_t high, const std::string& what, std::int64_t& out,
                   std::string& why) {
  const auto v = axes::parse_integer(text);
  if (!v || *v < low || *v > high) {
    why = what + ": '" + std::string(text) + "' is not an integer from " + std::to_string(low) + " to " + std::to_string(high);
    return false;
  }
  out = *v;
  return true;
}

bool parse_object(std::string_view where, master_step& s, std::string& why) {
  const auto colon = where.find(':');
  const auto index = axes::parse_integer(where.substr(0, colon));
  const auto sub = colon == std::string_view::npos ? std::optional<std::int64_t>(0) : axes::parse_integer(where.substr(colon + 1));
  if (!index || *index < 0 || *index > 0xFFFF || !sub || *sub < 0 || *sub > 0xFF) {
    why = "'" + std::string(where) + "' is not INDEX[:SUB] (e.g. 0x6060 or 0x1018:1)";
    return false;
  }
  s.index = static_cast<std::uint16_t>(*index);
  s.sub = static_cast<std::uint8_t>(*sub);
  return true;
}

// The operands of a step, taken from `words` at `i` (which it moves past them).
bool take_operands(master_step& s, const std::vector<std::string>& words, std::size_t& i, std::string& why) {
  const auto next = [&](const char* what) -> std::optional<std::string> {
    if (i < words.size() && words[i].rfind("--", 0) != 0) return words[i++];
    why = s.verb + " " + what + ": missing";
    return std::nullopt;
  };
  const std::string& v = s.verb;
  if (v == "state" || v == "enable" || v == "disable" || v == "quick-stop" || v == "reset" || v == "watch" ||
      v == "csp-stream") {
    return true;
  }
  if (v == "halt") {
    const auto w = next("on|off");
    if (!w) return false;
    if (*w != "on" && *w != "off") return (why = "halt on|off: '" + *w + "'", false);
    s.on = *w == "on";
    return true;
  }
  if (v == "mode") {
    const auto w = next("MODE");
    if (!w) return false;
    if (!mode::parse(*w, s.mode)) return (why = "mode MODE: pp, pv, tq, hm, csp, csv, cst or the number of 0x6060, not '" + *w + "'", false);
    return true;
  }
  if (v == "move") return next("POSITION") && number_for(words[i - 1], object_index::target_position, s.number, why);
  if (v == "velocity") return next("RPM") && number_for(words[i - 1], object_index::target_velocity, s.number, why);
  if (v == "torque") return next("PERMILLE") && number_for(words[i - 1], object_index::target_torque, s.number, why);
  if (v == "wait") return next("MS") && number_within(words[i - 1], 0, longest_wait_ms, "wait MS", s.number, why);
  if (v == "jog") {
    return next("RPM") && number_for(words[i - 1], object_index::target_velocity, s.number, why) && next("MS") &&
           number_within(words[i - 1], 1, longest_wait_ms, "jog RPM MS", s.number2, why);
  }
  if (v == "home") {
    // The method is optional: a number right after home.
    if (i < words.size() && axes::parse_integer(words[i])) {
      std::int64_t m = 0;
      if (!number_for(words[i++], object_index::homing_method, m, why)) return false;
      s.method = m;
    }
    return true;
  }
  if (v == "nmt") {
    const auto w = next("start|stop|preop|reset|reset-communication");
    if (!w) return false;
    if (!one_of(nmt_commands, *w)) return (why = "nmt start|stop|preop|reset|reset-communication: '" + *w + "'", false);
    s.nmt = *w;
    return true;
  }
  if (v == "sdo") {
    const auto how = next("read|write");
    if (!how) return false;
    if (*how != "read" && *how != "write") return (why = "sdo read INDEX[:SUB] | sdo write INDEX[:SUB] VALUE", false);
    s.verb = "sdo " + *how;
    const auto where = next("INDEX[:SUB]");
    if (!where || !parse_object(*where, s, why)) return false;
    if (*how == "read") return true;
    const auto value = next("VALUE");
    if (!value) return false;
    s.value = *value;
    // A CiA 402 object's type is known here: a value outside it is refused before anything is sent.
    if (const object_description* o = find_drive_object(s.index, s.sub)) {
      std::string bad;
      if (!axes::parse_value(s.value, axes::format_of(o->type), bad)) return (why = "sdo write " + *where + ": " + bad + " (" + o->name + ")", false);
    }
    return true;
  }
  why = "'" + v + "' is not a step (state, enable, disable, quick-stop, reset, halt, mode, move, velocity, torque, home, "
                  "jog, csp-stream, wait, watch, sdo, nmt)";
  return false;
}

// An option that belongs to the step before it.
bool take_option(master_step& s, std::string_view name, std::string_view value, std::string& why) {
  const auto fits = [&](const char* verb) { return s.verb == verb; };
  if (name == "--relative") {
    if (!fits("move")) return (why = "--relative belongs to move, not " + s.verb, false);
    s.relative = true;
    return true;
  }
  std::int64_t v = 0;
  if (name == "--velocity") {
    if (!fits("move") && !fits("csp-stream")) return (why = "--velocity belongs to move or csp-stream, not " + s.verb, false);
    if (!number_within(value, 1, 100000, s.verb + " --velocity", v, why)) return false;
    s.velocity = v;
  } else if (name == "--to") {
    if (!fits("csp-stream")) return (why = "--to belongs to csp-stream, not " + s.verb, false);
    if (!number_for(value, object_index::target_position, v, why)) return false;
    s.to = v;
  } else if (name == "--offset" || name == "--method") {
    if (!fits("home")) return (why = std::string(name) + " belongs to home, not " + s.verb, false);
    if (!number_for(value, name == "--offset" ? object_index::home_offset : object_index::homing_method, v, why)) return false;
    (name == "--offset" ? s.offset : s.method) = v;
  } else {
    why = "unknown option " + std::string(name);
    return false;
  }
  s.text += " " + std::string(name) + " " + std::string(value);
  return true;
}

}  // namespace

std::optional<std::vector<master_step>> parse_master_steps(const std::vector<std::string>& raw, std::string& why) {
  const auto from = std::find(raw.begin(), raw.end(), "master");
  const std::vector<std::string> words(from == raw.end() ? raw.begin() : from + 1, raw.end());
  std::vector<master_step> steps;
  for (std::size_t i = 0; i < words.size();) {
    const std::string& w = words[i];
    if (w.rfind("--", 0) == 0 || w == "-h") {
      const auto eq = w.find('=');
      const std::string name = w.substr(0, eq);
      if (one_of(global_options, name)) {
        i += eq == std::string::npos ? 2 : 1;
        continue;
      }
      if (one_of(global_flags, name)) {
        ++i;
        continue;
      }
      if (steps.empty()) {
        why = name + " must follow the step it belongs to";
        return std::nullopt;
      }
      std::string value;
      if (name != "--relative") {
        if (eq != std::string::npos) {
          value = w.substr(eq + 1);
        } else if (i + 1 < words.size()) {
          value = words[++i];
        }
      }
      ++i;
      if (!take_option(steps.back(), name, value, why)) return std::nullopt;
      continue;
    }
    master_step s;
    s.verb = w;
    const std::size_t first = i++;
    if (!take_operands(s, words, i, why)) return std::nullopt;
    s.text.clear();
    for (std::size_t k = first; k < i; ++k) s.text += (k == first ? "" : " ") + words[k];
    steps.push_back(std::move(s));
  }
  if (steps.empty()) {
    why = "no step given";
    return std::nullopt;
  }
  for (const master_step& s : steps) {
    if (s.verb == "csp-stream" && (!s.to || !s.velocity)) {
      why = "csp-stream --to POSITION --velocity RPM: both are needed";
      return std::nullopt;
    }
  }
  return steps;
}

}  // namespace cia402::cli
