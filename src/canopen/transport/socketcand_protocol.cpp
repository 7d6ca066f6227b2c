#include <charconv>
#include <cstdio>

#include "cia402/canopen/transport/socketcand.hpp"
#include "cia402/support/text.hpp"

namespace cia402::canopen::socketcand {
namespace {

bool hex_value(std::string_view text, std::uint32_t& out) {
  if (text.empty() || text.size() > 8) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out, 16);
  return ec == std::errc{} && end == text.data() + text.size();
}

bool identifier(std::string_view text, frame& out, std::string& why) {
  std::uint32_t id = 0;
  if (!hex_value(text, id)) {
    why = "identifier '" + std::string(text) + "' is not hexadecimal";
    return false;
  }
  // socketcand: 8 digits mean a 29-bit identifier; an 11-bit one above 0x7FF cannot be.
  out.extended = text.size() == 8 || id > max_base_id;
  if (id > max_extended_id) {
    why = "identifier " + std::string(text) + " is above 0x1FFFFFFF";
    return false;
  }
  out.id = id;
  return true;
}

}  // namespace

element_reader::result element_reader::next(std::string& element) {
  std::size_t used = 0;
  result r = result::none;
  for (; used < pending_.size() && r == result::none; ++used) {
    const char c = pending_[used];
    if (!inside_) {
      if (c == '<') {
        inside_ = true;
        skipping_ = false;
        current_.assign(1, c);
      }
      continue;
    }
    if (skipping_) {
      if (c == '>') inside_ = skipping_ = false;
      continue;
    }
    if (c == '<') {  // an element never closed: start again here
      current_.assign(1, c);
      continue;
    }
    current_.push_back(c);
    if (c == '>') {
      inside_ = false;
      element.swap(current_);
      current_.clear();
      r = result::element;
    } else if (current_.size() >= max_) {
      skipping_ = true;
      current_.clear();
      r = result::too_long;
    }
  }
  pending_.erase(0, used);
  return r;
}

std::vector<std::string_view> words(std::string_view element) {
  if (element.size() >= 2 && element.front() == '<' && element.back() == '>') {
    element = element.substr(1, element.size() - 2);
  }
  return support::split_words(element);
}

std::string format_frame(const frame& f, std::uint64_t time_us) {
  char buf[96];
  int n = std::snprintf(buf, sizeof buf, f.extended ? "< frame %08X %llu.%06llu " : "< frame %03X %llu.%06llu ",
                        f.id, static_cast<unsigned long long>(time_us / 1000000),
                        static_cast<unsigned long long>(time_us % 1000000));
  for (std::uint8_t i = 0; i < f.len && i < 8; ++i) {
    n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "%02X", f.data[i]);
  }
  std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), " >");
  return buf;
}

std::string format_send(const frame& f) {
  char buf[64];
  int n = std::snprintf(buf, sizeof buf, f.extended ? "< send %08X %u" : "< send %03X %u", f.id,
                        static_cast<unsigned>(f.len));
  for (std::uint8_t i = 0; i < f.len && i < 8; ++i) {
    n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), " %02X", f.data[i]);
  }
  std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), " >");
  return buf;
}

namespace {

// The words of an element that names a frame, `< KEYWORD ID more... >` with at least one word after
// the identifier, and the frame's identifier; false with the reason when it is anything else.
bool frame_element(std::string_view element, std::string_view keyword, const char* expected,
                   std::vector<std::string_view>& w, frame& f, std::string& why) {
  w = words(element);
  if (w.size() < 3 || w[0] != keyword) {
    why = expected;
    return false;
  }
  return identifier(w[1], f, why);
}

}  // namespace

bool parse_send(std::string_view element, frame& out, std::string& why) {
  std::vector<std::string_view> w;
  frame f;
  if (!frame_element(element, "send", "expected < send ID LEN DATA... >", w, f, why)) return false;
  unsigned len = 0;
  const auto [end, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), len, 10);
  if (ec != std::errc{} || end != w[2].data() + w[2].size() || len > 8) {
    why = "length '" + std::string(w[2]) + "' is not 0..8";
    return false;
  }
  if (w.size() != 3 + len) {
    why = "length " + std::to_string(len) + " but " + std::to_string(w.size() - 3) + " data bytes";
    return false;
  }
  f.len = static_cast<std::uint8_t>(len);
  for (unsigned i = 0; i < len; ++i) {
    std::uint32_t b = 0;
    if (w[3 + i].size() > 2 || !hex_value(w[3 + i], b)) {
      why = "data byte '" + std::string(w[3 + i]) + "' is not one hexadecimal byte";
      return false;
    }
    f.data[i] = static_cast<std::uint8_t>(b);
  }
  out = f;
  return true;
}

bool parse_frame(std::string_view element, frame& out, std::string& why) {
  std::vector<std::string_view> w;
  frame f;
  if (!frame_element(element, "frame", "expected < frame ID SECS.USECS DATA >", w, f, why)) return false;
  std::string hex;
  for (std::size_t i = 3; i < w.size(); ++i) hex.append(w[i]);
  if (hex.size() % 2 != 0 || hex.size() > 16) {
    why = "data '" + hex + "' is not 0..8 hexadecimal bytes";
    return false;
  }
  for (std::size_t i = 0; i < hex.size() / 2; ++i) {
    std::uint32_t b = 0;
    if (!hex_value(std::string_view(hex).substr(2 * i, 2), b)) {
      why = "data '" + hex + "' is not hexadecimal";
      return false;
    }
    f.data[i] = static_cast<std::uint8_t>(b);
  }
  f.len = static_cast<std::uint8_t>(hex.size() / 2);
  out = f;
  return true;
}

}  // namespace cia402::canopen::socketcand
