#include "cli/master_output.hpp"

#include <ostream>

#include "cia402/error_codes.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

using json = nlohmann::ordered_json;

json state_json(const axes::result& r) {
  return {{"state", r.shown ? json(state_name(*r.shown)) : json(nullptr)},
          {"statusword", hex(r.status_word, 4)},
          {"error_code", hex(r.error_code, 4)}};
}

std::string state_words(const axes::result& r) {
  std::string s = std::string(r.shown ? state_name(*r.shown) : "UNKNOWN") + " (statusword " + hex(r.status_word, 4) + ")";
  if (r.error_code != 0) s += ", error code " + hex(r.error_code, 4) + " (" + error_code_text(r.error_code) + ")";
  return s;
}

json merged(json first, const json& rest) {
  first.update(rest);
  return first;
}

std::string joined(const std::vector<std::string>& list) {
  std::string s;
  for (const std::string& x : list) s += (s.empty() ? "" : ", ") + x;
  return s;
}

}  // namespace

void master_output::drive(const drive_tag& who, const json& fields, const std::string& prose) {
  if (json_) {
    *out_ << merged(json{{who.key, who.number}}, fields).dump() << "\n";
  } else {
    *out_ << who.prose() << ": " << prose << "\n";
  }
  out_->flush();
}

void master_output::line(const json& fields, const std::string& prose) {
  *out_ << (json_ ? fields.dump() : prose) << "\n";
  out_->flush();
}

void master_output::failure(const drive_tag& who, const std::string& step, const std::string& why) {
  *err_ << "cia402 master: " << who.prose() << ": " << step << ": " << why << "\n";
  if (json_) drive(who, {{"event", "failed"}, {"step", step}, {"error", why}}, {});
}

void master_output::error(const std::string& why) {
  *err_ << "cia402 master: " << why << "\n";
  if (json_) line({{"event", "failed"}, {"error", why}}, {});
}

void master_output::state(const drive_tag& who, cia402::state s, std::uint16_t status_word, std::uint16_t error_code) {
  drive(who, {{"event", "state"}, {"state", state_name(s)}, {"statusword", hex(status_word, 4)}, {"error_code", hex(error_code, 4)}},
        std::string(state_name(s)) + " (statusword " + hex(status_word, 4) + ")");
}

void master_output::emergency(const drive_tag& who, std::uint16_t code, std::uint8_t reg, bool reg_known) {
  json j{{"event", "emcy"}, {"error_code", hex(code, 4)}};
  if (reg_known) j["error_register"] = hex(reg, 2);
  j["text"] = code == 0 ? "error reset" : error_code_text(code);
  drive(who, j,
        "EMCY " + hex(code, 4) + (code == 0 ? " (error reset)" : std::string(" ") + error_code_text(code)) +
            (reg_known ? ", error register " + hex(reg, 2) : std::string()));
}

void master_output::started(const drive_tag& who, const axes::drive_link& link) {
  json in = json::array(), out = json::array();
  std::string in_words, out_words;
  for (const axes::cyclic_object& o : link.cyclic_inputs()) {
    in.push_back(hex(o.index, 4) + ":" + std::to_string(o.sub));
    in_words += " " + hex(o.index, 4);
  }
  for (const axes::cyclic_object& o : link.cyclic_outputs()) {
    out.push_back(hex(o.index, 4) + ":" + std::to_string(o.sub));
    out_words += " " + hex(o.index, 4);
  }
  const std::uint32_t us = link.cycle_us();
  const std::string period = us % 1000 == 0 ? std::to_string(us / 1000) + " ms" : std::to_string(us) + " us";
  drive(who, {{"event", "started"}, {"cycle_us", us}, {"inputs", in}, {"outputs", out}},
        "configured and started (every " + period + "; cyclic in:" + in_words + "; out:" + out_words + ")");
}

void master_output::closed(const drive_tag& who, const axes::close_report& report) {
  if (report.restored.empty() && report.left.empty()) return;
  std::string words;
  if (!report.restored.empty()) words = "put back as found: " + joined(report.restored);
  if (!report.left.empty()) words += (words.empty() ? "" : "; ") + std::string("left: ") + joined(report.left);
  drive(who, {{"event", "closed"}, {"restored", report.restored}, {"left", report.left}}, words);
}

void master_output::progress(const drive_tag& who, axes::progress_kind kind, const axes::result& r,
                             const std::string& stream_words, std::uint32_t cycle_us) {
  using axes::progress_kind;
  switch (kind) {
    case progress_kind::mode_confirmed: {
      const std::int64_t m = r.mode.value_or(0);
      return drive(who, {{"event", "mode"}, {"mode", m}, {"name", mode::short_name(m)}},
                   "mode " + std::to_string(m) + " (" + mode::short_name(m) + ")");
    }
    case progress_kind::set_point:
      return drive(who, {{"event", "setpoint"}, {"position", r.position.value_or(0)}}, "set-point " + std::to_string(r.position.value_or(0)));
    case progress_kind::target_velocity:
      return drive(who, {{"event", "target_velocity"}, {"velocity_rpm", r.velocity.value_or(0)}},
                   "0x60FF target velocity = " + std::to_string(r.velocity.value_or(0)) + " rpm");
    case progress_kind::target_torque:
      return drive(who, {{"event", "target_torque"}, {"torque_permille", r.torque.value_or(0)}},
                   "0x6071 target torque = " + std::to_string(r.torque.value_or(0)) + " permille");
    case progress_kind::homing_started: return drive(who, {{"event", "homing_started"}}, "homing started");
    case progress_kind::jog_started:
      return drive(who, {{"event", "jog"}, {"velocity_rpm", r.velocity.value_or(0)}},
                   "jogging at " + std::to_string(r.velocity.value_or(0)) + " rpm");
    case progress_kind::stream_started:
      return drive(who,
                   {{"event", "stream_started"}, {"from", r.stream_from}, {"to", r.stream_to},
                    {"velocity_rpm", r.velocity.value_or(0)}, {"sync_us", cycle_us}},
                   "streaming 0x607A from " + std::to_string(r.stream_from) + " to " + std::to_string(r.stream_to) + " at " +
                       std::to_string(r.velocity.value_or(0)) + " rpm " + stream_words);
  }
}

void master_output::result(const drive_tag& who, const master_step& step, const axes::result& r) {
  const std::string& v = step.verb;
  if (v == "state") {
    json j = merged(json{{"event", "status"}}, state_json(r));
    if (r.error_code != 0) j["error_text"] = error_code_text(r.error_code);
    return drive(who, j, state_words(r));
  }
  if (v == "enable" || v == "disable" || (v == "reset" && r.note.empty())) {
    return drive(who, merged(json{{"event", "reached"}}, state_json(r)),
                 std::string("reached ") + (r.shown ? state_name(*r.shown) : "UNKNOWN"));
  }
  if (v == "reset") {
    return drive(who, merged(json{{"event", "nothing_to_reset"}}, state_json(r)), state_words(r) + ": " + r.note);
  }
  if (v == "quick-stop") {
    return drive(who, merged(json{{"event", "quick_stop_done"}}, state_json(r)),
                 std::string("quick stop done, ") + (r.shown ? state_name(*r.shown) : "UNKNOWN"));
  }
  if (v == "halt") return drive(who, {{"event", "halt"}, {"on", step.on}}, std::string("halt ") + (step.on ? "on" : "off") + " (control bit 8)");
  if (v == "mode") return;  // said by its progress line
  if (v == "move") {
    return drive(who, {{"event", "reached"}, {"position", r.position.value_or(0)}},
                 "target reached, position " + std::to_string(r.position.value_or(0)));
  }
  if (v == "velocity") {
    return drive(who, merged(json{{"event", "reached"}}, json{{"state", r.shown ? state_name(*r.shown) : "UNKNOWN"}, {"velocity_rpm", r.velocity.value_or(0)}}),
                 "running at " + std::to_string(r.velocity.value_or(0)) + " rpm in " + (r.shown ? state_name(*r.shown) : "UNKNOWN"));
  }
  if (v == "torque") {
    return drive(who, {{"event", "reached"}, {"torque_permille", r.torque.value_or(0)}},
                 "torque " + std::to_string(r.torque.value_or(0)) + " permille reached");
  }
  if (v == "home") {
    return drive(who, {{"event", "homed"}, {"position", r.position.value_or(0)}},
                 "homing attained, position " + std::to_string(r.position.value_or(0)));
  }
  if (v == "jog") {
    return drive(who, {{"event", "jog_released"}, {"velocity_rpm", r.velocity.value_or(0)}},
                 "jog released, at " + std::to_string(r.velocity.value_or(0)) + " rpm");
  }
  if (v == "csp-stream") {
    return drive(who,
                 {{"event", "streamed"}, {"position", r.position.value_or(0)}, {"set_points", r.set_points},
                  {"max_following_error", r.max_following_error}},
                 "reached " + std::to_string(r.position.value_or(0)) + " after " + std::to_string(r.set_points) +
                     " set-points, max following error " + std::to_string(r.max_following_error) + " increments");
  }
  if (v == "sdo read" || v == "sdo write") {
    const bool writing = v == "sdo write";
    const std::string object = hex(step.index, 4) + ":" + std::to_string(step.sub);
    json j{{"event", writing ? "sdo_written" : "sdo"}, {"object", object}};
    if (r.value) j["value"] = json::parse(axes::value_json(*r.value, r.format));
    j["type"] = r.format ? r.format->type_name() : std::string("unknown");
    std::string words = object + (writing ? " written: " : " = ") + (r.value ? axes::value_text(*r.value, r.format) : "");
    if (!r.format) words += writing ? ", as " + std::to_string(r.size) + " byte(s): the size the drive took" : ", type not known";
    if (r.size != 0) j["size"] = r.size;
    if (!r.note.empty()) {
      j["note"] = r.note;
      words += " (" + r.note + ")";
    }
    return drive(who, j, words);
  }
}

}  // namespace cia402::cli
