#include "cia402/replay.hpp"

#include <cstring>
#include <limits>
#include <optional>
#include <nlohmann/json.hpp>

#include "cia402/support/text.hpp"

namespace cia402 {
namespace {

using support::hex;
using support::split_words;

// A number as `cia402 replay` reads one: decimal or 0x-hexadecimal, within 32 bits signed or
// unsigned; each event checks its own range after.
std::optional<std::int64_t> parse_number(std::string_view text) {
  return support::parse_integer(text, std::numeric_limits<std::int32_t>::min(),
                                std::numeric_limits<std::uint32_t>::max());
}

bool same_outputs(const drive_outputs& a, const drive_outputs& b) {
  return a.current == b.current && a.status_word == b.status_word && a.ramp == b.ramp &&
         a.torque == b.torque && a.brake_released == b.brake_released &&
         a.clear_setpoints == b.clear_setpoints && a.error_code == b.error_code &&
         a.error_register == b.error_register;
}

bool same_axis(const axis& a, const axis& b) {
  return std::memcmp(&a, &b, sizeof(axis)) == 0;
}

}  // namespace

settle_result settle(const profile& p, axis& a, const drive_inputs& in,
                     const drive_outputs* previous) {
  settle_result result;
  bool stepped = previous != nullptr;
  if (previous != nullptr) result.last = *previous;
  for (int i = 0; i < max_settle_steps && !result.settled; ++i) {
    const axis before = a;
    const drive_outputs out = step(p, a, in);
    if (out.transition != no_transition) result.transitions.push_back(out.transition);
    result.settled = out.transition == no_transition && same_axis(before, a) && stepped &&
                     same_outputs(out, result.last);
    result.last = out;
    stepped = true;
  }
  return result;
}

replay_session::replay_session(const profile& p) : profile_(&p), axis_(make_axis(p)) {}

sdo_abort replay_session::write(std::uint16_t index, std::int32_t value) {
  return write_option(*profile_, axis_, index, value);
}

std::string replay_session::power_up() { return settle_line(); }

std::string replay_session::settle_line() {
  const settle_result r = settle(*profile_, axis_, inputs_, stepped_ ? &last_ : nullptr);
  last_ = r.last;
  stepped_ = true;
  std::string transitions;
  for (const std::uint8_t t : r.transitions) {
    transitions += (transitions.empty() ? "" : ",") + std::to_string(t);
  }
  std::string line = std::string("{\"state\":\"") + state_name(last_.current) +
                     "\",\"statusword\":\"" + hex(last_.status_word, 4) + "\",\"transitions\":[" +
                     transitions + "],\"torque\":" + (last_.torque ? "true" : "false") +
                     ",\"brake\":\"" + (last_.brake_released ? "released" : "engaged") +
                     "\",\"ramp\":\"" + stop_ramp_name(last_.ramp) + "\",\"error_code\":\"" +
                     hex(last_.error_code, 4) + "\"";
  if (!r.settled) line += ",\"settled\":false";
  return line + "}";
}

// The reason may echo bytes of the input that are not UTF-8: they become U+FFFD, so every line
// replay prints is valid JSON whatever it was fed.
std::string replay_session::error(std::string_view reason, int line_number) const {
  const nlohmann::ordered_json line = {{"error", std::string(reason)}, {"line", line_number}};
  return line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

std::string replay_session::feed(std::string_view line, int line_number) {
  if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) {
    line = line.substr(0, hash);
  }
  const std::vector<std::string_view> words = split_words(line);
  if (words.empty()) return "";
  return handle(words, line_number);
}

// Every check comes before any change, so a refused line leaves drive and inputs as they were.
std::string replay_session::handle_fault(const std::vector<std::string_view>& words,
                                         int line_number) {
  const std::size_t args = words.size() - 1;
  const bool class_word = args == 3 && words[2] == "class";
  if (args > 2 && !class_word) {
    return error("'fault' takes at most a code and a class: fault [CODE [class N]]", line_number);
  }
  std::uint16_t code = error_code::generic;
  std::uint8_t error_class = drive_inputs{}.fault_class;
  if (args >= 1) {
    const auto v = parse_number(words[1]);
    if (!v || *v < 1 || *v > 0xFFFF) {
      return error("fault code '" + std::string(words[1]) + "' is not an error code 0x0001..0xFFFF",
                   line_number);
    }
    code = static_cast<std::uint16_t>(*v);
  }
  if (class_word) {
    // Profiles without error classes take every class as a fault (the drive ignores it).
    const auto v = parse_number(words[3]);
    if (!v || *v < 0 || *v > 4) {
      return error("fault class '" + std::string(words[3]) + "' is not 0..4", line_number);
    }
    error_class = static_cast<std::uint8_t>(*v);
  } else if (args == 2) {
    if (!profile_->error_classes) {
      return error(std::string("profile '") + profile_->name +
                       "' has no error classes; write 'fault CODE'",
                   line_number);
    }
    const auto v = parse_number(words[2]);
    if (!v || *v < 0 || *v > 4) {
      return error("fault class '" + std::string(words[2]) + "' is not 0..4", line_number);
    }
    error_class = static_cast<std::uint8_t>(*v);
  }
  // A cause that is raised again becomes the newest.
  std::erase_if(faults_, [&](const auto& f) { return f.first == code; });
  faults_.emplace_back(code, error_class);
  inputs_.fault_code = code;
  inputs_.fault_class = error_class;
  return settle_line();
}

std::string replay_session::handle_set(const std::vector<std::string_view>& words,
                                       int line_number) {
  if (words.size() != 3) {
    return error("'set' takes an index and a value: set INDEX VALUE", line_number);
  }
  const auto index = parse_number(words[1]);
  if (!index || *index < 0 || *index > 0xFFFF) {
    return error("index '" + std::string(words[1]) + "' is not a 16-bit object index", line_number);
  }
  const auto value = parse_number(words[2]);
  if (!value || *value < INT32_MIN || *value > INT32_MAX) {
    return error("value '" + std::string(words[2]) + "' is not a number", line_number);
  }
  const sdo_abort result = write_option(*profile_, axis_, static_cast<std::uint16_t>(*index),
                                        static_cast<std::int32_t>(*value));
  if (result != sdo_abort::none) {
    return error("set " + hex(static_cast<std::uint32_t>(*index), 4) + " " +
                     std::to_string(*value) + " refused: " + sdo_abort_words(result).c_str(),
                 line_number);
  }
  return settle_line();
}

std::string replay_session::handle(const std::vector<std::string_view>& words, int line_number) {
  const std::string_view event = words[0];
  const std::size_t args = words.size() - 1;
  auto wrong_count = [&](std::string_view usage) {
    return error("'" + std::string(event) + "' takes " + std::string(usage), line_number);
  };

  if (event == "cw") {
    if (args != 1) return wrong_count("one value: cw VALUE");
    const auto v = parse_number(words[1]);
    if (!v) return error("cw value '" + std::string(words[1]) + "' is not a number", line_number);
    if (*v < 0 || *v > 0xFFFF) {
      return error("cw value '" + std::string(words[1]) + "' does not fit 16 bits", line_number);
    }
    inputs_.control_word = static_cast<std::uint16_t>(*v);
    return settle_line();
  }
  if (event == "fault") return handle_fault(words, line_number);
  if (event == "clear") {
    if (args != 0) return wrong_count("no argument: clear");
    faults_.clear();
    inputs_.fault_code = 0;
    inputs_.fault_class = drive_inputs{}.fault_class;
    return settle_line();
  }
  if (event == "set") return handle_set(words, line_number);
  if (event == "voltage" || event == "sto") {
    if (args != 1 || (words[1] != "on" && words[1] != "off")) {
      return wrong_count("on or off: " + std::string(event) + " on|off");
    }
    const bool on = words[1] == "on";
    if (event == "voltage")
      inputs_.dc_link = on;
    else
      inputs_.sto = on;
    return settle_line();
  }
  if (event == "moving" || event == "standstill") {
    if (args != 0) return wrong_count("no argument: " + std::string(event));
    inputs_.standstill = event == "standstill";
    return settle_line();
  }
  if (event == "local") {
    if (args != 1 || (words[1] != "enable" && words[1] != "disable" && words[1] != "off")) {
      return wrong_count("enable, disable or off: local enable|disable|off");
    }
    inputs_.local_enable = words[1] == "enable";
    inputs_.local_disable = words[1] == "disable";
    return settle_line();
  }
  if (event == "remote") {
    if (args != 1 || (words[1] != "on" && words[1] != "off")) {
      return wrong_count("on or off: remote on|off");
    }
    inputs_.remote = words[1] == "on";
    return settle_line();
  }
  if (event == "link") {
    if (args != 1 || (words[1] != "lost" && words[1] != "ok")) {
      return wrong_count("lost or ok: link lost|ok");
    }
    inputs_.connection_lost = words[1] == "lost";
    return settle_line();
  }
  return error("unknown event '" + std::string(event) +
                   "' (cw, fault, clear, set, voltage, sto, moving, standstill, local, remote, link)",
               line_number);
}

}  // namespace cia402
