// JSON as text, for every answer and snapshot of the page: the one way the page dumps JSON
// (issue 42). A text that a request or a peer brings (a path, a query value, a drive's 0x1008 name,
// a string entry of its dictionary) may be any bytes; nlohmann's dump() throws on a string that is
// not UTF-8 (type_error 316), and thrown in cpp-httplib's error handler or in the cycle thread it
// ended `cia402 serve`. Here each invalid byte becomes U+FFFD instead, so no dump of the page throws.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <string_view>

namespace cia402::page::detail {

/// `j` as compact JSON text; a string that is not UTF-8 has each invalid byte replaced by U+FFFD.
template <typename Json>
std::string json_text(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

/// Whether `s` is well-formed UTF-8 (no overlong forms, no surrogates, at most U+10FFFF): the
/// support layer's reading, the one TOML files are checked by (json_text.cpp; the page's tests
/// and fuzz target see this header, not the support layer's).
bool is_utf8(std::string_view s);

/// A drive's text for display: as it is when it is UTF-8, else read as ISO 8859-1 (Latin-1, what
/// a drive that is not UTF-8 most often sends: "Servoverst\xe4rker" shows as "Servoverstärker").
inline std::string display_text(std::string_view s) {
  if (is_utf8(s)) return std::string(s);
  std::string out;
  out.reserve(s.size() * 2);
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x80) {
      out += ch;
    } else {
      out += static_cast<char>(0xC0 | (c >> 6));        // UTF-8 lead byte: not a control word
      out += static_cast<char>(0x80 | (c & 0x3F));  // UTF-8 continuation: not a control word
    }
  }
  return out;
}

}  // namespace cia402::page::detail
