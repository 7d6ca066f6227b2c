#include "sim_machine.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <variant>

#include "cia402/objects.hpp"
#include "cia402/sim/plant.hpp"

namespace cia402::python {
namespace {

using sim::plant_config;

// plant_config's fields by name: the one spelling Python uses for them (the struct's own).
struct plant_field {
  const char* name;
  std::variant<std::uint32_t plant_config::*, bool plant_config::*, std::int32_t plant_config::*,
               std::int64_t plant_config::*, std::optional<std::int64_t> plant_config::*>
      member;
};

const plant_field plant_fields[] = {
    {"cycle_us", &plant_config::cycle_us},
    {"brake_fitted", &plant_config::brake_fitted},
    {"brake_engage_delay_us", &plant_config::brake_engage_delay_us},
    {"brake_release_delay_us", &plant_config::brake_release_delay_us},
    {"brake_deceleration", &plant_config::brake_deceleration},
    {"coast_deceleration", &plant_config::coast_deceleration},
    {"standstill_window_rpm", &plant_config::standstill_window_rpm},
    {"target_window_rpm", &plant_config::target_window_rpm},
    {"current_limit_percent", &plant_config::current_limit_percent},
    {"voltage_limit_percent", &plant_config::voltage_limit_percent},
    {"max_velocity_rpm", &plant_config::max_velocity_rpm},
    {"max_acceleration_rpm_s", &plant_config::max_acceleration_rpm_s},
    {"torque_acceleration_rpm_s", &plant_config::torque_acceleration_rpm_s},
    {"friction_permille", &plant_config::friction_permille},
    {"load_permille", &plant_config::load_permille},
    {"home_switch_fitted", &plant_config::home_switch_fitted},
    {"home_switch_position", &plant_config::home_switch_position},
    {"home_switch_end", &plant_config::home_switch_end},
    {"negative_limit_switch", &plant_config::negative_limit_switch},
    {"positive_limit_switch", &plant_config::positive_limit_switch},
    {"index_position", &plant_config::index_position},
};

std::int64_t integer_value(const py::handle& v, const std::string& key) {
  if (!py::isinstance<py::int_>(v) || py::isinstance<py::bool_>(v)) {
    raise_argument_error("plant key '" + key + "' takes an int");
  }
  try {
    return v.cast<std::int64_t>();
  } catch (const py::cast_error&) {
    raise_argument_error("plant key '" + key + "' is beyond 64 bits");
  }
}

void set_field(plant_config& c, const plant_field& f, const py::handle& v) {
  const std::string key = f.name;
  std::visit(
      [&](auto member) {
        using type = std::remove_cvref_t<decltype(c.*member)>;
        if constexpr (std::is_same_v<type, bool>) {
          if (!py::isinstance<py::bool_>(v)) raise_argument_error("plant key '" + key + "' takes True or False");
          c.*member = v.cast<bool>();
        } else if constexpr (std::is_same_v<type, std::optional<std::int64_t>>) {
          c.*member = v.is_none() ? std::nullopt : std::optional<std::int64_t>(integer_value(v, key));
        } else {
          c.*member = static_cast<type>(checked_integer(integer_value(v, key), std::numeric_limits<type>::min(),
                                                        std::numeric_limits<type>::max(), "plant key '" + key + "'"));
        }
      },
      f.member);
}

}  // namespace

plant_config plant_config_from(const py::handle& plant) {
  plant_config c;
  if (plant.is_none()) return c;
  if (!py::isinstance<py::dict>(plant)) raise_argument_error("plant is a dict of plant settings or None");
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(plant)) {
    const std::string name = py::str(key);
    const auto* f = std::find_if(std::begin(plant_fields), std::end(plant_fields),
                                 [&](const plant_field& each) { return name == each.name; });
    if (f == std::end(plant_fields)) {
      raise_argument_error("unknown plant key '" + name + "' (the keys: " + names_of(plant_fields) + ")");
    }
    set_field(c, *f, value);
  }
  if (const char* why = sim::check_plant_config(c)) raise_argument_error(std::string("plant refused: ") + why);
  return c;
}

py::dict plant_config_dict(const plant_config& c) {
  py::dict d;
  for (const plant_field& f : plant_fields) {
    std::visit(
        [&](auto member) {
          using type = std::remove_cvref_t<decltype(c.*member)>;
          if constexpr (std::is_same_v<type, std::optional<std::int64_t>>) {
            d[f.name] = (c.*member) ? py::object(py::int_(*(c.*member))) : py::object(py::none());
          } else {
            d[f.name] = c.*member;
          }
        },
        f.member);
  }
  return d;
}

machine_core::machine_core(profile_ptr p, std::size_t axes, const plant_config& config, unsigned threads)
    : profile_(std::move(p)), config_(config), machine_(profile_->get(), axes, config, threads) {}

machine_core::use::use(machine_core& m) : m_(m) {
  if (m.busy_.exchange(true, std::memory_order_acquire)) {
    raise_busy_error("the machine is in use on another thread (it steps with the GIL released)");
  }
}

std::size_t machine_core::checked_axis(std::int64_t i) const {
  return static_cast<std::size_t>(checked_integer(i, 0, static_cast<std::int64_t>(size()) - 1, "axis"));
}

void machine_core::step_once() noexcept {
  if (recording_.empty()) {
    machine_.step();
    return;
  }
  const std::uint64_t t = machine_.time_us();
  for (const std::size_t i : recording_) {
    traces_[i].push_back(sim::begin_row(t, machine_.constants(), machine_.axis_at(i)));
  }
  machine_.step();
  for (const std::size_t i : recording_) sim::complete_row(traces_[i].back(), machine_.axis_at(i).last);
}

void machine_core::step_cycles(std::uint64_t cycles) noexcept {
  for (std::uint64_t c = 0; c < cycles; ++c) step_once();
}

void machine_core::check_writes(std::uint16_t index, std::uint8_t sub,
                                std::span<const std::int64_t> values) const {
  // A scratch axis: whether a write is refused depends on the profile, the object and the value,
  // never on the axis's state (sim/virtual_drive.hpp), so one scratch axis answers for all.
  sim::axis_state scratch = sim::make_axis_state(profile_->get(), machine_.constants());
  std::optional<std::int64_t> last_checked;
  for (const std::int64_t v : values) {
    if (last_checked == v) continue;
    check_access(sim::write_object(profile_->get(), scratch, index, sub, v), index, sub, "writing");
    last_checked = v;
  }
}

void machine_core::stream(std::uint16_t index, std::uint8_t sub, std::span<const std::int64_t> values,
                          std::size_t width) noexcept {
  const std::size_t n = size();
  for (std::size_t row = 0; row * width < values.size(); ++row) {
    const std::int64_t* v = values.data() + row * width;
    for (std::size_t i = 0; i < n; ++i) machine_.drive(i).write(index, sub, v[width == 1 ? 0 : i]);
    step_once();
  }
}

void machine_core::record(std::size_t axis, bool on) {
  const auto at = std::find(recording_.begin(), recording_.end(), axis);
  if (on && at == recording_.end()) {
    recording_.insert(std::upper_bound(recording_.begin(), recording_.end(), axis), axis);
  } else if (!on && at != recording_.end()) {
    recording_.erase(at);
  }
}

bool machine_core::recording(std::size_t axis) const {
  return std::find(recording_.begin(), recording_.end(), axis) != recording_.end();
}

trace_ptr machine_core::trace(std::size_t axis) const {
  auto data = std::make_shared<trace_data>();
  if (const auto at = traces_.find(axis); at != traces_.end()) data->rows = at->second;
  data->info.title = "axis " + std::to_string(axis);
  data->info.profile_name = profile_->get().name;
  data->info.cycle_us = config_.cycle_us;
  data->info.brake_fitted = config_.brake_fitted;
  return data;
}

step_outputs outputs_of(const sim::drive_view& d) {
  step_outputs o;
  o.out = d.outputs();
  if (o.out.transition != no_transition) o.transitions.push_back(o.out.transition);
  return o;
}

machine_ptr make_machine(std::int64_t axes, const py::object& profile, const py::object& plant,
                         std::int64_t threads) {
  const auto n = static_cast<std::size_t>(checked_integer(axes, 1, 1'000'000, "axes"));
  const auto t = static_cast<unsigned>(checked_integer(threads, 0, 256, "threads"));
  profile_ptr p = profile_argument(profile);
  const plant_config config = plant_config_from(plant);
  return std::make_shared<machine_core>(std::move(p), n, config, t);
}

}  // namespace cia402::python
