#include "cli/words.hpp"

#include <sstream>

#include "cia402/words.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

// CiA 402 names (cia402-reference.md §1.2 and §2.1).
constexpr const char* status_bit_names[16] = {
    "ready to switch on",
    "switched on",
    "operation enabled",
    "fault",
    "voltage enabled (DC link present)",
    "quick stop (active low: 0 = quick stop in progress)",
    "switch on disabled",
    "warning",
    "manufacturer specific",
    "remote (control word processed)",
    "target reached",
    "internal limit active",
    "operation mode specific",
    "operation mode specific",
    "manufacturer specific",
    "manufacturer specific",
};

constexpr const char* control_bit_names[16] = {
    "switch on",
    "enable voltage",
    "quick stop (active low)",
    "enable operation",
    "operation mode specific",
    "operation mode specific",
    "operation mode specific",
    "fault reset (0->1 edge)",
    "halt",
    "operation mode specific",
    "reserved",
    "manufacturer specific",
    "manufacturer specific",
    "manufacturer specific",
    "manufacturer specific",
    "manufacturer specific",
};

void write_bits(std::ostringstream& o, std::uint16_t word, const char* const (&names)[16],
                std::uint16_t decoder_bits) {
  for (int b = 0; b < 16; ++b) {
    o << "  bit " << (b < 10 ? " " : "") << b << "  " << ((word >> b) & 1u) << "  " << names[b];
    if ((decoder_bits >> b) & 1u) o << "  [read by the profile's decoder]";
    o << "\n";
  }
}

}  // namespace

std::uint16_t status_mask_of(state s) {
  switch (s) {
    case state::start:
    case state::not_ready_to_switch_on:
    case state::switch_on_disabled:
    case state::fault_reaction_active:
    case state::fault:
      return 0x4F;
    default:
      return 0x6F;
  }
}

std::optional<state> state_of_status_word(const profile& p, std::uint16_t status_word) {
  // START is never reported by a status word of its own, so it is not a candidate.
  for (int i = 1; i < state_count; ++i) {
    const state s = static_cast<state>(i);
    const std::uint16_t mask = status_mask_of(s);
    if ((status_word & mask) == (p.status_pattern(s) & mask)) return s;
  }
  return std::nullopt;
}

std::string describe_status_word(const profile& p, std::uint16_t status_word) {
  std::ostringstream o;
  const std::optional<state> s = state_of_status_word(p, status_word);
  o << "statusword " << hex(status_word, 4) << " (profile " << p.name << ")\n";
  o << "state: " << (s ? state_name(*s) : "none (bits 0..3, 5, 6 match no state)") << "\n";
  write_bits(o, status_word, status_bit_names, 0);
  return o.str();
}

std::string describe_control_word(const profile& p, std::uint16_t control_word) {
  std::ostringstream o;
  std::uint16_t decoder_bits = 0;
  for (std::size_t i = 0; i < p.decoder_size; ++i) decoder_bits |= p.decoder[i].mask;
  const bool reset = (control_word & control_bit::fault_reset) != 0;
  const bool halt = (control_word & control_bit::halt) != 0;
  o << "controlword " << hex(control_word, 4) << " (profile " << p.name << ")\n";
  o << "command: " << command_name(p.decode(control_word)) << "\n";
  o << "fault reset: " << (reset ? 1 : 0)
    << (reset ? " (a 0->1 edge of bit 7 in FAULT resets it, T15, once no cause is present)" : "")
    << "\n";
  o << "halt: " << (halt ? 1 : 0);
  if (halt) {
    o << (p.spec(option::halt).exists() ? " (stops on the 0x605D ramp in OPERATION ENABLED)"
                                        : " (this profile has no halt: bit 8 is ignored)");
  }
  o << "\n";
  write_bits(o, control_word, control_bit_names, decoder_bits);
  return o.str();
}

}  // namespace cia402::cli
