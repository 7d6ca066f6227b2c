// Stepping a virtual_axis_page in the page's tests and reading its snapshots: run cycles, take the
// snapshot as JSON, walk to OPERATION ENABLED with the command buttons, wait for a status bit.
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <string>
#include <variant>

#include "virtual_axis_page.hpp"

namespace cia402::page::testing::steps {

using json = nlohmann::json;

inline void run(virtual_axis_page& inst, int cycles) {
  for (int i = 0; i < cycles; ++i) inst.step();
}

inline json snapshot(const virtual_axis_page& inst) { return json::parse(inst.snapshot_json()); }

// The newest result, after the drive had time to settle (an action settles 50 quiet cycles after
// its last transition).
inline json settled_result(virtual_axis_page& inst) {
  run(inst, 300);
  const json s = snapshot(inst);
  EXPECT_FALSE(s["results"].empty());
  return s["results"].empty() ? json::object() : s["results"][0];
}

// The id of an accepted command; a refused one fails the test with its reason.
inline std::uint64_t id_of(const cia402::page::reply& r) {
  const auto* ok = std::get_if<accepted>(&r);
  EXPECT_NE(ok, nullptr) << (std::holds_alternative<refused>(r) ? std::get<refused>(r).reason : "");
  return ok != nullptr ? ok->id : 0;
}

inline int hex_value(const json& v) { return std::stoi(v.get<std::string>(), nullptr, 16); }

inline void enable(virtual_axis_page& inst) {
  for (const page_command c :
       {page_command::shutdown, page_command::switch_on, page_command::enable_operation}) {
    id_of(inst.command(c));
    run(inst, 100);
  }
}

// The plant change that makes a fault cause appear, with error code `code` (0x603F), and the one
// that takes every cause away.
inline plant_change fault_of(std::uint16_t code = plant_change{}.fault_code) {
  plant_change c;
  c.fault = true;
  c.fault_code = code;
  return c;
}
inline plant_change no_fault() {
  plant_change c;
  c.fault = false;
  return c;
}

// Steps until the snapshot shows status bit `bit` set (or `limit` cycles passed).
inline json run_until_status_bit(virtual_axis_page& inst, int bit, int limit) {
  json s = snapshot(inst);
  for (int i = 0; i < limit && ((hex_value(s["status_word"]) >> bit) & 1) == 0; i += 10) {
    run(inst, 10);
    s = snapshot(inst);
  }
  return s;
}

}  // namespace cia402::page::testing::steps
