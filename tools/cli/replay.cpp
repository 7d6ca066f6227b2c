#include "cli/replay.hpp"

#include <cstring>
#include <istream>
#include <nlohmann/json.hpp>
#include <ostream>

#include "cli/common.hpp"

namespace cia402::cli {
namespace {

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

std::string abort_text(sdo_abort code) {
  return "SDO abort " + hex(static_cast<std::uint32_t>(code), 8) + " (" + sdo_abort_text(code) +
         ")";
}

}  // namespace

bool parse_option_write(std::string_view text, option_write& out, std::string& error) {
  const std::size_t eq = text.find('=');
  if (eq == std::string_view::npos) {
    error = "expected INDEX=VALUE, e.g. 0x605A=6";
    return false;
  }
  const auto index = parse_number(text.substr(0, eq));
  if (!index || *index < 0 || *index > 0xFFFF) {
    error = "index '" + std::string(text.substr(0, eq)) + "' is not a 16-bit object index";
    return false;
  }
  const auto value = parse_number(text.substr(eq + 1));
  if (!value || *value < INT32_MIN || *value > INT32_MAX) {
    error = "value '" + std::string(text.substr(eq + 1)) + "' is not a number";
    return false;
  }
  out.index = static_cast<std::uint16_t>(*index);
  out.value = static_cast<std::int32_t>(*value);
  return true;
}

replay_session::replay_session(const profile& p) : profile_(&p), axis_(make_axis(p)) {}

sdo_abort replay_session::write(const option_write& w) {
  return write_option(*profile_, axis_, w.index, w.value);
}

std::string replay_session::power_up() { return settle(); }

namespace {

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

// Steps with unchanged inputs until a step takes no transition and changes neither the axis nor the
// outputs: then every further step would be the same.
std::string replay_session::settle() {
  std::string transitions;
  bool settled = false;
  for (int i = 0; i < max_settle_steps && !settled; ++i) {
    const axis before = axis_;
    const drive_outputs out = step(*profile_, axis_, inputs_);
    if (out.transition != no_transition) {
      transitions += (transitions.empty() ? "" : ",") + std::to_string(out.transition);
    }
    settled = out.transition == no_transition && same_axis(before, axis_) && stepped_ &&
              same_outputs(out, last_);
    last_ = out;
    stepped_ = true;
  }
  std::string line = std::string("{\"state\":\"") + state_name(last_.current) +
                     "\",\"statusword\":\"" + hex(last_.status_word, 4) + "\",\"transitions\":[" +
                     transitions + "],\"torque\":" + (last_.torque ? "true" : "false") +
                     ",\"brake\":\"" + (last_.brake_released ? "released" : "engaged") +
                     "\",\"ramp\":\"" + stop_ramp_name(last_.ramp) + "\",\"error_code\":\"" +
                     hex(last_.error_code, 4) + "\"";
  if (!settled) line += ",\"settled\":false";
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
    return settle();
  }
  if (event == "fault") {
    const bool class_word = args == 3 && words[2] == "class";
    if (args > 2 && !class_word) {
      return wrong_count("at most a code and a class: fault [CODE [class N]]");
    }
    std::uint16_t code = error_code::generic;
    std::uint8_t error_class = drive_inputs{}.fault_class;
    if (args >= 1) {
      const auto v = parse_number(words[1]);
      if (!v || *v < 1 || *v > 0xFFFF) {
        return error(
            "fault code '" + std::string(words[1]) + "' is not an error code 0x0001..0xFFFF",
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
    return settle();
  }
  if (event == "clear") {
    if (args != 0) return wrong_count("no argument: clear");
    faults_.clear();
    inputs_.fault_code = 0;
    inputs_.fault_class = drive_inputs{}.fault_class;
    return settle();
  }
  if (event == "set") {
    if (args != 2) return wrong_count("an index and a value: set INDEX VALUE");
    const auto index = parse_number(words[1]);
    if (!index || *index < 0 || *index > 0xFFFF) {
      return error("index '" + std::string(words[1]) + "' is not a 16-bit object index",
                   line_number);
    }
    const auto value = parse_number(words[2]);
    if (!value || *value < INT32_MIN || *value > INT32_MAX) {
      return error("value '" + std::string(words[2]) + "' is not a number", line_number);
    }
    const sdo_abort result = write_option(*profile_, axis_, static_cast<std::uint16_t>(*index),
                                          static_cast<std::int32_t>(*value));
    if (result != sdo_abort::none) {
      return error("set " + hex(static_cast<std::uint32_t>(*index), 4) + " " +
                       std::to_string(*value) + " refused: " + abort_text(result),
                   line_number);
    }
    return settle();
  }
  if (event == "voltage" || event == "sto") {
    if (args != 1 || (words[1] != "on" && words[1] != "off")) {
      return wrong_count("on or off: " + std::string(event) + " on|off");
    }
    const bool on = words[1] == "on";
    if (event == "voltage")
      inputs_.dc_link = on;
    else
      inputs_.sto = on;
    return settle();
  }
  if (event == "moving" || event == "standstill") {
    if (args != 0) return wrong_count("no argument: " + std::string(event));
    inputs_.standstill = event == "standstill";
    return settle();
  }
  if (event == "local") {
    if (args != 1 || (words[1] != "enable" && words[1] != "disable" && words[1] != "off")) {
      return wrong_count("enable, disable or off: local enable|disable|off");
    }
    inputs_.local_enable = words[1] == "enable";
    inputs_.local_disable = words[1] == "disable";
    return settle();
  }
  if (event == "remote") {
    if (args != 1 || (words[1] != "on" && words[1] != "off")) {
      return wrong_count("on or off: remote on|off");
    }
    inputs_.remote = words[1] == "on";
    return settle();
  }
  if (event == "link") {
    if (args != 1 || (words[1] != "lost" && words[1] != "ok")) {
      return wrong_count("lost or ok: link lost|ok");
    }
    inputs_.connection_lost = words[1] == "lost";
    return settle();
  }
  return error("unknown event '" + std::string(event) +
                   "' (cw, fault, clear, set, voltage, sto, moving, standstill, local, remote, link)",
               line_number);
}

int run_replay(const profile& p, const std::vector<option_write>& writes, std::istream& in,
               std::ostream& out, std::ostream& err) {
  replay_session session(p);
  for (const option_write& w : writes) {
    const sdo_abort result = session.write(w);
    if (result != sdo_abort::none) {
      err << "cia402 replay: --set " << hex(w.index, 4) << "=" << w.value << " refused by profile '"
          << p.name << "': " << abort_text(result) << "\n";
      return 2;
    }
  }
  out << session.power_up() << "\n" << std::flush;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string result = session.feed(line, line_number);
    if (!result.empty()) out << result << "\n" << std::flush;
  }
  return 0;
}

}  // namespace cia402::cli
