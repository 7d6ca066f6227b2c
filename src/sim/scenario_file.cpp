// Scenario files: TOML in, a checked cia402::sim::scenario out. As with profile files, the whole
// scenario is built aside and handed over only when every key, name, time and start-up write has
// passed, so a caller gets a runnable scenario or a line and a reason, never half of one.
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>

#include "cia402/profile_file.hpp"
#include "cia402/objects.hpp"
#include "cia402/sim/scenario.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/support/text.hpp"
#include "cia402/support/toml_reading.hpp"
#include "scenario_reading.hpp"

static_assert(TOML_EXCEPTIONS, "the loader relies on toml::parse throwing toml::parse_error");

namespace cia402::sim {
namespace {

using support::hex;
using toml_reading::get_array;
using toml_reading::get_bool;
using toml_reading::get_int;
using toml_reading::get_string;
using toml_reading::get_table;
using toml_reading::refusal;
using toml_reading::refuse;
using toml_reading::refuse_type;
using toml_reading::type_name;

using scenario_reading::check_keys;
using scenario_reading::get_time_us;
using scenario_reading::get_velocity;
using scenario_reading::parse_index;
using scenario_reading::seconds_text;

struct loader {
  scenario s;
  std::string base_dir;
  std::uint64_t duration_us = 0;
  const toml::node* duration_node = nullptr;

  std::uint64_t cycle_of(const toml::node& n, std::string_view what) {
    const std::uint64_t us = get_time_us(n, what);
    const std::uint32_t cycle = s.plant.cycle_us;
    if (us % cycle != 0) {
      refuse(n, std::string(what) + " " + seconds_text(us) + " is not a multiple of the cycle (" +
                    seconds_text(cycle) + ")");
    }
    if (us > duration_us) {
      refuse(n, std::string(what) + " " + seconds_text(us) + " lies after the end of the run (" +
                    "duration " + seconds_text(duration_us) + ")");
    }
    return us / cycle;
  }

  void load_profile(const toml::table& root) {
    const toml::node* by_name = root.get("profile");
    const toml::node* by_file = root.get("profile_file");
    if (by_name && by_file) refuse(*by_file, "give either 'profile' or 'profile_file', not both");
    if (by_file) {
      const std::string_view file = get_string(*by_file, "profile_file");
      // A scenario names a profile file, never any file: one that is not a .toml file is not read,
      // so a scenario cannot make the tool open a device or show a line of a foreign file.
      if (file.size() < 6 || file.substr(file.size() - 5) != ".toml") {
        refuse(*by_file, "profile_file must name a .toml profile file");
      }
      std::filesystem::path path(file);
      if (path.is_relative()) path = std::filesystem::path(base_dir) / path;
      profile_load_result loaded = load_profile_toml_file(path.string());
      if (const auto* e = std::get_if<profile_file_error>(&loaded)) {
        refuse(*by_file, "profile file refused: " + e->message());
      }
      s.drive_profile = std::get<custom_profile>(loaded);
      return;
    }
    std::string_view name = "cia402";
    if (by_name) name = get_string(*by_name, "profile");
    const profile* p = find_builtin_profile(name);
    if (p == nullptr) {
      std::string list;
      for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
        list += (i ? ", " : "") + std::string(builtin_profile(i).name);
      }
      refuse(by_name ? *by_name : static_cast<const toml::node&>(root),
             "unknown profile " + toml_reading::quoted(name) + " (built-in: " + list + ")");
    }
    s.drive_profile = custom_profile(*p);
  }

  // Start-up writes go through the object interface of a scratch axis, so a refusal is known now.
  void load_objects(const toml::table& t) {
    axis_state scratch = make_axis_state(s.drive_profile.get());
    for (auto&& [key, value] : t) {
      std::uint16_t index = 0;
      std::uint8_t sub = 0;
      if (!parse_index(key.str(), index, sub)) {
        std::string hint;
        for (std::string_view root_key : {"events", "expect", "name", "duration", "cycle", "plant"}) {
          if (key.str() == root_key) {
            hint = " (a [table] lasts until the next one: write '" + std::string(root_key) +
                   "' before [objects], or as objects.0x605A = ... dotted keys)";
          }
        }
        refuse(key, "object key " + toml_reading::quoted(key.str()) +
                        " is not an index such as 0x605A (or \"0x607D:2\" with a sub-index)" + hint);
      }
      const std::int64_t v = get_int(value, "object " + hex(index, 4),
                                     std::numeric_limits<std::int64_t>::min(),
                                     std::numeric_limits<std::int64_t>::max());
      const sdo_abort r = write_object(s.drive_profile.get(), scratch, index, sub, v);
      if (r != sdo_abort::none) {
        refuse(value, "writing " + hex(index, 4) + (sub ? ":" + std::to_string(sub) : std::string()) + " = " +
                          std::to_string(v) + " is refused: SDO abort " + hex(static_cast<std::uint32_t>(r), 8) +
                          " (" + sdo_abort_text(r) + ")");
      }
      s.initial_writes.push_back({index, sub, v});
    }
  }

  void load_event(const toml::table& t) {
    check_keys(t,
               {"at", "write", "acceleration", "deceleration", "quick_stop_deceleration",
                "target_velocity", "target_position", "target_torque", "mode", "cw", "abort", "voltage",
                "sto", "connection_lost", "clear_fault", "fault", "fault_class"},
               "an event");
    const toml::node* at = t.get("at");
    if (at == nullptr) refuse(t, "an event needs 'at', the time it happens (e.g. at = \"10ms\")");
    scenario_event base;
    base.cycle = cycle_of(*at, "'at'");
    base.line = static_cast<int>(t.source().begin.line);
    std::vector<scenario_event> actions;

    auto add_write = [&](std::uint16_t index, const toml::node& n, std::string_view what, std::uint8_t sub = 0) {
      scenario_event e = base;
      e.what = scenario_event::kind::write;
      e.index = index;
      e.sub = sub;
      e.value = get_int(n, what, std::numeric_limits<std::int64_t>::min(),
                        std::numeric_limits<std::int64_t>::max());
      actions.push_back(e);
    };
    if (const auto* n = t.get("write")) {
      for (auto&& [key, value] : get_table(*n, "'write'")) {
        std::uint16_t index = 0;
        std::uint8_t sub = 0;
        if (!parse_index(key.str(), index, sub)) {
          refuse(key, "object key " + toml_reading::quoted(key.str()) +
                          " is not an index such as 0x605A (or \"0x607D:2\" with a sub-index)");
        }
        add_write(index, value, "object " + hex(index, 4), sub);
      }
    }
    if (const auto* n = t.get("acceleration")) add_write(object::profile_acceleration, *n, "acceleration");
    if (const auto* n = t.get("deceleration")) add_write(object::profile_deceleration, *n, "deceleration");
    if (const auto* n = t.get("quick_stop_deceleration")) {
      add_write(object::quick_stop_deceleration, *n, "quick_stop_deceleration");
    }
    if (const auto* n = t.get("target_velocity")) add_write(object::target_velocity, *n, "target_velocity");
    if (const auto* n = t.get("target_position")) add_write(object::target_position, *n, "target_position");
    if (const auto* n = t.get("target_torque")) add_write(object::target_torque, *n, "target_torque");
    if (const auto* n = t.get("mode")) {
      std::int8_t m = 0;
      const std::string text = n->is_string() ? std::string(get_string(*n, "mode"))
                                              : std::to_string(get_int(*n, "mode", -128, 127));
      if (!mode::parse(text, m)) refuse(*n, "mode must be pp, pv, tq, hm, csp, csv, cst or a number");
      scenario_event e = base;
      e.what = scenario_event::kind::write;
      e.index = object::modes_of_operation;
      e.value = m;
      actions.push_back(e);
    }
    if (const auto* n = t.get("cw")) add_write(object::control_word, *n, "cw");
    const std::size_t writes = actions.size();
    if (const auto* n = t.get("abort")) {
      if (writes != 1) refuse(*n, "'abort' needs exactly one write in its event");
      actions.back().expected_abort = static_cast<sdo_abort>(
          get_int(*n, "abort", 1, std::numeric_limits<std::uint32_t>::max()));
    }
    auto add_flag = [&](const char* key, scenario_event::kind k) {
      if (const auto* n = t.get(key)) {
        scenario_event e = base;
        e.what = k;
        e.flag = get_bool(*n, key);
        actions.push_back(e);
      }
    };
    add_flag("voltage", scenario_event::kind::dc_link);
    add_flag("sto", scenario_event::kind::sto);
    add_flag("connection_lost", scenario_event::kind::connection_lost);
    if (const auto* n = t.get("clear_fault")) {
      scenario_event e = base;
      if (n->is_string()) {
        if (get_string(*n, "clear_fault") != "all") {
          refuse(*n, "clear_fault must be an error code or \"all\"");
        }
        e.what = scenario_event::kind::clear_faults;
      } else {
        e.what = scenario_event::kind::clear_fault;
        e.code = static_cast<std::uint16_t>(get_int(*n, "clear_fault", 1, 0xFFFF));
      }
      actions.push_back(e);
    }
    const toml::node* fault_class = t.get("fault_class");
    if (const auto* n = t.get("fault")) {
      scenario_event e = base;
      e.what = scenario_event::kind::inject_fault;
      e.code = static_cast<std::uint16_t>(get_int(*n, "fault", 1, 0xFFFF));
      if (fault_class) {
        if (!s.drive_profile.get().error_classes) {
          refuse(*fault_class, std::string("profile '") + s.drive_profile.get().name +
                                   "' has no error classes; leave out fault_class");
        }
        e.fault_class = static_cast<std::uint8_t>(get_int(*fault_class, "fault_class", 0, 4));
      }
      actions.push_back(e);
    } else if (fault_class) {
      refuse(*fault_class, "fault_class needs a fault in the same event");
    }
    if (actions.empty()) {
      refuse(t, "an event needs an action: cw, mode, target_velocity, target_position, target_torque, "
                "acceleration, deceleration, quick_stop_deceleration, write, fault, clear_fault, voltage, "
                "sto or connection_lost");
    }
    s.events.insert(s.events.end(), actions.begin(), actions.end());
  }

  // `always = "rule"`: a rule checked on every cycle of the run.
  void load_rule(const toml::table& t, const toml::node& rule, expectation base, bool timed) {
    const toml::node* always = &rule;
    if (timed) refuse(*always, "'always' holds for the whole run: leave out at/between");
    if (t.size() != 1) refuse(t, "'always' stands alone in its expectation");
    const std::string_view name = get_string(*always, "always");
    expectation e = base;
    e.what = expectation::kind::always;
    bool found = false;
    for (invariant i : {invariant::brake_engaged_before_torque_off,
                        invariant::motion_waits_for_brake_release,
                        invariant::coast_removes_torque_at_once}) {
      if (name == invariant_name(i)) {
        e.rule = i;
        found = true;
      }
    }
    if (!found) {
      refuse(*always, "unknown rule " + toml_reading::quoted(name) +
                          " (brake_engaged_before_torque_off, motion_waits_for_brake_release, "
                          "coast_removes_torque_at_once)");
    }
    if (e.rule == invariant::motion_waits_for_brake_release && !s.plant.brake_fitted) {
      refuse(*always, "motion_waits_for_brake_release needs a brake ([plant] brake = true)");
    }
    e.first_cycle = 0;
    e.last_cycle = s.cycles - 1;
    e.window = true;
    s.expectations.push_back(e);
  }

  // velocity = V, or { below = V }, { above = V }, { within = [LOW, HIGH] } (rpm).
  void velocity_claim(const toml::node& claim, expectation base) {
    const toml::node* n = &claim;
    expectation e = base;
    e.what = expectation::kind::velocity;
    if (const auto* cmp = n->as_table()) {
      if (cmp->size() != 1) {
        refuse(*n, "velocity takes one comparison: { below = V }, { above = V } or "
                   "{ within = [LOW, HIGH] }");
      }
      check_keys(*cmp, {"below", "above", "within"}, "a velocity comparison");
      if (const auto* b = cmp->get("below")) {
        e.how = expectation::compare::below;
        e.low = get_velocity(*b, "below");
      } else if (const auto* ab = cmp->get("above")) {
        e.how = expectation::compare::above;
        e.low = get_velocity(*ab, "above");
      } else {
        const toml::node& w = *cmp->get("within");
        const toml::array& range = get_array(w, "within");
        if (range.size() != 2) refuse(w, "within takes [LOW, HIGH]");
        e.how = expectation::compare::within;
        e.low = get_velocity(*range.get(0), "the low end of within");
        e.high = get_velocity(*range.get(1), "the high end of within");
        if (e.high < e.low) refuse(w, "within [LOW, HIGH] needs LOW <= HIGH");
      }
    } else {
      e.how = expectation::compare::equal;
      e.low = get_velocity(*n, "velocity");
    }
    s.expectations.push_back(e);
  }

  // position = P, or { within = [LOW, HIGH] } (increments).
  void position_claim(const toml::node& claim, expectation base) {
    const toml::node* n = &claim;
    expectation e = base;
    e.what = expectation::kind::position;
    constexpr std::int64_t reach = std::int64_t{1} << 40;
    if (const auto* cmp = n->as_table()) {
      check_keys(*cmp, {"within"}, "a position comparison");
      const toml::node* w = cmp->get("within");
      if (w == nullptr) refuse(*n, "position takes an increment count or { within = [LOW, HIGH] }");
      const toml::array& range = get_array(*w, "within");
      if (range.size() != 2) refuse(*w, "within takes [LOW, HIGH]");
      e.how = expectation::compare::within;
      e.low = get_int(*range.get(0), "the low end of within", -reach, reach);
      e.high = get_int(*range.get(1), "the high end of within", -reach, reach);
      if (e.high < e.low) refuse(*w, "within [LOW, HIGH] needs LOW <= HIGH");
    } else {
      e.how = expectation::compare::equal;
      e.low = get_int(*n, "position", -reach, reach);
    }
    s.expectations.push_back(e);
  }

  void load_expectation(const toml::table& t) {
    check_keys(t,
               {"at", "between", "state", "velocity", "statusword", "torque", "brake",
                "error_code", "transition", "always", "position", "mode"},
               "an expectation");
    expectation base;
    base.line = static_cast<int>(t.source().begin.line);
    base.column = static_cast<int>(t.source().begin.column);
    const toml::node* at = t.get("at");
    const toml::node* between = t.get("between");
    const toml::node* always = t.get("always");
    if (always) {
      load_rule(t, *always, base, at || between);
      return;
    }
    if (at && between) refuse(*between, "give either 'at' or 'between', not both");
    if (!at && !between) {
      refuse(t, "an expectation needs 'at' (a time) or 'between' (two times), or is 'always'");
    }
    if (at) {
      base.first_cycle = base.last_cycle = cycle_of(*at, "'at'");
    } else {
      const toml::array& a = get_array(*between, "'between'");
      if (a.size() != 2) refuse(*between, "'between' takes two times, e.g. [\"1s\", \"1.2s\"]");
      base.first_cycle = cycle_of(*a.get(0), "the first time of 'between'");
      base.last_cycle = cycle_of(*a.get(1), "the second time of 'between'");
      if (base.last_cycle < base.first_cycle) {
        refuse(*between, "'between' must run forwards: the second time is earlier");
      }
      base.window = true;
    }
    const std::size_t before = s.expectations.size();
    if (const auto* n = t.get("state")) {
      expectation e = base;
      e.what = expectation::kind::state;
      const std::string_view name = get_string(*n, "state");
      if (!parse_state(name, e.expected_state) || e.expected_state == state::start) {
        refuse(*n, "unknown state " + toml_reading::quoted(name) + " (e.g. OPERATION_ENABLED)");
      }
      s.expectations.push_back(e);
    }
    if (const auto* n = t.get("velocity")) velocity_claim(*n, base);
    if (const auto* n = t.get("statusword")) {
      expectation e = base;
      e.what = expectation::kind::statusword;
      if (const auto* m = n->as_table()) {
        check_keys(*m, {"mask", "value"}, "a statusword comparison");
        const toml::node* mask = m->get("mask");
        const toml::node* value = m->get("value");
        if (!mask || !value) refuse(*n, "statusword takes { mask = M, value = V }");
        e.high = get_int(*mask, "mask", 0, 0xFFFF);
        e.low = get_int(*value, "value", 0, 0xFFFF);
        if ((e.low & ~e.high) != 0) refuse(*value, "value has bits outside the mask");
      } else {
        e.high = 0xFFFF;
        e.low = get_int(*n, "statusword", 0, 0xFFFF);
      }
      s.expectations.push_back(e);
    }
    if (const auto* n = t.get("torque")) {
      expectation e = base;
      e.what = expectation::kind::torque;
      e.flag = get_bool(*n, "torque");
      s.expectations.push_back(e);
    }
    if (const auto* n = t.get("brake")) {
      expectation e = base;
      e.what = expectation::kind::brake;
      const std::string_view v = get_string(*n, "brake");
      if (v != "engaged" && v != "released") refuse(*n, "brake must be \"engaged\" or \"released\"");
      e.flag = v == "engaged";
      s.expectations.push_back(e);
    }
    if (const auto* n = t.get("position")) position_claim(*n, base);
    if (const auto* n = t.get("mode")) {
      expectation e = base;
      e.what = expectation::kind::mode;
      std::int8_t m = 0;
      const std::string text = n->is_string() ? std::string(get_string(*n, "mode"))
                                              : std::to_string(get_int(*n, "mode", -128, 127));
      if (!mode::parse(text, m)) refuse(*n, "mode must be pp, pv, tq, hm, csp, csv, cst or a number");
      e.low = m;
      s.expectations.push_back(e);
    }
    if (const auto* n = t.get("error_code")) {
      expectation e = base;
      e.what = expectation::kind::error_code;
      e.low = get_int(*n, "error_code", 0, 0xFFFF);
      s.expectations.push_back(e);
    }
    if (const auto* n = t.get("transition")) {
      expectation e = base;
      e.what = expectation::kind::transition;
      e.transition = static_cast<std::uint8_t>(get_int(*n, "transition", 0, 17));
      s.expectations.push_back(e);
    }
    if (s.expectations.size() == before) {
      refuse(t, "an expectation needs a claim: state, velocity, statusword, torque, brake, "
                "error_code or transition");
    }
  }

  template <typename Each>
  void load_list(const toml::node& n, std::string_view what, Each each) {
    const toml::array& list = get_array(n, what);
    for (const toml::node& item : list) each(get_table(item, std::string("each entry of ") + std::string(what)));
  }

  void load(const toml::table& root) {
    check_keys(root,
               {"name", "profile", "profile_file", "cycle", "duration", "plant", "objects",
                "events", "expect"},
               "the scenario");
    if (const auto* n = root.get("name")) s.name = get_string(*n, "name");
    load_profile(root);
    if (const auto* n = root.get("cycle")) {
      const std::uint64_t us = get_time_us(*n, "cycle");
      if (us < 1 || us > 1000000) refuse(*n, "cycle must be 1us .. 1s");
      s.plant.cycle_us = static_cast<std::uint32_t>(us);
    }
    duration_node = root.get("duration");
    if (duration_node == nullptr) {
      refuse(root, "the scenario lacks 'duration', how long it runs (e.g. duration = \"2s\")");
    }
    duration_us = get_time_us(*duration_node, "duration");
    if (duration_us % s.plant.cycle_us != 0) {
      refuse(*duration_node, "duration " + seconds_text(duration_us) +
                                 " is not a multiple of the cycle (" +
                                 seconds_text(s.plant.cycle_us) + ")");
    }
    if (duration_us / s.plant.cycle_us > 100000000ull) {
      refuse(*duration_node, "duration is more than 100 million cycles");
    }
    s.cycles = duration_us / s.plant.cycle_us + 1;
    if (const auto* n = root.get("plant")) scenario_reading::load_plant(get_table(*n, "[plant]"), s);
    if (const auto* n = root.get("objects")) load_objects(get_table(*n, "[objects]"));
    if (const auto* n = root.get("events")) {
      load_list(*n, "events", [&](const toml::table& t) { load_event(t); });
    }
    if (const auto* n = root.get("expect")) {
      load_list(*n, "expect", [&](const toml::table& t) { load_expectation(t); });
    }
    std::stable_sort(s.events.begin(), s.events.end(),
                     [](const scenario_event& a, const scenario_event& b) { return a.cycle < b.cycle; });
  }
};

std::string stem_of(std::string_view source_name) {
  const std::filesystem::path p{std::string(source_name)};
  return p.stem().string();
}

}  // namespace

std::string scenario_error::message() const {
  return support::located_message(source_name, "<scenario>", line, column, reason);
}

const char* invariant_name(invariant i) noexcept {
  switch (i) {
    case invariant::brake_engaged_before_torque_off: return "brake_engaged_before_torque_off";
    case invariant::motion_waits_for_brake_release: return "motion_waits_for_brake_release";
    case invariant::coast_removes_torque_at_once: return "coast_removes_torque_at_once";
  }
  return "unknown";
}

scenario_load_result load_scenario_toml(std::string_view text, std::string_view source_name,
                                        const std::string& base_dir) {
  const std::string name(source_name);
  loader l;
  l.base_dir = base_dir;
  l.s.source_name = name;
  if (const auto bad = toml_reading::parse_and_load(text, name, [&l](const toml::table& root) { l.load(root); })) {
    return scenario_error{bad->line, bad->column, bad->reason, name};
  }
  if (l.s.name.empty()) l.s.name = stem_of(name);
  return std::move(l.s);
}

scenario_load_result load_scenario_file(const std::string& path) {
  std::string why;
  const std::optional<std::string> text = toml_reading::read_small_file(path, why);
  if (!text) return scenario_error{0, 0, why, path};
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  return load_scenario_toml(*text, path, dir.empty() ? std::string(".") : dir.string());
}

}  // namespace cia402::sim
