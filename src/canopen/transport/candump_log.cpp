#include "cia402/canopen/transport/candump_log.hpp"
#include "cia402/support/text.hpp"

#include <charconv>
#include <cstdio>
#include <vector>

namespace cia402::canopen::candump {
namespace {

// can-utils' error-frame flag (CAN_ERR_FLAG) in a logged identifier.
constexpr std::uint32_t error_frame_flag = 0x20000000u;

bool digits_only(std::string_view text) {
  if (text.empty()) return false;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

bool parse_time(std::string_view text, std::uint64_t& out, std::string& why) {
  why = "time '" + std::string(text) + "' is not (SECONDS.FRACTION)";
  if (text.size() < 3 || text.front() != '(' || text.back() != ')') return false;
  text = text.substr(1, text.size() - 2);
  const auto dot = text.find('.');
  if (dot == std::string_view::npos) return false;
  const std::string_view whole = text.substr(0, dot);
  const std::string_view fraction = text.substr(dot + 1);
  // 12 digits of seconds keep the microseconds within 64 bits with room to spare.
  if (!digits_only(whole) || whole.size() > 12 || !digits_only(fraction) || fraction.size() > 9) {
    return false;
  }
  std::uint64_t seconds = 0;
  std::from_chars(whole.data(), whole.data() + whole.size(), seconds);
  std::uint64_t micros = 0;
  for (std::size_t i = 0; i < 6; ++i) {
    micros = micros * 10 + (i < fraction.size() ? static_cast<std::uint64_t>(fraction[i] - '0') : 0);
  }
  out = seconds * 1000000 + micros;
  return true;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool parse_identifier(std::string_view text, frame& f, std::string& why) {
  why = "identifier '" + std::string(text) + "' is not 3 or 8 hexadecimal digits";
  if (text.empty() || text.size() > 8) return false;
  std::uint32_t id = 0;
  for (char c : text) {
    const int d = hex_digit(c);
    if (d < 0) return false;
    id = (id << 4) | static_cast<std::uint32_t>(d);
  }
  // As python-can reads it: more than 3 digits is a 29-bit identifier.
  f.extended = text.size() > 3;
  if (f.extended && (id & error_frame_flag) != 0) {
    why = "an error frame (identifier " + std::string(text) + "), not a CAN frame";
    return false;
  }
  if (id > (f.extended ? max_extended_id : max_base_id)) {
    why = "identifier " + std::string(text) + " is out of range";
    return false;
  }
  f.id = id;
  return true;
}

bool parse_data(std::string_view text, frame& f, std::string& why) {
  if (!text.empty() && text.front() == '#') {
    why = "a CAN FD frame, not a classic CAN frame";
    return false;
  }
  if (!text.empty() && (text.front() == 'R' || text.front() == 'r')) {
    f.rtr = true;
    const std::string_view length = text.substr(1);
    if (length.empty()) return true;
    if (length.size() != 1 || length[0] < '0' || length[0] > '8') {
      why = "remote frame length '" + std::string(length) + "' is not 0..8";
      return false;
    }
    f.len = static_cast<std::uint8_t>(length[0] - '0');
    return true;
  }
  if (text.size() % 2 != 0 || text.size() > 16) {
    why = "data '" + std::string(text) + "' is not 0..8 bytes of two hexadecimal digits";
    return false;
  }
  for (std::size_t i = 0; i < text.size(); i += 2) {
    const int high = hex_digit(text[i]);
    const int low = hex_digit(text[i + 1]);
    if (high < 0 || low < 0) {
      why = "data '" + std::string(text) + "' is not hexadecimal";
      return false;
    }
    f.data[f.len++] = static_cast<std::uint8_t>(high * 16 + low);
  }
  return true;
}

}  // namespace

std::string format_frame(const frame& f) {
  char id[16];
  std::snprintf(id, sizeof id, f.extended ? "%08X#" : "%03X#", static_cast<unsigned>(f.id));
  std::string text = id;
  if (f.rtr) {
    text += 'R';
    if (f.len != 0) text += static_cast<char>('0' + (f.len > 8 ? 8 : f.len));
    return text;
  }
  static constexpr char digits[] = "0123456789ABCDEF";
  for (std::size_t i = 0; i < f.len && i < f.data.size(); ++i) {
    text += digits[f.data[i] >> 4];
    text += digits[f.data[i] & 0x0F];
  }
  return text;
}

std::string format_line(const frame& f, std::uint64_t time_us, std::string_view interface) {
  char head[48];
  std::snprintf(head, sizeof head, "(%llu.%06llu) ", static_cast<unsigned long long>(time_us / 1000000),
                static_cast<unsigned long long>(time_us % 1000000));
  std::string line = head;
  line.append(interface);
  line += ' ';
  return line + format_frame(f);
}

bool parse_line(std::string_view line, log_entry& out, std::string& why) {
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  const auto t = support::split_words(line);
  // python-can's writer adds the direction: " R" received, " T" transmitted.
  const bool direction = t.size() == 4 && (t[3] == "R" || t[3] == "T" || t[3] == "r" || t[3] == "t");
  if (t.size() != 3 && !direction) {
    why = "expected '(SECONDS.MICROS) INTERFACE ID#DATA'";
    return false;
  }
  log_entry e;
  if (!parse_time(t[0], e.time_us, why)) return false;
  e.interface = std::string(t[1]);
  const auto hash = t[2].find('#');
  if (hash == std::string_view::npos) {
    why = "frame '" + std::string(t[2]) + "' has no '#'";
    return false;
  }
  if (!parse_identifier(t[2].substr(0, hash), e.f, why)) return false;
  if (!parse_data(t[2].substr(hash + 1), e.f, why)) return false;
  out = std::move(e);
  return true;
}

}  // namespace cia402::canopen::candump
