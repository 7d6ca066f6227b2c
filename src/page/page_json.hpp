// What both backends of the page (instrument.cpp, remote_drive.cpp) share: the command buttons'
// table, the result list, and the profile part of /api/info. One source, so the page draws the
// same buttons, rows and bit names whichever drive it shows.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "cia402/page/backend.hpp"
#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402::page::detail {

using json = nlohmann::ordered_json;

/// "0x605A" with `digits` hex digits.
std::string hex(std::uint32_t value, int digits);
/// "SDO abort 0x06090030 (value range of parameter exceeded)".
std::string abort_text(sdo_abort code);

struct command_entry {
  page_command id;
  const char* key;
  const char* action;  // as results name it
};

const command_entry& entry_of(page_command c) noexcept;
/// The core's command for a button that is a plain command word; false for the two bit actions
/// (fault reset, halt).
bool core_command_of(page_command c, command& out) noexcept;

struct result_entry {
  std::uint64_t id = 0;
  std::string action;
  std::string outcome;  // "pending", "done", "refused"
  std::string text;
  std::vector<int> transitions;
};

/// Results for the page, newest first, at most `kept`; an entry with a known id is replaced.
void push_result(std::deque<result_entry>& results, result_entry r, std::size_t kept);
json results_json(const std::deque<result_entry>& results);

/// "done: T2, T3 -> SWITCHED_ON" for the transitions an action led to.
std::string transitions_text(const std::vector<int>& transitions, state now);

/// The profile's part of /api/info: name, states, rows, bit names, commands, objects.
json profile_info(const profile& p);

}  // namespace cia402::page::detail
