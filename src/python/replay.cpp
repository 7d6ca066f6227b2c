// cia402.Replay and Drive.replay: the replay interface (cia402/replay.hpp), the one `cia402 replay`
// runs, with its JSON lines handed to Python as dicts.
#include <pybind11/stl.h>

#include <map>
#include <optional>
#include <string>

#include "binding.hpp"
#include "cia402/replay.hpp"

namespace cia402::python {
namespace {

py::object parse_json(const std::string& line) {
  return py::module_::import("json").attr("loads")(line);
}

/// A replay in progress: powered up when made, as `cia402 replay` prints its power-up line first.
class replay_core {
 public:
  replay_core(profile_ptr p, const std::map<int, std::int64_t>& options)
      : profile_(std::move(p)), session_(profile_->get()) {
    for (const auto& [index, value] : options) {
      const auto i = static_cast<std::uint16_t>(checked_integer(index, 0, 0xFFFF, "index"));
      const sdo_abort r = value < INT32_MIN || value > INT32_MAX
                              ? (value < 0 ? sdo_abort::value_too_low : sdo_abort::value_too_high)
                              : session_.write(i, static_cast<std::int32_t>(value));
      check_access(r, i, 0, "writing");
    }
    power_up_ = session_.power_up();
  }
  replay_core(profile_ptr p, const axis& options) : profile_(std::move(p)), session_(profile_->get()) {
    for (int i = 0; i < option_count; ++i) {
      const auto o = static_cast<option>(i);
      if (profile_->get().spec(o).exists()) session_.write(option_index(o), options.options[i]);
    }
    power_up_ = session_.power_up();
  }

  const std::string& power_up_line() const noexcept { return power_up_; }

  /// One line: "" for a blank or comment line, else the JSON line replay prints.
  std::string feed(const std::string& line) {
    if (line.find('\n') != std::string::npos) raise_argument_error("feed() takes one line (no '\\n')");
    std::string text = line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    return session_.feed(text, ++line_number_);
  }

  py::list run(const py::object& lines) {
    py::list out;
    const auto each = [&](const std::string& line) {
      const std::string result = feed(line);
      if (!result.empty()) out.append(parse_json(result));
    };
    if (py::isinstance<py::str>(lines)) {
      const std::string text = lines.cast<std::string>();
      std::size_t start = 0;
      while (start < text.size()) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        each(text.substr(start, end - start));
        start = end + 1;
      }
    } else {
      for (const py::handle line : py::iter(lines)) {
        if (!py::isinstance<py::str>(line)) raise_argument_error("replay lines are str");
        each(line.cast<std::string>());
      }
    }
    return out;
  }

  int line_number() const noexcept { return line_number_; }
  const replay_session& session() const noexcept { return session_; }

 private:
  profile_ptr profile_;
  replay_session session_;
  std::string power_up_;
  int line_number_ = 0;
};

}  // namespace

py::list replay_dicts(const profile_ptr& p, const axis& options, const py::object& lines) {
  replay_core r(p, options);
  py::list out;
  out.append(parse_json(r.power_up_line()));
  for (const py::handle each : r.run(lines)) out.append(each);
  return out;
}

void bind_replay(py::module_& m) {
  py::class_<replay_core>(m, "Replay", R"doc(
The replay interface of `cia402 replay` (docs/semantics.md): one drive on an ideal plant, driven by
event lines (`cw 0x0F`, `fault 0x2310`, `set 0x605A 6`, `sto on`, `moving`, ...), each answered
once the drive is at rest with the JSON object the command line prints. Powered up when made
(`power_up` holds that first object); `options` are the --set writes before it ({0x605A: 6}; a
refused one raises SdoError). A bad line gives {"error": ..., "line": N} and changes nothing.)doc")
      .def(py::init([](const py::object& profile, const std::optional<std::map<int, std::int64_t>>& options) {
             return std::make_unique<replay_core>(profile_argument(profile), options.value_or(std::map<int, std::int64_t>{}));
           }),
           py::arg("profile") = "cia402", py::arg("options") = py::none())
      .def_property_readonly("power_up", [](const replay_core& r) { return parse_json(r.power_up_line()); },
                             "The power-up object ('transitions': [0, 1]).")
      .def("feed", [](replay_core& r, const std::string& line) -> py::object {
             const std::string result = r.feed(line);
             if (result.empty()) return py::none();
             return parse_json(result);
           }, py::arg("line"), "One event line: its JSON object as a dict, or None for a blank or comment line.")
      .def("feed_text", &replay_core::feed, py::arg("line"),
           "One event line: the JSON line exactly as `cia402 replay` prints it (\"\" for a blank or comment line).")
      .def("run", &replay_core::run, py::arg("lines"),
           "Every line of a str (or an iterable of lines): the objects of the non-blank lines, in order.")
      .def_property_readonly("line_number", &replay_core::line_number, "Lines fed so far.")
      .def_property_readonly("state", [](const replay_core& r) { return state_name(r.session().drive_axis().current); })
      .def_property_readonly("control_word", [](const replay_core& r) { return r.session().inputs().control_word; });
}

}  // namespace cia402::python
