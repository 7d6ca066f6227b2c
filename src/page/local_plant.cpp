#include "local_plant.hpp"

#include "cia402/drive.hpp"
#include "cia402/error_codes.hpp"
#include "cia402/objects.hpp"
#include "cia402/words.hpp"
#include "commissioning.hpp"
#include "page_json.hpp"
#include "page_names.hpp"

namespace cia402::page::detail {

std::optional<local_plant> local_plant::of(const drive_connection& c) {
  if (c.plant == nullptr) return std::nullopt;
  return local_plant(*c.plant);
}

std::optional<std::int64_t> local_plant::read(std::uint16_t index, std::uint8_t sub) const {
  std::int64_t v = 0;
  if (view().read(index, sub, v) == sdo_abort::none) return v;
  return std::nullopt;
}

std::uint16_t local_plant::error_code() const { return view().outputs().error_code; }

const sim::trace_row& local_plant::open_cycle() {
  const sim::drive_view v = view();
  open_row_ = sim::begin_row(drive_->time_us(), drive_->constants(), v.state_of_axis());
  open_row_cycle_ = drive_->cycle();
  open_row_state_ = v.current();
  return *open_row_;
}

std::optional<local_plant::closed_cycle> local_plant::close_cycle() {
  if (!open_row_ || drive_->cycle() == open_row_cycle_) return std::nullopt;
  closed_cycle c{*open_row_, open_row_state_, view().outputs()};
  open_row_.reset();
  sim::complete_row(c.row, c.out);
  return c;
}

std::vector<std::string> local_plant::conditions() const {
  const sim::drive_view v = view();
  std::vector<std::string> held;
  if (v.fault_cause() != 0) held.push_back("fault cause " + hex(v.fault_cause(), 4) + " present");
  if (v.sto()) held.push_back("STO asserted");
  if (!v.dc_link()) held.push_back("no DC-link voltage");
  return held;
}

std::string local_plant::waiting_for() const {
  const sim::drive_view v = view();
  if (v.sto()) return "STO asserted";
  if (!v.dc_link()) return "no DC-link voltage";
  if (cia402::stop_running(v.state_of_axis().core)) return "a stop is ramping";
  return "";
}

bool local_plant::stop_ramping(const profile& p) const {
  const sim::drive_view v = view();
  const state_activity act = p.info(v.current()).activity;
  return cia402::stop_running(v.state_of_axis().core) ||
         ((act == state_activity::quick_stop || act == state_activity::fault_reaction) && !v.inputs().standstill);
}

std::string local_plant::enable_blocker(state shown) const {
  const sim::drive_view v = view();
  return detail::enable_blocker(shown, v.outputs().error_code, v.sto(), v.dc_link(),
                                (v.outputs().status_word & status_bit::remote) != 0);
}

void local_plant::show(nlohmann::ordered_json& j, const profile& p) const {
  const sim::drive_view v = view();
  const drive_outputs& out = v.outputs();
  j["stop_running"] = cia402::stop_running(v.state_of_axis().core);
  j["ramp"] = stop_ramp_name(out.ramp);
  j["error_code"] = hex(out.error_code, 4);
  j["error_text"] = error_code_text(out.error_code);
  j["error_register"] = hex(out.error_register, 2);
  j["velocity"] = v.velocity_rpm();
  j["target_velocity"] = v.target_velocity();
  j["effective_target"] = v.effective_target();
  j["torque"] = out.torque;
  j["brake_engaged"] = v.brake_engaged();
  j["dc_link"] = v.dc_link();
  j["sto"] = v.sto();
  j["fault_cause"] = hex(v.fault_cause(), 4);
  j["mode"] = v.operation_mode();
  j["requested_mode"] = v.requested_mode();
  j["position"] = v.position();
  j["position_demand"] = v.position_demand();
  j["following_error"] = v.following_error();
  j["torque_actual"] = v.torque();
  const auto inputs = read(object_index::digital_inputs, 0);
  j["digital_inputs"] = inputs ? json(*inputs) : json(nullptr);
  json objs = json::object();
  for (const object_name& o : object_names(p)) {
    if (const auto value = read(o.index, 0)) objs[hex(o.index, 4)] = *value;
  }
  j["objects"] = std::move(objs);
}

std::vector<std::string> local_plant::change_inputs(const plant_change& change) {
  sim::drive_view v = view();
  std::vector<std::string> done;
  if (change.fault) {
    if (*change.fault) {
      v.inject_fault(change.fault_code, change.fault_class);
      done.push_back("FAULT " + hex(change.fault_code, 4) + " ON");
    } else {
      v.clear_faults();
      done.push_back("FAULT OFF");
    }
  }
  if (change.dc_link) {
    v.set_dc_link(*change.dc_link);
    done.push_back(std::string("DC_LINK ") + (*change.dc_link ? "ON" : "OFF"));
  }
  if (change.sto) {
    v.set_sto(*change.sto);
    done.push_back(std::string("STO ") + (*change.sto ? "ON" : "OFF"));
  }
  return done;
}

}  // namespace cia402::page::detail
