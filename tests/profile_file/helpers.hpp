// Shared helpers of the profile-file tests.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <variant>

#include "cia402/profile_file.hpp"

namespace cia402::test {

/// The loaded profile; fails the test (and returns a default profile) if the text was refused.
inline custom_profile load_ok(std::string_view text) {
  profile_load_result r = load_profile_toml(text, "test.toml");
  if (const auto* e = std::get_if<profile_file_error>(&r)) {
    ADD_FAILURE() << "refused: " << e->message();
    return custom_profile();
  }
  return std::get<custom_profile>(r);
}

/// The refusal; fails the test (and returns an empty error) if the text was accepted.
inline profile_file_error load_error(std::string_view text) {
  profile_load_result r = load_profile_toml(text, "test.toml");
  if (const auto* e = std::get_if<profile_file_error>(&r)) return *e;
  ADD_FAILURE() << "accepted a profile that should have been refused";
  return profile_file_error{};
}

}  // namespace cia402::test

namespace cia402::test {

/// Pieces of a profile file, joined into its text.
inline std::string toml(std::initializer_list<std::string_view> pieces) {
  std::string text;
  for (const std::string_view p : pieces) text += p;
  return text;
}

/// The power-up rows every table begins with, 5 lines each: T0 (START to NOT READY TO SWITCH ON)
/// and T1 (on to SWITCH ON DISABLED), both automatic. A based file needs T0 at least.
inline constexpr std::string_view t0_row = R"([[rows]]
number = 0
from = ["start"]
to = "not_ready_to_switch_on"
any = ["automatic"]
)";
inline constexpr std::string_view t1_row = R"([[rows]]
number = 1
from = ["not_ready_to_switch_on"]
to = "switch_on_disabled"
any = ["automatic"]
)";

/// A complete profile without base: the smallest file that passes (T0, T1, T2, T13, T14, T15).
/// Line numbers matter to the error tests that append to it: it is 78 lines long, the name and
/// the decoder on lines 1 to 5, T0 and T1 on 6 to 15, T2 from line 16 on.
inline const std::string minimal_profile = toml({R"(name = "minimal"
[[decoder]]
mask = 0x02
value = 0x00
command = "disable_voltage"
)", t0_row, t1_row, R"([[rows]]
number = 2
from = ["switch_on_disabled"]
to = "ready_to_switch_on"
any = ["enable_operation"]
[[rows]]
number = 13
from = ["switch_on_disabled", "ready_to_switch_on"]
to = "fault_reaction_active"
any = ["fault"]
[[rows]]
number = 14
from = ["fault_reaction_active"]
to = "fault"
any = ["automatic"]
[[rows]]
number = 15
from = ["fault"]
to = "switch_on_disabled"
any = ["fault_reset"]
none = ["fault_present"]
[states.not_ready_to_switch_on]
status = 0x00
activity = "idle"
[states.switch_on_disabled]
status = 0x40
activity = "idle"
[states.ready_to_switch_on]
status = 0x21
activity = "idle"
[states.switched_on]
status = 0x23
activity = "idle"
[states.operation_enabled]
status = 0x27
activity = "run"
[states.quick_stop_active]
status = 0x07
activity = "quick_stop"
[states.fault_reaction_active]
status = 0x0F
activity = "fault_reaction"
[states.fault]
status = 0x08
activity = "idle"
[options.0x605A]
supported = []
default = 0
[options.0x605B]
supported = []
default = 0
[options.0x605C]
supported = []
default = 0
[options.0x605D]
supported = []
default = 1
[options.0x605E]
supported = [0]
default = 0
[options.0x6007]
supported = [0, 1]
default = 1
)"});

}  // namespace cia402::test
