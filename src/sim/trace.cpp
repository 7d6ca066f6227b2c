// Trace rows and the text formats made from them: CSV, JSON Lines, VCD.
#include "cia402/sim/trace.hpp"

#include <ostream>
#include <string>
#include <utility>

#include "cia402/support/text.hpp"

namespace cia402::sim {
namespace {

using support::hex;

std::string binary(std::uint32_t v, int bits) {
  std::string s;
  for (int i = bits - 1; i >= 0; --i) s += ((v >> i) & 1u) ? '1' : '0';
  return s;
}

// Everything but the velocity: a row that differs here from the one before is always kept.
bool same_but_velocity(const trace_row& a, const trace_row& b) {
  return a.target_velocity == b.target_velocity && a.control_word == b.control_word &&
         a.status_word == b.status_word && a.error_code == b.error_code &&
         a.fault_cause == b.fault_cause && a.current == b.current &&
         b.transition == no_transition && a.ramp == b.ramp && a.torque == b.torque &&
         a.brake_released == b.brake_released && a.brake_engaged == b.brake_engaged &&
         a.dc_link == b.dc_link && a.sto == b.sto && a.mode == b.mode;
}

// Control-word and status-word bits as VCD signal names (cia402-reference.md §1.2, §2.1; bits 12
// and 13 of the status word as profile velocity mode defines them).
constexpr const char* control_bit_names[16] = {
    "0_switch_on",      "1_enable_voltage", "2_quick_stop",     "3_enable_operation",
    "4_mode_specific",  "5_mode_specific",  "6_mode_specific",  "7_fault_reset",
    "8_halt",           "9_mode_specific",  "10_reserved",      "11_manufacturer",
    "12_manufacturer",  "13_manufacturer",  "14_manufacturer",  "15_manufacturer",
};
constexpr const char* status_bit_names[16] = {
    "0_ready_to_switch_on", "1_switched_on",     "2_operation_enabled", "3_fault",
    "4_voltage_enabled",    "5_quick_stop",      "6_switch_on_disabled", "7_warning",
    "8_manufacturer",       "9_remote",          "10_target_reached",   "11_internal_limit",
    "12_speed_zero",        "13_max_slippage",   "14_manufacturer",     "15_manufacturer",
};

// VCD identifiers: printable ASCII from '!' on, more characters when needed.
std::string vcd_id(int n) {
  std::string id;
  do {
    id += static_cast<char>('!' + n % 94);
    n /= 94;
  } while (n > 0);
  return id;
}

std::string without_dollar_end(std::string text) {
  for (std::size_t at; (at = text.find('$')) != std::string::npos;) text[at] = '_';
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

}  // namespace

trace_row begin_row(std::uint64_t time_us, const plant_constants& k, const axis_state& a) noexcept {
  trace_row r;
  r.time_us = time_us;
  r.velocity = a.velocity;
  r.target_velocity = a.target_velocity;
  r.control_word = a.control_word;
  const drive_inputs in = plant_inputs(k, a);
  r.fault_cause = in.fault_code;
  r.brake_engaged = in.brake_engaged;
  r.dc_link = in.dc_link;
  r.sto = in.sto;
  r.position = a.position;
  r.position_demand = a.demand;
  r.torque_permille = a.torque;
  r.mode = a.operation_mode;
  r.digital_inputs = digital_inputs(k, a);
  return r;
}

void complete_row(trace_row& row, const drive_outputs& out) noexcept {
  row.status_word = out.status_word;
  row.error_code = out.error_code;
  row.current = out.current;
  row.transition = out.transition;
  row.ramp = out.ramp;
  row.torque = out.torque;
  row.brake_released = out.brake_released;
}

std::string format_rpm(std::int64_t micro_rpm) {
  const bool negative = micro_rpm < 0;
  // Magnitude as unsigned so that the most negative value formats too.
  const std::uint64_t m = negative ? 0 - static_cast<std::uint64_t>(micro_rpm)
                                   : static_cast<std::uint64_t>(micro_rpm);
  std::string s = (negative ? "-" : "") + std::to_string(m / 1000000);
  std::uint64_t frac = m % 1000000;
  if (frac == 0) return s;
  std::string f = std::to_string(frac);
  f.insert(0, 6 - f.size(), '0');
  while (f.back() == '0') f.pop_back();
  return s + "." + f;
}

std::string format_seconds(std::uint64_t time_us) {
  std::string f = std::to_string(time_us % 1000000);
  f.insert(0, 6 - f.size(), '0');
  return std::to_string(time_us / 1000000) + "." + f;
}

std::vector<std::size_t> kept_rows(const std::vector<trace_row>& rows, std::size_t every) {
  std::vector<std::size_t> keep;
  if (every < 1) every = 1;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (every == 1 || i % every == 0 || i + 1 == rows.size() ||
        (i > 0 && !same_but_velocity(rows[i - 1], rows[i]))) {
      keep.push_back(i);
    }
  }
  return keep;
}

void write_csv(std::ostream& out, const std::vector<trace_row>& rows, std::size_t every) {
  out << "time_us,controlword,statusword,state,transition,velocity_rpm,target_rpm,torque,"
         "brake_released,brake_engaged,ramp,error_code,fault_cause,dc_link,sto,position,position_demand,"
         "torque_permille,mode\n";
  for (std::size_t i : kept_rows(rows, every)) {
    const trace_row& r = rows[i];
    out << r.time_us << ',' << hex(r.control_word, 4) << ',' << hex(r.status_word, 4) << ','
        << state_name(r.current) << ','
        << (r.transition == no_transition ? std::string() : std::to_string(r.transition)) << ','
        << format_rpm(r.velocity) << ',' << r.target_velocity << ',' << int{r.torque} << ','
        << int{r.brake_released} << ',' << int{r.brake_engaged} << ',' << stop_ramp_name(r.ramp)
        << ',' << hex(r.error_code, 4) << ',' << hex(r.fault_cause, 4) << ',' << int{r.dc_link} << ','
        << int{r.sto} << ',' << r.position << ',' << r.position_demand << ',' << r.torque_permille << ','
        << int{r.mode} << '\n';
  }
}

void write_jsonl(std::ostream& out, const std::vector<trace_row>& rows, std::size_t every) {
  auto b = [](bool v) { return v ? "true" : "false"; };
  for (std::size_t i : kept_rows(rows, every)) {
    const trace_row& r = rows[i];
    out << "{\"time_us\":" << r.time_us << ",\"controlword\":\"" << hex(r.control_word, 4)
        << "\",\"statusword\":\"" << hex(r.status_word, 4) << "\",\"state\":\""
        << state_name(r.current) << "\",\"transition\":"
        << (r.transition == no_transition ? std::string("null") : std::to_string(r.transition))
        << ",\"velocity_rpm\":" << format_rpm(r.velocity) << ",\"target_rpm\":"
        << r.target_velocity << ",\"torque\":" << b(r.torque)
        << ",\"brake_released\":" << b(r.brake_released)
        << ",\"brake_engaged\":" << b(r.brake_engaged) << ",\"ramp\":\""
        << stop_ramp_name(r.ramp) << "\",\"error_code\":\"" << hex(r.error_code, 4)
        << "\",\"fault_cause\":\"" << hex(r.fault_cause, 4) << "\",\"dc_link\":" << b(r.dc_link)
        << ",\"sto\":" << b(r.sto) << ",\"position\":" << r.position << ",\"position_demand\":"
        << r.position_demand << ",\"torque_permille\":" << r.torque_permille << ",\"mode\":" << int{r.mode}
        << "}\n";
  }
}

void write_vcd(std::ostream& out, const std::vector<trace_row>& rows, const trace_info& info) {
  // Signals in declaration order; each knows how to print its value from a row.
  enum class type { wire, vector, real, string, integer };
  struct signal {
    std::string scope;
    std::string name;
    type t;
    int width;
    std::string (*value)(const trace_row&, int bit);
    int bit;
    std::uint32_t (*code)(const trace_row&) = nullptr;  // a string's integer code (vcd_standard)
  };
  using value_fn = std::string (*)(const trace_row&, int);
  const value_fn cw_bit = [](const trace_row& r, int bit) {
    return std::string(((r.control_word >> bit) & 1u) ? "1" : "0");
  };
  const value_fn sw_bit = [](const trace_row& r, int bit) {
    return std::string(((r.status_word >> bit) & 1u) ? "1" : "0");
  };
  std::vector<signal> signals = {
      {"", "controlword", type::vector, 16,
       [](const trace_row& r, int) { return binary(r.control_word, 16); }, 0},
      {"", "statusword", type::vector, 16,
       [](const trace_row& r, int) { return binary(r.status_word, 16); }, 0},
      {"", "state", type::string, 1,
       [](const trace_row& r, int) { return std::string(state_name(r.current)); }, 0,
       [](const trace_row& r) { return static_cast<std::uint32_t>(r.current); }},
      {"", "last_transition", type::integer, 8, nullptr, 0},  // filled in below: it is sticky
      {"", "transition_taken", type::wire, 1,
       [](const trace_row& r, int) { return std::string(r.transition != no_transition ? "1" : "0"); },
       0},
      {"", "velocity_rpm", type::real, 64,
       [](const trace_row& r, int) { return format_rpm(r.velocity); }, 0},
      {"", "target_rpm", type::real, 64,
       [](const trace_row& r, int) { return std::to_string(r.target_velocity); }, 0},
      {"", "ramp", type::string, 1,
       [](const trace_row& r, int) { return std::string(stop_ramp_name(r.ramp)); }, 0,
       [](const trace_row& r) { return static_cast<std::uint32_t>(r.ramp); }},
      {"", "torque", type::wire, 1,
       [](const trace_row& r, int) { return std::string(r.torque ? "1" : "0"); }, 0},
      {"", "brake_released", type::wire, 1,
       [](const trace_row& r, int) { return std::string(r.brake_released ? "1" : "0"); }, 0},
      {"", "brake_engaged", type::wire, 1,
       [](const trace_row& r, int) { return std::string(r.brake_engaged ? "1" : "0"); }, 0},
      {"", "dc_link", type::wire, 1,
       [](const trace_row& r, int) { return std::string(r.dc_link ? "1" : "0"); }, 0},
      {"", "sto", type::wire, 1,
       [](const trace_row& r, int) { return std::string(r.sto ? "1" : "0"); }, 0},
      {"", "error_code", type::vector, 16,
       [](const trace_row& r, int) { return binary(r.error_code, 16); }, 0},
      {"", "fault_cause", type::vector, 16,
       [](const trace_row& r, int) { return binary(r.fault_cause, 16); }, 0},
      {"", "position", type::vector, 32,
       [](const trace_row& r, int) { return binary(static_cast<std::uint32_t>(r.position), 32); }, 0},
      {"", "position_demand", type::vector, 32,
       [](const trace_row& r, int) { return binary(static_cast<std::uint32_t>(r.position_demand), 32); }, 0},
      {"", "torque_permille", type::vector, 16,
       [](const trace_row& r, int) { return binary(static_cast<std::uint16_t>(r.torque_permille), 16); }, 0},
      {"", "mode", type::vector, 8,
       [](const trace_row& r, int) { return binary(static_cast<std::uint8_t>(r.mode), 8); }, 0},
  };
  // 0x60FD's inputs, one wire each: what a scope of the machine's switches shows.
  const value_fn input = [](const trace_row& r, int bit) { return std::string((r.digital_inputs >> bit) & 1u ? "1" : "0"); };
  for (const auto& [name, bit] : {std::pair{"negative_limit_switch", 0}, std::pair{"positive_limit_switch", 1},
                                  std::pair{"home_switch", 2}, std::pair{"index_pulse", 16}}) {
    signals.push_back({"", name, type::wire, 1, input, bit});
  }
  for (int b = 0; b < 16; ++b) signals.push_back({"cw", control_bit_names[b], type::wire, 1, cw_bit, b});
  for (int b = 0; b < 16; ++b) signals.push_back({"sw", status_bit_names[b], type::wire, 1, sw_bit, b});
  if (info.vcd_standard) {
    // IEEE 1364 has no string variables: the names become codes, and the header says which.
    for (signal& s : signals) {
      if (s.t != type::string) continue;
      s.t = type::integer;
      s.width = 8;
      s.value = nullptr;
    }
  }

  out << "$comment cia402 simulate: " << without_dollar_end(info.title) << " (profile "
      << without_dollar_end(info.profile_name) << ", cycle " << info.cycle_us << " us) $end\n"
      << "$version cia402 simulator $end\n"
      << "$timescale 1us $end\n";
  if (info.vcd_standard) {
    out << "$comment state codes:";
    for (int i = 0; i < state_count; ++i) out << ' ' << i << '=' << state_name(static_cast<state>(i));
    out << "; ramp codes:";
    for (int i = 0; i <= static_cast<int>(stop_ramp::coast); ++i) {
      out << ' ' << i << '=' << stop_ramp_name(static_cast<stop_ramp>(i));
    }
    out << " $end\n";
  }
  out << "$scope module drive $end\n";
  std::string open_scope;
  for (std::size_t i = 0; i < signals.size(); ++i) {
    const signal& s = signals[i];
    if (s.scope != open_scope) {
      if (!open_scope.empty()) out << "$upscope $end\n";
      if (!s.scope.empty()) out << "$scope module " << s.scope << " $end\n";
      open_scope = s.scope;
    }
    const char* kind = s.t == type::real      ? "real"
                       : s.t == type::string  ? "string"
                       : s.t == type::integer ? "integer"
                                              : "wire";
    out << "$var " << kind << ' ' << s.width << ' ' << vcd_id(static_cast<int>(i)) << ' ' << s.name
        << " $end\n";
  }
  if (!open_scope.empty()) out << "$upscope $end\n";
  out << "$upscope $end\n$enddefinitions $end\n";

  auto format = [&](const signal& s, const std::string& v, std::size_t i) {
    const std::string id = vcd_id(static_cast<int>(i));
    switch (s.t) {
      case type::wire: return v + id;
      case type::vector:
      case type::integer: return "b" + v + " " + id;
      case type::real: return "r" + v + " " + id;
      case type::string: return "s" + v + " " + id;
    }
    return std::string();
  };
  std::vector<std::string> last(signals.size());
  int last_transition = 0;
  bool first = true;
  for (const trace_row& r : rows) {
    if (r.transition != no_transition) last_transition = r.transition;
    std::string changes;
    for (std::size_t i = 0; i < signals.size(); ++i) {
      const signal& s = signals[i];
      const std::string v = s.value  ? s.value(r, s.bit)
                            : s.code ? binary(s.code(r), 8)
                                     : binary(static_cast<std::uint32_t>(last_transition), 8);
      if (first || v != last[i]) {
        changes += format(s, v, i) + "\n";
        last[i] = v;
      }
    }
    if (first) {
      out << "#" << r.time_us << "\n$dumpvars\n" << changes << "$end\n";
      first = false;
    } else if (!changes.empty()) {
      out << "#" << r.time_us << "\n" << changes;
    }
  }
  if (!rows.empty()) out << "#" << rows.back().time_us + info.cycle_us << "\n";
}

}  // namespace cia402::sim
