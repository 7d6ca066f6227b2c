// What the page's drive (axis_page.cpp) and the server share: the command buttons'
// table and the profile part of /api/info. One source, so the page draws the same buttons, rows and
// bit names whichever drive it shows. What else they share has a file of its own: the results
// (action_log.hpp), publishing snapshots (snapshot_board.hpp), the buttons' control words
// (word_change.hpp).
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>

#include "cia402/page/backend.hpp"
#include "cia402/profile.hpp"
#include "cia402/sdo_abort.hpp"
#include "cia402/support/text.hpp"

namespace cia402::page::detail {

using json = nlohmann::ordered_json;

using support::hex;  // "0x605A" with `digits` hex digits

/// "SDO abort 0x06090030 (invalid value for parameter)": the core's sdo_abort_words as a string.
inline std::string abort_text(sdo_abort code) { return sdo_abort_words(code).c_str(); }

struct command_entry {
  page_command id;
  const char* key;
  const char* action;  // as results name it
};

const command_entry& entry_of(page_command c) noexcept;
/// The core's command for a button that is a plain command word; false for the two bit actions
/// (fault reset, halt).
bool core_command_of(page_command c, command& out) noexcept;

/// The profile's part of /api/info: name, states, rows, bit names, commands, objects.
json profile_info(const profile& p);

}  // namespace cia402::page::detail
