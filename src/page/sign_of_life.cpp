#include "sign_of_life.hpp"

#include <string>
#include <variant>

#include "cia402/lost_client.hpp"
#include "cia402/words.hpp"

namespace cia402::page::detail {

std::optional<word_change> stop_for_silent_page(const profile& p, std::uint16_t control_word,
                                                int abort_connection, std::uint64_t lease_us) {
  const lost_client_stop how = stop_for_lost_client(abort_connection, p.spec(option::halt).exists());
  std::optional<word_change> w;
  if (how == lost_client_stop::halt) {
    if ((control_word & control_bit::halt) != 0) return std::nullopt;
    w = flip_bit(p, control_word, 8);
  } else {
    const page_command c =
        how == lost_client_stop::disable_voltage ? page_command::disable_voltage : page_command::quick_stop;
    auto change = press_button(p, c, control_word);
    // A profile without a quick stop word: Disable voltage stops the torque at least.
    if (std::holds_alternative<refused>(change) && c == page_command::quick_stop) {
      change = press_button(p, page_command::disable_voltage, control_word);
    }
    if (std::holds_alternative<refused>(change)) return std::nullopt;
    w = std::get<word_change>(std::move(change));
  }
  w->action = "SIGN OF LIFE LOST (no page for " + std::to_string(lease_us / 1000) + " ms, 0x6007 = " +
              std::to_string(abort_connection) + "): " + w->action;
  return w;
}

}  // namespace cia402::page::detail
