#include "cli/decode.hpp"

#include <sstream>

#include "cia402/master.hpp"
#include "cia402/words.hpp"
#include "cli/common.hpp"

namespace cia402::cli {
namespace {

void write_bits(std::ostringstream& o, std::uint16_t word, const char* const (&names)[16],
                std::uint16_t decoder_bits) {
  for (int b = 0; b < 16; ++b) {
    o << "  bit " << (b < 10 ? " " : "") << b << "  " << ((word >> b) & 1u) << "  " << names[b];
    if ((decoder_bits >> b) & 1u) o << "  [read by the profile's decoder]";
    o << "\n";
  }
}

}  // namespace

std::string describe_status_word(const profile& p, std::uint16_t status_word) {
  std::ostringstream o;
  const word_bit_names& names = bit_names_of(p);
  state s{};
  const bool shown = decode_status(p, status_word, s);
  o << names.status_word << ": " << hex(status_word, 4) << " (profile " << p.name << ")\n";
  o << "state: " << (shown ? state_name(s) : "none (bits 0..3, 5, 6 match no state)") << "\n";
  write_bits(o, status_word, names.status, 0);
  return o.str();
}

std::string describe_control_word(const profile& p, std::uint16_t control_word) {
  std::ostringstream o;
  std::uint16_t decoder_bits = 0;
  for (std::size_t i = 0; i < p.decoder_size; ++i) decoder_bits |= p.decoder[i].mask;
  const bool reset = (control_word & control_bit::fault_reset) != 0;
  const bool halt = (control_word & control_bit::halt) != 0;
  const word_bit_names& names = bit_names_of(p);
  o << names.control_word << ": " << hex(control_word, 4) << " (profile " << p.name << ")\n";
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
  write_bits(o, control_word, names.control, decoder_bits);
  return o.str();
}

}  // namespace cia402::cli
