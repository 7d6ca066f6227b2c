#include "cli/decode.hpp"

#include <sstream>

#include <nlohmann/json.hpp>

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

namespace {

nlohmann::ordered_json bits_json(std::uint16_t word, const char* const (&names)[16],
                                 const std::uint16_t* decoder_bits) {
  nlohmann::ordered_json bits = nlohmann::ordered_json::array();
  for (int b = 0; b < 16; ++b) {
    nlohmann::ordered_json bit{{"bit", b}, {"value", (word >> b) & 1u}, {"name", names[b]}};
    if (decoder_bits != nullptr) bit["decoded"] = ((*decoder_bits >> b) & 1u) != 0;
    bits.push_back(std::move(bit));
  }
  return bits;
}

}  // namespace

std::string status_word_json(const profile& p, std::uint16_t status_word) {
  state s{};
  const bool shown = decode_status(p, status_word, s);
  nlohmann::ordered_json j;
  j["profile"] = p.name;
  j["word"] = hex(status_word, 4);
  j["state"] = shown ? nlohmann::ordered_json(state_name(s)) : nlohmann::ordered_json(nullptr);
  j["bits"] = bits_json(status_word, bit_names_of(p).status, nullptr);
  return j.dump();
}

std::string control_word_json(const profile& p, std::uint16_t control_word) {
  std::uint16_t decoder_bits = 0;
  for (std::size_t i = 0; i < p.decoder_size; ++i) decoder_bits |= p.decoder[i].mask;
  nlohmann::ordered_json j;
  j["profile"] = p.name;
  j["word"] = hex(control_word, 4);
  j["command"] = command_name(p.decode(control_word));
  j["fault_reset"] = (control_word & control_bit::fault_reset) != 0;
  j["halt"] = (control_word & control_bit::halt) != 0 && p.spec(option::halt).exists();
  j["bits"] = bits_json(control_word, bit_names_of(p).control, &decoder_bits);
  return j.dump();
}

}  // namespace cia402::cli
