#include "word_change.hpp"

#include "cia402/master.hpp"
#include "cia402/objects.hpp"
#include "cia402/words.hpp"
#include "page_json.hpp"
#include "page_names.hpp"

namespace cia402::page::detail {

std::variant<word_change, refused> press_button(const profile& p, page_command c,
                                                std::uint16_t control_word) {
  constexpr std::uint16_t bit7 = control_bit::fault_reset;
  constexpr std::uint16_t bit8 = control_bit::halt;
  word_change w;
  w.action = entry_of(c).action;
  if (c == page_command::halt) {
    if (!p.spec(option::halt).exists()) {
      return refused{409, std::string("profile ") + p.name + " has no halt; its bit 8 is \"" +
                              bit_names_of(p).control[8] + "\", toggled as a bit"};
    }
    w.word = static_cast<std::uint16_t>(control_word ^ bit8);
    w.tracked = false;
    w.text = std::string("done: halt bit 8 = ") + ((w.word & bit8) != 0 ? "1" : "0");
    return w;
  }
  if (c == page_command::fault_reset) {
    w.word = static_cast<std::uint16_t>(control_word & ~bit7);
    w.fault_reset_edge = true;
    return w;
  }
  cia402::command core_command{};
  core_command_of(c, core_command);
  if (!encode_command(p, core_command, control_word, w.word)) {
    return refused{409, std::string("profile ") + p.name + " has no control word for " + w.action};
  }
  return w;
}

action_log::expectation word_change::expect_in(const profile& p, std::uint16_t before,
                                               std::optional<state> now) const {
  const std::uint16_t bit7 = control_bit::fault_reset;
  if (fault_reset_edge || ((word & bit7) != 0 && (before & bit7) == 0)) {
    return action_log::expectation::edge;
  }
  if (!now) return action_log::expectation::act;
  // The command leads to the present state (a row into it fires on it): the drive is where the
  // command would take it, as Enable operation in OPERATION ENABLED or Shutdown in READY TO
  // SWITCH ON.
  const auto wanted = static_cast<std::uint32_t>(command_fact(p.decode(word)));
  for (std::size_t r = 0; r < p.row_count; ++r) {
    const transition_row row = p.row(r);
    if (row.to == *now && (row.any.bits() & wanted) != 0) return action_log::expectation::already_there;
  }
  return action_log::expectation::act;
}

word_change flip_bit(const profile& p, std::uint16_t control_word, int bit) {
  word_change w;
  w.word = static_cast<std::uint16_t>(control_word ^ (1u << bit));
  const bool value = ((w.word >> bit) & 1u) != 0;
  const cia402::command was = p.decode(control_word);
  const cia402::command now = p.decode(w.word);
  const bool reset_edge = bit == 7 && value;
  w.action = "BIT_" + std::to_string(bit) + "=" + (value ? "1" : "0");
  if (was != now || reset_edge) {
    w.action += std::string(" (") + (reset_edge ? "FAULT_RESET edge" : command_name(now)) + ")";
    return w;
  }
  w.tracked = false;
  const bool owned = ((owned_control_bits(p) >> bit) & 1u) != 0;
  w.text = owned ? std::string("done: still decodes to ") + command_name(now)
                 : std::string("done: the state machine does not read bit ") + std::to_string(bit);
  return w;
}

std::optional<refused> new_setpoint_refusal(const profile& p, std::optional<std::int64_t> m) {
  if (!left_to_mode(p, true, 4)) {
    return refused{409, std::string("profile ") + p.name + " names control bit 4 \"" +
                            bit_names_of(p).control[4] + "\": no set-point handshake on it"};
  }
  if (m && *m != mode::profile_position) {
    const char* name = mode::short_name(*m);
    return refused{409, "the new set-point handshake is profile position's (0x6060 = 1); the drive "
                        "runs mode " + std::to_string(*m) +
                        (name[0] != '\0' ? std::string(" (") + name + ")" : std::string())};
  }
  return std::nullopt;
}

}  // namespace cia402::page::detail
