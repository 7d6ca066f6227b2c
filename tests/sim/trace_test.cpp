// Traces: the same scenario gives the same bytes; CSV, JSON Lines, VCD and SVG carry what they
// claim, read back by independent parsers (nlohmann::json for JSONL, a small VCD reader here).
#include <gtest/gtest.h>

#include <bitset>

#include <algorithm>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "cia402/sim/scenario.hpp"
#include "cia402/sim/trace.hpp"

namespace {

using namespace cia402;
using namespace cia402::sim;

scenario load_example(const std::string& name) {
  scenario_load_result r =
      load_scenario_file(std::string(CIA402_EXAMPLE_SCENARIOS_DIR) + "/" + name);
  if (const auto* e = std::get_if<scenario_error>(&r)) {
    ADD_FAILURE() << e->message();
    return {};
  }
  return std::get<scenario>(std::move(r));
}

struct outputs {
  std::string csv, jsonl, vcd, svg;
};

outputs render(const scenario& s) {
  const run_result r = run_scenario(s);
  trace_info info{s.name, s.drive_profile.get().name, s.plant.cycle_us, s.plant.brake_fitted};
  std::ostringstream csv, jsonl, vcd, svg;
  write_csv(csv, r.trace);
  write_jsonl(jsonl, r.trace);
  write_vcd(vcd, r.trace, info);
  write_svg_plot(svg, r.trace, info);
  return {csv.str(), jsonl.str(), vcd.str(), svg.str()};
}

TEST(determinism, the_same_scenario_twice_gives_identical_bytes_in_every_format) {
  for (const char* name : {"fault-during-quick-stop.toml", "sto-while-moving.toml"}) {
    const scenario s = load_example(name);
    const outputs a = render(s);
    (void)render(load_example("halt-and-resume.toml"));  // another run in between shares nothing
    const outputs b = render(load_example(name));        // loaded afresh
    EXPECT_EQ(a.csv, b.csv) << name;
    EXPECT_EQ(a.jsonl, b.jsonl) << name;
    EXPECT_EQ(a.vcd, b.vcd) << name;
    EXPECT_EQ(a.svg, b.svg) << name;
    EXPECT_GT(a.csv.size(), 10000u);
  }
}

TEST(csv, one_row_per_cycle_under_a_header_and_decimation_keeps_every_change) {
  const scenario s = load_example("quick-stop-2.toml");
  const run_result r = run_scenario(s);
  std::ostringstream full, every50;
  write_csv(full, r.trace);
  write_csv(every50, r.trace, 50);
  std::istringstream in(full.str());
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "time_us,controlword,statusword,state,transition,velocity_rpm,target_rpm,torque,"
            "brake_released,brake_engaged,ramp,error_code,fault_cause,dc_link,sto,position,"
            "position_demand,torque_permille,mode");
  std::size_t rows = 0;
  std::string t11;
  while (std::getline(in, line)) {
    ++rows;
    if (line.find(",QUICK_STOP_ACTIVE,11,") != std::string::npos) t11 = line;
  }
  EXPECT_EQ(rows, s.cycles);
  const std::string first15 = "600000,0x000B,0x0217,QUICK_STOP_ACTIVE,11,1500,1500,1,1,0,quick_stop,0x0000,"
                             "0x0000,1,0,";
  ASSERT_EQ(t11.substr(0, first15.size()), first15);
  // The operation-mode columns: that cycle's position, demand, torque (friction at a steady 1500
  // rpm) and mode 3.
  const trace_row& row = r.trace[600];
  EXPECT_EQ(t11.substr(first15.size()), std::to_string(row.position) + "," + std::to_string(row.position_demand) +
                                            ",20,3");
  EXPECT_GT(row.position, 0);
  const std::string d = every50.str();
  EXPECT_LT(d.size(), full.str().size() / 5);
  for (const char* kept : {"\n0,", "\n21000,", "\n600000,", "\n745000,", "\n1000000,"}) {
    EXPECT_NE(d.find(kept), std::string::npos) << kept;  // transitions, brake changes, the last row
  }
}

TEST(jsonl, every_line_is_a_json_object_with_the_fields_of_the_row) {
  const scenario s = load_example("undervoltage-while-moving.toml");
  const run_result r = run_scenario(s);
  std::ostringstream out;
  write_jsonl(out, r.trace);
  std::istringstream in(out.str());
  std::string line;
  std::size_t i = 0;
  while (std::getline(in, line)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    const trace_row& row = r.trace.at(i++);
    ASSERT_EQ(j.at("time_us").get<std::uint64_t>(), row.time_us);
    EXPECT_EQ(j.at("state").get<std::string>(), state_name(row.current));
    EXPECT_EQ(j.at("torque").get<bool>(), row.torque);
    EXPECT_EQ(j.at("dc_link").get<bool>(), row.dc_link);
    EXPECT_DOUBLE_EQ(j.at("velocity_rpm").get<double>(), static_cast<double>(row.velocity) / 1e6);
    if (row.transition == no_transition) {
      EXPECT_TRUE(j.at("transition").is_null());
    } else {
      EXPECT_EQ(j.at("transition").get<int>(), row.transition);
    }
  }
  EXPECT_EQ(i, r.trace.size());
}

// A small VCD reader: the declared signals by hierarchical name, and each one's value over time.
struct vcd_file {
  std::string timescale;
  std::map<std::string, std::string> type_of;       // "drive.sw.10_target_reached" -> "wire"
  std::map<std::string, std::string> name_of_id;
  std::map<std::string, std::map<std::uint64_t, std::string>> changes;  // name -> time -> value

  std::string value_at(const std::string& name, std::uint64_t t) const {
    const auto& c = changes.at(name);
    auto it = c.upper_bound(t);
    return it == c.begin() ? "" : std::prev(it)->second;
  }
};

vcd_file read_vcd(const std::string& text) {
  vcd_file v;
  std::istringstream in(text);
  std::string word;
  std::vector<std::string> scope;
  std::uint64_t now = 0;
  bool definitions = true;
  std::uint64_t last_time = 0;
  while (in >> word) {
    if (definitions) {
      if (word == "$timescale") {
        in >> v.timescale;
      } else if (word == "$scope") {
        std::string kind, name;
        in >> kind >> name;
        scope.push_back(name);
      } else if (word == "$upscope") {
        scope.pop_back();
      } else if (word == "$var") {
        std::string type, width, id, name;
        in >> type >> width >> id >> name;
        std::string full;
        for (const auto& s : scope) full += s + ".";
        full += name;
        v.type_of[full] = type;
        v.name_of_id[id] = full;
      } else if (word == "$enddefinitions") {
        definitions = false;
      }
      continue;
    }
    if (word == "$dumpvars" || word == "$end") continue;
    if (word[0] == '#') {
      now = std::stoull(word.substr(1));
      EXPECT_GE(now, last_time) << "time goes backwards";
      last_time = now;
    } else if (word[0] == 'b' || word[0] == 'r' || word[0] == 's') {
      std::string id;
      in >> id;
      v.changes[v.name_of_id.at(id)][now] = word.substr(1);
    } else {
      v.changes[v.name_of_id.at(word.substr(1))][now] = word.substr(0, 1);
    }
  }
  return v;
}

TEST(vcd, signals_are_named_per_bit_and_their_values_follow_the_trace) {
  const scenario s = load_example("quick-stop-2.toml");
  const run_result r = run_scenario(s);
  std::ostringstream out;
  write_vcd(out, r.trace, trace_info{s.name, "cia402", 1000, true});
  const vcd_file v = read_vcd(out.str());
  EXPECT_EQ(v.timescale, "1us");
  EXPECT_EQ(v.type_of.at("drive.state"), "string");
  EXPECT_EQ(v.type_of.at("drive.velocity_rpm"), "real");
  EXPECT_EQ(v.type_of.at("drive.torque"), "wire");
  EXPECT_EQ(v.type_of.at("drive.cw.0_switch_on"), "wire");
  EXPECT_EQ(v.type_of.at("drive.cw.8_halt"), "wire");
  EXPECT_EQ(v.type_of.at("drive.sw.10_target_reached"), "wire");
  EXPECT_EQ(v.type_of.at("drive.sw.4_voltage_enabled"), "wire");
  EXPECT_EQ(v.type_of.at("drive.position"), "wire");
  EXPECT_EQ(v.type_of.at("drive.index_pulse"), "wire");
  EXPECT_EQ(v.type_of.size(), 15u + 4u + 4u + 16u + 16u)
      << "15 drive signals, 4 of the operation modes, 4 inputs of 0x60FD, 32 bits";
  bool pulses = false;
  for (const trace_row& row : r.trace) {
    const std::uint64_t t = row.time_us;
    ASSERT_EQ(v.value_at("drive.state", t), state_name(row.current)) << t;
    ASSERT_EQ(v.value_at("drive.index_pulse", t), (row.digital_inputs >> 16) & 1u ? "1" : "0") << t;
    pulses = pulses || (row.digital_inputs >> 16) & 1u;
    ASSERT_EQ(v.value_at("drive.torque", t), row.torque ? "1" : "0") << t;
    ASSERT_EQ(v.value_at("drive.sw.2_operation_enabled", t), (row.status_word & 4) ? "1" : "0") << t;
    ASSERT_EQ(v.value_at("drive.cw.2_quick_stop", t), (row.control_word & 4) ? "1" : "0") << t;
    ASSERT_EQ(v.value_at("drive.velocity_rpm", t), format_rpm(row.velocity)) << t;
    ASSERT_EQ(v.value_at("drive.position", t), std::bitset<32>(static_cast<std::uint32_t>(row.position)).to_string())
        << t;
  }
  EXPECT_TRUE(pulses) << "the shaft turns over index pulses";
  EXPECT_EQ(v.value_at("drive.last_transition", 700000), "00001011");  // T11
  EXPECT_EQ(v.value_at("drive.last_transition", 800000), "00001100");  // T12
}

// The standard form keeps to IEEE 1364: no `$var string` (GTKWave's extension), the state and the
// ramp as integer codes that the header names; every other signal as before.
TEST(vcd, the_standard_form_has_no_string_variables_and_names_its_codes) {
  const scenario s = load_example("quick-stop-2.toml");
  const run_result r = run_scenario(s);
  trace_info info{s.name, "cia402", 1000, true};
  info.vcd_standard = true;
  std::ostringstream out;
  write_vcd(out, r.trace, info);
  EXPECT_EQ(out.str().find("$var string"), std::string::npos);
  EXPECT_NE(out.str().find("5=OPERATION_ENABLED"), std::string::npos) << "the codes are named";
  const vcd_file v = read_vcd(out.str());
  EXPECT_EQ(v.type_of.at("drive.state"), "integer");
  EXPECT_EQ(v.type_of.at("drive.ramp"), "integer");
  EXPECT_EQ(v.type_of.at("drive.position"), "wire");
  EXPECT_EQ(v.type_of.size(), 15u + 4u + 4u + 16u + 16u)
      << "15 drive signals, 4 of the operation modes, 4 inputs of 0x60FD, 32 bits";
  for (const trace_row& row : r.trace) {
    const std::uint64_t t = row.time_us;
    ASSERT_EQ(std::stoul(v.value_at("drive.state", t), nullptr, 2), static_cast<unsigned>(row.current)) << t;
    ASSERT_EQ(std::stoul(v.value_at("drive.ramp", t), nullptr, 2), static_cast<unsigned>(row.ramp)) << t;
    ASSERT_EQ(v.value_at("drive.velocity_rpm", t), format_rpm(row.velocity)) << t;
    ASSERT_EQ(v.value_at("drive.position", t), std::bitset<32>(static_cast<std::uint32_t>(row.position)).to_string())
        << t;
  }
}

TEST(svg, the_plot_names_states_marks_transitions_and_labels_its_axes) {
  const scenario s = load_example("quick-stop-2.toml");
  const run_result r = run_scenario(s);
  std::ostringstream out;
  write_svg_plot(out, r.trace, trace_info{s.name, "cia402", 1000, true});
  const std::string svg = out.str();
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  for (const char* part : {">OPERATION ENABLED<", ">SWITCH ON DISABLED<", ">T11<", ">T12<",
                           "time [s]", "velocity [rpm]", "QSA = QUICK STOP ACTIVE",
                           "id=\"velocity\"", "id=\"target\"", ">torque on<", ">brake open<"}) {
    EXPECT_NE(svg.find(part), std::string::npos) << part;
  }
  // Every opened element is closed: count tags roughly.
  std::size_t opens = 0, closes = 0;
  for (std::size_t at = 0; (at = svg.find("<text", at)) != std::string::npos; ++at) ++opens;
  for (std::size_t at = 0; (at = svg.find("</text>", at)) != std::string::npos; ++at) ++closes;
  EXPECT_EQ(opens, closes);
}

TEST(svg, a_long_trace_is_thinned_to_the_plot_width_without_losing_peaks) {
  std::vector<trace_row> rows(60000);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].time_us = i * 1000;
    rows[i].current = state::operation_enabled;
    rows[i].velocity = (i == 31234) ? 5000 * 1000000LL : 100 * 1000000LL;  // one spike
  }
  std::ostringstream out;
  write_svg_plot(out, rows, trace_info{"long", "cia402", 1000, true});
  const std::string svg = out.str();
  EXPECT_LT(svg.size(), 200000u);
  const std::size_t at = svg.find("id=\"velocity\"");
  ASSERT_NE(at, std::string::npos);
  const std::string line = svg.substr(at, svg.find("/>", at) - at);
  // Few points, and the one-cycle spike is still among them: one point far above the rest.
  std::vector<double> ys;
  for (std::size_t at = line.find(','); at != std::string::npos; at = line.find(',', at + 1)) {
    ys.push_back(std::stod(line.substr(at + 1)));
  }
  EXPECT_LT(ys.size(), 4000u);
  ASSERT_FALSE(ys.empty());
  const double top = *std::min_element(ys.begin(), ys.end());
  const double bottom = *std::max_element(ys.begin(), ys.end());
  EXPECT_GT(bottom - top, 200.0) << "the 5000 rpm spike was lost";
  EXPECT_EQ(std::count(ys.begin(), ys.end(), top), 1);
}

TEST(svg, a_trace_of_another_mode_gets_a_torque_lane_that_keeps_its_extremes) {
  std::vector<trace_row> rows(20000);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].time_us = i * 1000;
    rows[i].current = state::operation_enabled;
    rows[i].mode = 10;  // cyclic synchronous torque
    rows[i].torque_permille = (i == 12345) ? -700 : 250;  // one negative spike
  }
  std::ostringstream out;
  write_svg_plot(out, rows, trace_info{"cst", "cia402", 1000, true});
  const std::string svg = out.str();
  EXPECT_NE(svg.find("height=\"670\""), std::string::npos) << "the lane adds its room";
  const std::size_t at = svg.find("id=\"torque\"");
  ASSERT_NE(at, std::string::npos);
  EXPECT_NE(svg.find(">-700<"), std::string::npos) << "the lowest torque is labelled";
  EXPECT_NE(svg.find(">250<"), std::string::npos) << "the highest torque is labelled";
  const std::string line = svg.substr(at, svg.find("/>", at) - at);
  std::vector<double> ys;
  for (std::size_t c = line.find(','); c != std::string::npos; c = line.find(',', c + 1)) {
    ys.push_back(std::stod(line.substr(c + 1)));
  }
  EXPECT_LT(ys.size(), 4000u) << "thinned to the plot width";
  ASSERT_FALSE(ys.empty());
  const double lowest = *std::max_element(ys.begin(), ys.end());  // SVG y grows downwards
  EXPECT_EQ(std::count(ys.begin(), ys.end(), lowest), 1) << "the one-cycle spike survives thinning";

  for (trace_row& r : rows) r.mode = 3;  // profile velocity only: the plot stays as it was
  std::ostringstream pv;
  write_svg_plot(pv, rows, trace_info{"pv", "cia402", 1000, true});
  EXPECT_EQ(pv.str().find("torque-lane"), std::string::npos);
  EXPECT_NE(pv.str().find("height=\"600\""), std::string::npos);
}

TEST(format, rpm_prints_exact_decimals_and_seconds_six_places) {
  EXPECT_EQ(format_rpm(0), "0");
  EXPECT_EQ(format_rpm(1500000000), "1500");
  EXPECT_EQ(format_rpm(-2500000), "-2.5");
  EXPECT_EQ(format_rpm(125), "0.000125");
  EXPECT_EQ(format_rpm(-1), "-0.000001");
  EXPECT_EQ(format_rpm(std::numeric_limits<std::int64_t>::min()), "-9223372036854.775808");
  EXPECT_EQ(format_seconds(0), "0.000000");
  EXPECT_EQ(format_seconds(1250000), "1.250000");
}

}  // namespace
