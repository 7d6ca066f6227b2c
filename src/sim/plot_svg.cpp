// The SVG plot of a trace, written by hand as text: velocity over time on coloured, labelled state
// bands, a numbered mark at every transition, torque and brake lanes, axes, legend. Readable without
// colour: each band carries its state's name (or abbreviation) where it is wide enough.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "cia402/sim/trace.hpp"
#include "cia402/support/text.hpp"

namespace cia402::sim {
namespace {

// Layout, in SVG pixels.
constexpr double width = 1000;
constexpr double left = 84;
constexpr double right = 970;
constexpr double plot_top = 96;
constexpr double plot_bottom = 376;
// The lanes, the time axis and the legend below the plot; a trace of the operation modes gets the
// torque 0x6077 lane between the plot and them, which moves them down by `torque_lane_room`.
constexpr double torque_on_top_pv = 390;
constexpr double brake_top_pv = 410;
constexpr double inputs_top_pv = 430;
constexpr double lane_height = 14;
constexpr double axis_y_pv = 452;
constexpr double legend_top_pv = 508;
constexpr double torque_lane_top = 392;
constexpr double torque_lane_height = 56;
constexpr double torque_lane_room = 70;
constexpr double char_width = 7.4;  // a generous width of one upper-case character at 11 px

struct state_style {
  const char* fill;
  const char* abbreviation;
  const char* label;
};

// Index by state. Light fills from a colour-blind-safe palette; the darker the further from normal
// operation.
constexpr state_style styles[state_count] = {
    {"#eeeeee", "START", "START"},
    {"#e3e3e3", "NRTSO", "NOT READY TO SWITCH ON"},
    {"#d4e6f6", "SOD", "SWITCH ON DISABLED"},
    {"#a9cde8", "RTSO", "READY TO SWITCH ON"},
    {"#f6e39a", "SO", "SWITCHED ON"},
    {"#b2e3c0", "OE", "OPERATION ENABLED"},
    {"#f7bb6b", "QSA", "QUICK STOP ACTIVE"},
    {"#f19c94", "FRA", "FAULT REACTION ACTIVE"},
    {"#d9706a", "FAULT", "FAULT"},
};

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  std::string s = buf;
  if (s == "-0.0") s = "0.0";
  if (s.size() > 2 && s.compare(s.size() - 2, 2, ".0") == 0) s.resize(s.size() - 2);
  return s;
}

// A "nice" tick step (1, 2 or 5 x 10^k) giving about `target` intervals over span.
double nice_step(double span, int target) {
  if (span <= 0) return 1;
  const double raw = span / target;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  const double m = raw / power;
  const double nice = m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10;
  return nice * power;
}

int decimals_for(double step) {
  int d = 0;
  while (d < 6 && std::fabs(step * std::pow(10.0, d) - std::round(step * std::pow(10.0, d))) > 1e-9) ++d;
  return d;
}

std::string fixed(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s.size() > 1 && s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

struct scale {
  double t0 = 0;
  double t1 = 1;
  double v0 = 0;
  double v1 = 1;
  double vstep = 1;  // the velocity axis's tick step
  double x(double t_us) const { return left + (t_us - t0) / (t1 - t0) * (right - left); }
  double y(double rpm) const {
    return plot_bottom - (rpm - v0) / (v1 - v0) * (plot_bottom - plot_top);
  }
};

// Per pixel column, the first, lowest, highest and last sample in time order, each once: a line
// drawn through them keeps every peak of a trace far longer than the plot is wide.
template <typename Value, typename Point>
void each_column_extremes(const std::vector<trace_row>& rows, const scale& s, Value value, Point point) {
  auto column_of = [&](const trace_row& r) { return std::lround(std::floor(s.x(static_cast<double>(r.time_us)))); };
  for (std::size_t i = 0; i < rows.size();) {
    const long column = column_of(rows[i]);
    std::size_t j = i, lo = i, hi = i;
    while (j < rows.size() && column_of(rows[j]) == column) {
      if (value(rows[j]) < value(rows[lo])) lo = j;
      if (value(rows[j]) > value(rows[hi])) hi = j;
      ++j;
    }
    std::vector<std::size_t> picks = {i, lo, hi, j - 1};
    std::sort(picks.begin(), picks.end());
    picks.erase(std::unique(picks.begin(), picks.end()), picks.end());
    for (std::size_t k : picks) point(rows[k]);
    i = j;
  }
}

double rpm(std::int64_t micro) { return static_cast<double>(micro) / 1e6; }


// Where the lanes, the time axis and the legend sit: a trace of the operation modes moves them down
// to make room for the torque lane.
struct layout {
  double height, torque_top, brake_top, inputs_top, axis_y, legend_top;
};

layout layout_for(bool positions) {
  const double shift = positions ? torque_lane_room : 0;
  return {600 + shift,         torque_on_top_pv + shift, brake_top_pv + shift,
          inputs_top_pv + shift, axis_y_pv + shift,      legend_top_pv + shift};
}

void write_header(std::ostream& out, const trace_info& info, const layout& at, bool positions) {
  const double height = at.height;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(width) << "\" height=\""
      << num(height) << "\" viewBox=\"0 0 " << num(width) << " " << num(height)
      << "\" font-family=\"DejaVu Sans, Arial, sans-serif\" font-size=\"11\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  out << "<text x=\"" << num(left) << "\" y=\"24\" font-size=\"15\" font-weight=\"bold\">"
      << support::xml_escaped(info.title) << "</text>\n";
  out << "<text x=\"" << num(left) << "\" y=\"42\" fill=\"#444\">profile " << support::xml_escaped(info.profile_name)
      << ", cycle " << info.cycle_us << " us; velocity 0x606C (solid), target 0x60FF (dashed); "
      << (positions ? "position 0x6064 (magenta, right scale); torque 0x6077 below; " : "")
      << "bands: state; marks: transitions</text>\n";
}

// The time and velocity scales of the plot, from every row.
scale scale_for(const std::vector<trace_row>& rows, const trace_info& info) {
  scale s;
  s.t0 = static_cast<double>(rows.front().time_us);
  s.t1 = static_cast<double>(rows.back().time_us + info.cycle_us);
  double vmin = 0;
  double vmax = 0;
  for (const trace_row& r : rows) {
    vmin = std::min({vmin, rpm(r.velocity), static_cast<double>(r.target_velocity)});
    vmax = std::max({vmax, rpm(r.velocity), static_cast<double>(r.target_velocity)});
  }
  if (vmax - vmin < 1) vmax = vmin + 1;
  const double vstep = nice_step(vmax - vmin, 6);
  s.vstep = vstep;
  s.v0 = std::floor(vmin / vstep) * vstep;
  s.v1 = std::ceil(vmax / vstep) * vstep;
  if (s.v1 - vmax < vstep * 0.1) s.v1 += vstep * 0.5;  // room for the band labels
  if (vmin - s.v0 < vstep * 0.05 && s.v0 < 0) s.v0 -= vstep * 0.25;
  return s;
}

// State bands, each labelled where it is wide enough; which states occur, for the legend.
std::vector<bool> write_state_bands(std::ostream& out, const std::vector<trace_row>& rows, const scale& s) {
  out << "<g id=\"state-bands\">\n";
  std::vector<bool> present(state_count, false);
  for (std::size_t i = 0; i < rows.size();) {
    std::size_t j = i;
    while (j < rows.size() && rows[j].current == rows[i].current) ++j;
    const double xa = s.x(static_cast<double>(rows[i].time_us));
    const double xb = j < rows.size() ? s.x(static_cast<double>(rows[j].time_us)) : right;
    const state_style& st = styles[static_cast<int>(rows[i].current)];
    present[static_cast<std::size_t>(rows[i].current)] = true;
    out << "<rect x=\"" << num(xa) << "\" y=\"" << num(plot_top) << "\" width=\""
        << num(std::max(xb - xa, 0.5)) << "\" height=\"" << num(plot_bottom - plot_top)
        << "\" fill=\"" << st.fill << "\"><title>" << st.label << "</title></rect>\n";
    const std::string full = st.label;
    const double room = xb - xa - 6;
    std::string label;
    if (room >= static_cast<double>(full.size()) * char_width) {
      label = full;
    } else if (room >= static_cast<double>(std::string(st.abbreviation).size()) * char_width) {
      label = st.abbreviation;
    }
    if (!label.empty()) {
      out << "<text x=\"" << num((xa + xb) / 2) << "\" y=\"" << num(plot_top + 15)
          << "\" text-anchor=\"middle\" fill=\"#222\" stroke=\"#ffffff\" stroke-width=\"3\" "
             "paint-order=\"stroke\">"
          << label << "</text>\n";
    }
    i = j;
  }
  out << "</g>\n";
  return present;
}

void write_axes(std::ostream& out, const scale& s, const layout& at) {
  const double vstep = s.vstep;
  const double inputs_top = at.inputs_top;
  const double axis_y = at.axis_y;
  out << "<g id=\"axes\" stroke=\"#000\" fill=\"none\">\n";
  const int vdec = decimals_for(vstep);
  for (double v = s.v0; v <= s.v1 + vstep * 1e-6; v += vstep) {
    const double y = s.y(v);
    out << "<line x1=\"" << num(left) << "\" y1=\"" << num(y) << "\" x2=\"" << num(right)
        << "\" y2=\"" << num(y) << "\" stroke=\"" << (std::fabs(v) < vstep * 1e-6 ? "#555" : "#bbb")
        << "\" stroke-width=\"" << (std::fabs(v) < vstep * 1e-6 ? "1" : "0.5") << "\"/>\n";
    out << "<line x1=\"" << num(left - 5) << "\" y1=\"" << num(y) << "\" x2=\"" << num(left)
        << "\" y2=\"" << num(y) << "\"/>\n";
    out << "<text x=\"" << num(left - 8) << "\" y=\"" << num(y + 4)
        << "\" text-anchor=\"end\" stroke=\"none\" fill=\"#000\">" << fixed(v, vdec) << "</text>\n";
  }
  const double span_s = (s.t1 - s.t0) / 1e6;
  const double tstep = nice_step(span_s, 10);
  const int tdec = decimals_for(tstep);
  for (double t = std::ceil(s.t0 / 1e6 / tstep) * tstep; t <= s.t1 / 1e6 + tstep * 1e-6; t += tstep) {
    const double x = s.x(t * 1e6);
    if (x > right + 0.5) break;
    out << "<line x1=\"" << num(x) << "\" y1=\"" << num(plot_top) << "\" x2=\"" << num(x)
        << "\" y2=\"" << num(plot_bottom) << "\" stroke=\"#bbb\" stroke-width=\"0.5\"/>\n";
    out << "<line x1=\"" << num(x) << "\" y1=\"" << num(inputs_top + lane_height + 2) << "\" x2=\""
        << num(x) << "\" y2=\"" << num(axis_y + 5) << "\"/>\n";
    out << "<text x=\"" << num(x) << "\" y=\"" << num(axis_y + 18)
        << "\" text-anchor=\"middle\" stroke=\"none\" fill=\"#000\">" << fixed(t, tdec)
        << "</text>\n";
  }
  out << "<rect x=\"" << num(left) << "\" y=\"" << num(plot_top) << "\" width=\""
      << num(right - left) << "\" height=\"" << num(plot_bottom - plot_top) << "\"/>\n";
  out << "<line x1=\"" << num(left) << "\" y1=\"" << num(axis_y) << "\" x2=\"" << num(right)
      << "\" y2=\"" << num(axis_y) << "\"/>\n";
  out << "</g>\n";
  out << "<text x=\"" << num((left + right) / 2) << "\" y=\"" << num(axis_y + 36)
      << "\" text-anchor=\"middle\">time [s]</text>\n";
  out << "<text transform=\"translate(22," << num((plot_top + plot_bottom) / 2)
      << ") rotate(-90)\" text-anchor=\"middle\">velocity [rpm]</text>\n";
}

// Target velocity (a dashed step line) and the velocity.
void write_velocities(std::ostream& out, const std::vector<trace_row>& rows, const scale& s) {
  // Target velocity: a dashed step line through its changes.
  out << "<polyline id=\"target\" fill=\"none\" stroke=\"#555\" stroke-width=\"1.2\" "
         "stroke-dasharray=\"6 4\" points=\"";
  {
    std::int32_t last = rows.front().target_velocity;
    out << num(s.x(s.t0)) << "," << num(s.y(last));
    for (const trace_row& r : rows) {
      if (r.target_velocity != last) {
        const double x = s.x(static_cast<double>(r.time_us));
        out << " " << num(x) << "," << num(s.y(last)) << " " << num(x) << ","
            << num(s.y(r.target_velocity));
        last = r.target_velocity;
      }
    }
    out << " " << num(s.x(s.t1)) << "," << num(s.y(last));
  }
  out << "\"/>\n";

  // Velocity: every sample when they are few, else per pixel column the first, lowest, highest
  // and last sample in time order, so no peak is lost.
  out << "<polyline id=\"velocity\" fill=\"none\" stroke=\"#0b3d91\" stroke-width=\"1.8\" "
         "stroke-linejoin=\"round\" points=\"";
  {
    const double columns = right - left;
    bool first = true;
    auto point = [&](const trace_row& r) {
      out << (first ? "" : " ") << num(s.x(static_cast<double>(r.time_us))) << ","
          << num(s.y(rpm(r.velocity)));
      first = false;
    };
    if (static_cast<double>(rows.size()) <= columns * 2) {
      for (const trace_row& r : rows) point(r);
    } else {
      each_column_extremes(rows, s, [](const trace_row& r) { return r.velocity; }, point);
    }
  }
  out << "\"/>\n";
}

// Position 0x6064 on a scale of its own (labels at the right edge, in its colour), when the trace
// ran a mode other than profile velocity: a pv plot stays as it was.
void write_position(std::ostream& out, const std::vector<trace_row>& rows, const scale& s) {
  double pmin = static_cast<double>(rows.front().position);
  double pmax = pmin;
  for (const trace_row& r : rows) {
    pmin = std::min(pmin, static_cast<double>(r.position));
    pmax = std::max(pmax, static_cast<double>(r.position));
  }
  if (pmax - pmin < 1) pmax = pmin + 1;
  const double pstep = nice_step(pmax - pmin, 5);
  const double p0 = std::floor(pmin / pstep) * pstep;
  const double p1 = std::ceil(pmax / pstep) * pstep;
  const auto yp = [&](double p) { return plot_bottom - (p - p0) / (p1 - p0) * (plot_bottom - plot_top); };
  out << "<g id=\"position-axis\" fill=\"#b5179e\">\n";
  for (double p = p0; p <= p1 + pstep * 1e-6; p += pstep) {
    out << "<text x=\"" << num(right - 4) << "\" y=\"" << num(yp(p) - 3) << "\" text-anchor=\"end\">"
        << fixed(p, 0) << "</text>\n";
  }
  out << "<text transform=\"translate(" << num(width - 8) << "," << num((plot_top + plot_bottom) / 2)
      << ") rotate(90)\" text-anchor=\"middle\">position 0x6064 [increments]</text>\n</g>\n";
  // One point a pixel column at most: the position is smooth.
  out << "<polyline id=\"position\" fill=\"none\" stroke=\"#b5179e\" stroke-width=\"1.6\" "
         "stroke-linejoin=\"round\" points=\"";
  const std::size_t every = std::max<std::size_t>(1, rows.size() / 900);
  for (std::size_t i = 0; i < rows.size(); i += every) {
    out << (i ? " " : "") << num(s.x(static_cast<double>(rows[i].time_us))) << ","
        << num(yp(static_cast<double>(rows[i].position)));
  }
  out << " " << num(s.x(static_cast<double>(rows.back().time_us))) << ","
      << num(yp(static_cast<double>(rows.back().position)));
  out << "\"/>\n";
}

// Transitions: a dashed line and a triangle at the cycle they happen; numbers above the plot,
// grouped when they are closer than a label's width and staggered over three rows.
void write_transitions(std::ostream& out, const std::vector<trace_row>& rows, const scale& s) {
  struct mark {
    double x;
    std::string label;
  };
  std::vector<mark> groups;
  out << "<g id=\"transitions\">\n";
  for (const trace_row& r : rows) {
    if (r.transition == no_transition) continue;
    const double x = s.x(static_cast<double>(r.time_us));
    const std::string name = "T" + std::to_string(r.transition);
    out << "<line x1=\"" << num(x) << "\" y1=\"" << num(plot_top) << "\" x2=\"" << num(x)
        << "\" y2=\"" << num(plot_bottom) << "\" stroke=\"#333\" stroke-width=\"0.8\" "
        << "stroke-dasharray=\"2 2\"><title>" << name << " at " << format_seconds(r.time_us)
        << " s</title></line>\n";
    out << "<path d=\"M" << num(x - 4) << "," << num(plot_top - 7) << " L" << num(x + 4) << ","
        << num(plot_top - 7) << " L" << num(x) << "," << num(plot_top) << " Z\" fill=\"#333\"/>\n";
    if (!groups.empty() &&
        x - groups.back().x < static_cast<double>(groups.back().label.size()) * 6.5 + 2) {
      groups.back().label += " " + name;
    } else {
      groups.push_back({x, name});
    }
  }
  double row_end[3] = {-1e9, -1e9, -1e9};
  for (const mark& g : groups) {
    const double w = static_cast<double>(g.label.size()) * 6.5;
    int row = 0;
    while (row < 2 && g.x - w / 2 < row_end[row] + 4) ++row;
    const double x = std::clamp(g.x, left + w / 2, right - w / 2);
    out << "<text x=\"" << num(x) << "\" y=\"" << num(plot_top - 12 - row * 13)
        << "\" text-anchor=\"middle\" font-weight=\"bold\" fill=\"#222\">" << g.label
        << "</text>\n";
    row_end[row] = x + w / 2;
  }
  out << "</g>\n";
}

// Torque 0x6077 (permille of rated torque) in a lane of its own, zero line and its extremes
// labelled; per pixel column the first, lowest, highest and last sample, so no step is lost.
void write_torque_lane(std::ostream& out, const std::vector<trace_row>& rows, const scale& s) {
  double tmin = 0;
  double tmax = 0;
  for (const trace_row& r : rows) {
    tmin = std::min(tmin, static_cast<double>(r.torque_permille));
    tmax = std::max(tmax, static_cast<double>(r.torque_permille));
  }
  if (tmax - tmin < 1) tmax = tmin + 1;
  const double lane_bottom = torque_lane_top + torque_lane_height;
  const auto yt = [&](double t) {
    return lane_bottom - 3 - (t - tmin) / (tmax - tmin) * (torque_lane_height - 6);
  };
  out << "<g id=\"torque-lane\">\n";
  out << "<rect x=\"" << num(left) << "\" y=\"" << num(torque_lane_top) << "\" width=\""
      << num(right - left) << "\" height=\"" << num(torque_lane_height)
      << "\" fill=\"#fbfbfb\" stroke=\"#999\" stroke-width=\"0.5\"/>\n";
  out << "<line x1=\"" << num(left) << "\" y1=\"" << num(yt(0)) << "\" x2=\"" << num(right)
      << "\" y2=\"" << num(yt(0)) << "\" stroke=\"#bbb\" stroke-width=\"0.5\"/>\n";
  out << "<text x=\"" << num(left - 8) << "\" y=\"" << num(torque_lane_top + 11)
      << "\" text-anchor=\"end\">torque 0x6077</text>\n";
  out << "<text x=\"" << num(left - 8) << "\" y=\"" << num(torque_lane_top + 24)
      << "\" text-anchor=\"end\" font-size=\"10\" fill=\"#444\">[permille]</text>\n";
  for (const double t : {tmin, 0.0, tmax}) {
    if (t != 0.0 && std::fabs(t) < 1) continue;
    if (t == 0.0 && (tmin == 0.0 || tmax == 0.0)) continue;  // labelled as an extreme
    out << "<text x=\"" << num(right - 4) << "\" y=\"" << num(yt(t) + 4)
        << "\" text-anchor=\"end\" font-size=\"10\" fill=\"#2a7f62\">" << fixed(t, 0) << "</text>\n";
  }
  out << "<polyline id=\"torque\" fill=\"none\" stroke=\"#2a7f62\" stroke-width=\"1.4\" "
         "stroke-linejoin=\"round\" points=\"";
  bool first = true;
  auto point = [&](const trace_row& r) {
    out << (first ? "" : " ") << num(s.x(static_cast<double>(r.time_us))) << ","
        << num(yt(static_cast<double>(r.torque_permille)));
    first = false;
  };
  each_column_extremes(rows, s, [](const trace_row& r) { return r.torque_permille; }, point);
  out << "\"/>\n</g>\n";
}

// A lane's label at its left and its grey background.
void write_lane_frame(std::ostream& out, double top, const char* label) {
  out << "<text x=\"" << num(left - 8) << "\" y=\"" << num(top + 11) << "\" text-anchor=\"end\">" << label
      << "</text>\n";
  out << "<rect x=\"" << num(left) << "\" y=\"" << num(top) << "\" width=\"" << num(right - left)
      << "\" height=\"" << num(lane_height) << "\" fill=\"#f4f4f4\" stroke=\"#999\" stroke-width=\"0.5\"/>\n";
}

// Lanes: torque on; brake released (solid) and changing over (light); inputs from outside.
void write_lanes(std::ostream& out, const std::vector<trace_row>& rows, const scale& s,
                 const trace_info& info, const layout& places) {
  const double torque_top = places.torque_top;
  const double brake_top = places.brake_top;
  const double inputs_top = places.inputs_top;
  out << "<g id=\"lanes\">\n";
  write_lane_frame(out, torque_top, "torque on");
  write_lane_frame(out, brake_top, "brake open");
  auto lane = [&](double top, auto level, const char* fill) {
    for (std::size_t i = 0; i < rows.size();) {
      const int v = level(rows[i]);
      std::size_t j = i;
      while (j < rows.size() && level(rows[j]) == v) ++j;
      if (v != 0) {
        const double xa = s.x(static_cast<double>(rows[i].time_us));
        const double xb = j < rows.size() ? s.x(static_cast<double>(rows[j].time_us)) : right;
        out << "<rect x=\"" << num(xa) << "\" y=\"" << num(top + 1) << "\" width=\""
            << num(std::max(xb - xa, 0.5)) << "\" height=\"" << num(lane_height - 2) << "\" fill=\""
            << (v == 2 ? "#b8b8b8" : fill) << "\"/>\n";
      }
      i = j;
    }
  };
  lane(torque_top, [](const trace_row& r) { return r.torque ? 1 : 0; }, "#333333");
  if (info.brake_fitted) {
    // 1: open; 2: commanded one way, still the other (the engage or release delay).
    lane(brake_top,
         [](const trace_row& r) {
           if (!r.brake_engaged) return r.brake_released ? 1 : 2;
           return r.brake_released ? 2 : 0;
         },
         "#6a6a6a");
  } else {
    out << "<text x=\"" << num(left + 6) << "\" y=\"" << num(brake_top + 11)
        << "\" fill=\"#666\">no brake fitted</text>\n";
  }
  // Inputs from outside: STO, DC link lost, a fault cause; labelled where there is room.
  write_lane_frame(out, inputs_top, "inputs");
  auto input_text = [](const trace_row& r) {
    std::string t;
    if (r.sto) t += "STO";
    if (!r.dc_link) t += std::string(t.empty() ? "" : ", ") + "no DC link";
    if (r.fault_cause != 0) {
      static constexpr char d[] = "0123456789ABCDEF";
      std::string code = "0x";
      for (int i = 3; i >= 0; --i) code += d[(r.fault_cause >> (4 * i)) & 0xFu];
      t += std::string(t.empty() ? "" : ", ") + "fault " + code;
    }
    return t;
  };
  for (std::size_t i = 0; i < rows.size();) {
    const std::string text = input_text(rows[i]);
    std::size_t j = i;
    while (j < rows.size() && input_text(rows[j]) == text) ++j;
    if (!text.empty()) {
      const double xa = s.x(static_cast<double>(rows[i].time_us));
      const double xb = j < rows.size() ? s.x(static_cast<double>(rows[j].time_us)) : right;
      out << "<rect x=\"" << num(xa) << "\" y=\"" << num(inputs_top + 1) << "\" width=\""
          << num(std::max(xb - xa, 0.5)) << "\" height=\"" << num(lane_height - 2)
          << "\" fill=\"#e8a09a\" stroke=\"#ffffff\" stroke-width=\"0.8\"><title>" << text
          << "</title></rect>\n";
      // The whole text where it fits, else without the word "fault".
      std::string shown = text;
      if (xb - xa - 6 < static_cast<double>(shown.size()) * 6.2) {
        for (std::size_t at; (at = shown.find("fault ")) != std::string::npos;) shown.erase(at, 6);
      }
      if (xb - xa - 6 >= static_cast<double>(shown.size()) * 6.2) {
        out << "<text x=\"" << num(xa + 4) << "\" y=\"" << num(inputs_top + 11)
            << "\" font-size=\"10\" fill=\"#222\">" << shown << "</text>\n";
      }
    }
    i = j;
  }
  out << "</g>\n";
}

// Legend: the states that occur, then the lines and lanes.
void write_legend(std::ostream& out, const std::vector<bool>& present, const layout& at, bool positions) {
  const double legend_top = at.legend_top;
  out << "<g id=\"legend\">\n";
  double x = left;
  double y = legend_top;
  for (int i = 0; i < state_count; ++i) {
    if (!present[static_cast<std::size_t>(i)]) continue;
    const state_style& st = styles[i];
    const std::string text = std::string(st.abbreviation) == st.label
                                 ? std::string(st.label)
                                 : std::string(st.abbreviation) + " = " + st.label;
    const double w = 22 + static_cast<double>(text.size()) * 6.4 + 16;
    if (x + w > right) {
      x = left;
      y += 20;
    }
    out << "<rect x=\"" << num(x) << "\" y=\"" << num(y - 10) << "\" width=\"16\" height=\"12\" fill=\""
        << st.fill << "\" stroke=\"#666\" stroke-width=\"0.5\"/>\n";
    out << "<text x=\"" << num(x + 22) << "\" y=\"" << num(y) << "\">" << text << "</text>\n";
    x += w;
  }
  y += 22;
  x = left;
  out << "<line x1=\"" << num(x) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(x + 24)
      << "\" y2=\"" << num(y - 4) << "\" stroke=\"#0b3d91\" stroke-width=\"1.8\"/>\n"
      << "<text x=\"" << num(x + 30) << "\" y=\"" << num(y) << "\">velocity 0x606C</text>\n";
  x += 150;
  out << "<line x1=\"" << num(x) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(x + 24)
      << "\" y2=\"" << num(y - 4)
      << "\" stroke=\"#555\" stroke-width=\"1.2\" stroke-dasharray=\"6 4\"/>\n"
      << "<text x=\"" << num(x + 30) << "\" y=\"" << num(y) << "\">target 0x60FF</text>\n";
  x += 140;
  out << "<path d=\"M" << num(x + 8) << "," << num(y - 11) << " L" << num(x + 16) << ","
      << num(y - 11) << " L" << num(x + 12) << "," << num(y - 4) << " Z\" fill=\"#333\"/>\n"
      << "<text x=\"" << num(x + 30) << "\" y=\"" << num(y) << "\">Tn = transition n</text>\n";
  x += 150;
  out << "<rect x=\"" << num(x) << "\" y=\"" << num(y - 10) << "\" width=\"24\" height=\"12\" "
      << "fill=\"#b8b8b8\"/>\n"
      << "<text x=\"" << num(x + 30) << "\" y=\"" << num(y)
      << "\">brake engaging / releasing (its delay)</text>\n";
  y += 20;
  if (positions) {
    out << "<line x1=\"" << num(left) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(left + 24)
        << "\" y2=\"" << num(y - 4) << "\" stroke=\"#b5179e\" stroke-width=\"1.6\"/>\n"
        << "<text x=\"" << num(left + 30) << "\" y=\"" << num(y) << "\">position 0x6064 (right scale)</text>\n";
    out << "<line x1=\"" << num(left + 290) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(left + 314)
        << "\" y2=\"" << num(y - 4) << "\" stroke=\"#2a7f62\" stroke-width=\"1.4\"/>\n"
        << "<text x=\"" << num(left + 320) << "\" y=\"" << num(y)
        << "\">torque 0x6077 (permille of rated torque)</text>\n";
    y += 20;
  }
  out << "<rect x=\"" << num(left) << "\" y=\"" << num(y - 10) << "\" width=\"24\" height=\"12\" "
      << "fill=\"#e8a09a\"/>\n"
      << "<text x=\"" << num(left + 30) << "\" y=\"" << num(y)
      << "\">inputs: STO active, DC-link voltage lost, an injected fault cause (its error code)</text>\n";
  out << "</g>\n</svg>\n";
}

}  // namespace

void write_svg_plot(std::ostream& out, const std::vector<trace_row>& rows, const trace_info& info) {
  // A trace that ran a mode other than profile velocity gets the position 0x6064 (on its own scale
  // in the plot) and a torque 0x6077 lane; a pv-only trace's plot stays as it was.
  const bool positions =
      std::any_of(rows.begin(), rows.end(), [](const trace_row& r) { return r.mode != 3; });
  const layout at = layout_for(positions);
  write_header(out, info, at, positions);
  if (rows.empty()) {
    out << "<text x=\"" << num(left) << "\" y=\"120\">(empty trace)</text>\n</svg>\n";
    return;
  }
  const scale s = scale_for(rows, info);
  const std::vector<bool> present = write_state_bands(out, rows, s);
  write_axes(out, s, at);
  write_velocities(out, rows, s);
  if (positions) write_position(out, rows, s);
  write_transitions(out, rows, s);
  if (positions) write_torque_lane(out, rows, s);
  write_lanes(out, rows, s, info, at);
  write_legend(out, present, at, positions);
}

}  // namespace cia402::sim
